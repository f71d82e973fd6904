// Symbolic SUP/INF over linear inequalities (Bledsoe 1975, Shostak 1977, Brooks 1981).
//
// Given linear constraints among variables (box bounds `0 <= x <= 2` are linear constraints too),
// `sup(J, constraints, keep)` returns an expression in the kept variables that is >= J at every
// point satisfying the constraints, for every value of the kept variables (INF dually, <=). With
// `keep = {}` the answer is a number; otherwise it is a min (sup) or max (inf) of linear forms in
// the kept variables, e.g. SUP(x) under 0 <= x <= y <= 5 keeping y is `y`.
//
// The algorithm is Shostak's formulation of SUP-INF. Writing S for the variables not to eliminate:
//   SUP(c0 + Σ kept terms, S)      = itself
//   SUP(K + r·v, S)  (only v ∉ S)  = K + r·SUP(v, S) for r > 0,  K + r·INF(v, S) for r < 0
//   SUP(r·v + β, S)  (more ∉ S)    = min over a in SUP(β, S ∪ {v}) of SUP(r·v + a, S)
//   SUP(v, S)                      = SUPP(v, min over upper bounds u of v of SUP(u, S ∪ {v}))
//   SUPP(v, b·v + c)               = c / (1 - b) if b < 1, +∞ if b > 1 or (b = 1, c >= 0)
// and INF dually. Each bound is sound. Shostak proved that SUP(z, {}) is the exact maximum of a
// single variable z over a feasible polyhedron, so a target that is not a single variable is
// wrapped in a fresh variable z = J first (ShostakOptions::wrap_target); then keep = {} gives the
// exact LP optimum. All arithmetic is exact over 64-bit rationals (an overflow throws).
// Variables fixed by their own rows (lo = hi) are substituted before the recursion (an equivalent
// system), and the final min (max) drops pieces that are dominated on the variable box, so
// SUP(x) under 0 <= x <= 5, 0 <= y <= 5, x <= y keeping y is `y`, not `min(5, y)`.
//
// Strict inequalities are read as non-strict (the bounds of the closure are sound bounds). The
// target may be non-linear in kept variables (sin(y) + x keeping y), never in eliminated ones.
// Every failure throws ShostakError naming its reason; an answer is never returned wrong.
//
// Example:
//   symbolic::ExprPool pool;
//   auto constraints = parse_linear_constraints(pool, "0 <= x <= y <= 5");
//   Expr x = pool.variable("x"), y = pool.variable("y");
//   Expr upper = sup(x, constraints, std::array{y});   // y
//   Expr most = sup(x, constraints, {});               // 5
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spar/bounds/error.hpp"
#include "spar/symbolic/expr.hpp"

namespace spar::bounds {

enum class ShostakFailure {
  kNotLinear,       // a constraint, or the target in an eliminated variable, is not linear
  kMalformed,       // constraint text that does not parse or has no relation
  kInexact,         // a coefficient is a real enclosure, not an exact rational
  kUnbounded,       // SUP is +∞ (INF is -∞); also possible on infeasible constraints
  kInfeasible,      // the algorithm found the constraints contradictory (not always detected)
  kEffortExceeded,  // more than ShostakOptions::max_steps recursive steps
  kOverflow,        // a rational left 64 bits
};

// A BoundsError that also says which way the algorithm failed.
class ShostakError : public BoundsError {
 public:
  ShostakError(ShostakFailure failure, const std::string& message)
      : BoundsError(message), failure_(failure) {}
  [[nodiscard]] ShostakFailure failure() const { return failure_; }

 private:
  ShostakFailure failure_;
};

// `expression <= 0` or `expression == 0`, where expression is linear with exact rational
// coefficients (checked on construction).
struct LinearConstraint {
  enum class Relation { kLessEqual, kEqual };

  // lhs <= rhs and lhs == rhs. Throw ShostakError (kNotLinear, kInexact) naming the bad term.
  [[nodiscard]] static LinearConstraint less_equal(symbolic::Expr lhs, symbolic::Expr rhs);
  [[nodiscard]] static LinearConstraint equal(symbolic::Expr lhs, symbolic::Expr rhs);

  symbolic::Expr expression;
  Relation relation{Relation::kLessEqual};
};

// Parses "x + y <= 2", "a >= b", "2*x = y", "x < 1" (read as <=) and chains such as
// "0 <= y <= x <= 1" (one constraint per relation). Throws ShostakError (kMalformed with the
// parser's message, kNotLinear, kInexact).
[[nodiscard]] std::vector<LinearConstraint> parse_linear_constraints(symbolic::ExprPool& pool,
                                                                     std::string_view text);
// The same for text with exactly one relation.
[[nodiscard]] LinearConstraint parse_linear_constraint(symbolic::ExprPool& pool,
                                                       std::string_view text);

struct ShostakOptions {
  // Effort limit: recursive SUP/INF steps (plus piece comparisons) before giving up with
  // kEffortExceeded. SUP-INF always terminates, but may take exponentially many steps in the number
  // of variables.
  std::size_t max_steps{1'000'000};
  // Bound a target that is not a single variable as a fresh variable z with z = target (exact for
  // linear targets, see above). Off: apply the rules to the target directly (sound, maybe looser).
  bool wrap_target{true};
};

// Upper / lower bound of `target` over the constraints as an expression in `keep` (all in the
// target's pool). Throw ShostakError: kUnbounded, kInfeasible, kEffortExceeded, kOverflow,
// kNotLinear (target non-linear in a variable outside keep).
[[nodiscard]] symbolic::Expr sup(symbolic::Expr target,
                                 std::span<const LinearConstraint> constraints,
                                 std::span<const symbolic::Expr> keep,
                                 const ShostakOptions& options = {});
[[nodiscard]] symbolic::Expr inf(symbolic::Expr target,
                                 std::span<const LinearConstraint> constraints,
                                 std::span<const symbolic::Expr> keep,
                                 const ShostakOptions& options = {});

}  // namespace spar::bounds
