// Operations on expressions: differentiation, substitution, copying between pools, free
// variables, evaluation, sizes.
//
// Every operation walks the DAG in topological order with an explicit stack, so each shared
// subexpression is visited once and no expression is too deep to process. Differentiation is
// memoized over the DAG: d/dx of a node is built once however many parents share it.
//
// Example:
//   ExprPool pool;
//   Expr x = pool.variable("x"), y = pool.variable("y");
//   Expr f = x * sin(y);
//   Expr dfdy = differentiate(f, y);                 // x*cos(y)
//   Expr g = substitute(f, {{y, pool.integer(0)}});   // 0
//   double v = evaluate(f, {{"x", 2.0}, {"y", 0.5}});
#pragma once

#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "spar/symbolic/expr.hpp"

namespace spar::symbolic {

// d f / d variable. `variable` must be a Variable node. The result is correct wherever f is
// differentiable (e.g. d|u| = u/|u| · du, undefined at u = 0).
[[nodiscard]] Expr differentiate(Expr f, Expr variable);
// J[i][j] = d outputs[i] / d variables[j], sharing work across outputs.
[[nodiscard]] std::vector<std::vector<Expr>> jacobian(std::span<const Expr> outputs,
                                                      std::span<const Expr> variables);

// f with every occurrence of each key (a Variable) replaced by its value, rebuilt canonically.
[[nodiscard]] Expr substitute(Expr f, const std::vector<std::pair<Expr, Expr>>& replacements);

// Rebuilds a node of e's kind (same op, constant and factors) over new operands; used by
// rewriting passes. `operands.size()` must equal e.operand_count().
[[nodiscard]] Expr rebuild(Expr e, std::span<const Expr> operands);

// The roots built again in `to`, a pool with nothing in it yet (typically one per thread: pools
// are not thread-safe), node by node in the order of their ids. Ids are topological and the
// rebuilt nodes get ids in the same relative order, so every Add and Mul sorts its operands as
// the original did and each node is its own canonical form again: the copies print the same,
// compile to the same tapes and so bound the same as the roots. (Into a pool that already holds
// nodes, a rebuilt node may meet an older one out of that order; hence the empty pool.) `to` may
// also be the roots' own pool, which returns the roots. Returns the copies in the roots' order;
// the roots' pool gets no node (it is walked with its traversal marks: not while another thread
// uses it). Throws SymbolicError for another pool that is not empty.
// Cost: O(DAG) constructions in `to`.
[[nodiscard]] std::vector<Expr> copy_into(ExprPool& to, std::span<const Expr> roots);

// Variables occurring in f, sorted by name.
[[nodiscard]] std::vector<Expr> free_variables(Expr f);
[[nodiscard]] std::vector<Expr> free_variables(std::span<const Expr> roots);
// The same variables in the order a walk of the roots meets them (for callers that order them by
// something else: sorting by name is most of free_variables' cost on a small DAG).
[[nodiscard]] std::vector<Expr> variables_met(std::span<const Expr> roots);

// Value of f at a point given by variable name. Throws SymbolicError if a variable of f has no
// value. Returns NaN where f is undefined (log of a negative number, ...).
[[nodiscard]] double evaluate(Expr f, const std::map<std::string, double>& values);

// Nodes of f as a DAG (each shared node once) and as a tree (shared nodes counted per use;
// a double, because trees grow exponentially with the depth of sharing).
[[nodiscard]] std::size_t dag_size(Expr f);
[[nodiscard]] std::size_t dag_size(std::span<const Expr> roots);
[[nodiscard]] double tree_size(Expr f);

}  // namespace spar::symbolic
