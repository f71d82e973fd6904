// A precondition's expression and variables copied into a pool of their own (symbolic::
// copy_into), so that work on them may run on another thread (pools are not thread-safe): the
// copy compiles to the same tape, so its bounds and samples are the original's. Made on the
// thread that owns the analysis' pool (copying adds nothing to it but walks it with the pool's
// traversal marks, so not while another thread uses it).
#pragma once

#include <memory>
#include <vector>

#include "spar/planner/uncertainty/analysis.hpp"
#include "spar/symbolic/operations.hpp"

namespace spar::planner::internal {

// The symbols of a precondition's variables, in PreconditionResult::variables order.
[[nodiscard]] inline std::vector<symbolic::Expr> variable_symbols(
    const InstanceAnalysis& analysis, const PreconditionResult& result) {
  std::vector<symbolic::Expr> symbols;
  for (const VariableId id : result.variables) symbols.push_back(analysis.symbols.at(id.index));
  return symbols;
}

struct OwnCopy {
  std::unique_ptr<symbolic::ExprPool> pool;
  symbolic::Expr f;                    // the precondition's expression
  std::vector<symbolic::Expr> inputs;  // its variables, in PreconditionResult::variables order
};

[[nodiscard]] inline OwnCopy own_copy(const InstanceAnalysis& analysis,
                                      const PreconditionResult& result) {
  OwnCopy copy{std::make_unique<symbolic::ExprPool>(), {}, {}};
  std::vector<symbolic::Expr> roots = variable_symbols(analysis, result);
  roots.insert(roots.begin(), result.inequality.expression);
  const std::vector<symbolic::Expr> copies = symbolic::copy_into(*copy.pool, roots);
  copy.f = copies.front();
  copy.inputs.assign(copies.begin() + 1, copies.end());
  return copy;
}

}  // namespace spar::planner::internal
