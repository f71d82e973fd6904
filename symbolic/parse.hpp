// Infix syntax: parsing and printing.
//
// Grammar (the syntax of data/fpbench.jsonl and of the `spar` command):
//   expr    := term (('+' | '-') term)*
//   term    := unary (('*' | '/') unary)*
//   unary   := ('-' | '+') unary | power
//   power   := primary (('^' | '**') unary)?        right-associative: a^b^c = a^(b^c)
//   primary := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//   number  := digits ['.' digits] [('e'|'E') ['+'|'-'] digits]
// Functions: sin cos tan sqrt exp log abs atan asin acos (one argument), atan2 min max pow (two);
// fabs, fmin, fmax are accepted as aliases. The name `pi` is the constant π, enclosed to one ulp.
// Decimal literals are exact rationals where they fit (see Number::parse_decimal).
//
// Names are ASCII identifiers; a non-ASCII character (x², x−1, Δx) is refused with a hint.
// Constants print as they parse: rationals exactly, reals (pi, 17-digit literals) with 17 digits,
// and a real exponent stays a real (x^pi is a Pow node), so `to_string(parse(pool, s))` re-parses
// to the same node. A parenthesised group is one operand: "(a*b)*c" is a*b times c, the node
// a*b*c unless a*b has more than kFlattenLimit factors (expr.hpp); printing parenthesises such
// an unflattened factor and writes a denominator of more factors than that as "/a/b/...", so
// that it re-parses to the same node. Parsing uses explicit stacks, not recursion, and allows
// kMaxParseDepth levels of nesting (the message names the limit); printing is iterative too and
// works at any depth.
//
// Example:
//   ExprPool pool;
//   Expr f = parse(pool, "sin(x)^2 + 2*x*y");
//   std::string text = to_string(f);   // e.g. "2*x*y + sin(x)^2"
//   parse(pool, "sin(x");              // throws: "expected ')' at column 6 in 'sin(x'"
#pragma once

#include <string>
#include <string_view>

#include "spar/symbolic/expr.hpp"

namespace spar::symbolic {

// Parentheses, function calls, signs and powers may nest this deep.
inline constexpr int kMaxParseDepth = 10'000;

// Throws SymbolicError naming the offending token and its column.
[[nodiscard]] Expr parse(ExprPool& pool, std::string_view text);

// Infix text of the expression as a tree. Throws SymbolicError if the tree form would exceed
// `max_tree_nodes` nodes (a DAG with heavy sharing can be exponentially large as text).
[[nodiscard]] std::string to_string(Expr e, double max_tree_nodes = 1e7);

}  // namespace spar::symbolic
