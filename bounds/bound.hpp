// bound(): sound SUP/INF of an expression over a box, with inner bounds that prove how tight it is.
//
// Given f, a box of variable ranges and optional constraints `g rel 0`, bound() returns
//   lo <= inner_lo <= inner_hi <= hi   with   [inner_lo, inner_hi] ⊆ f(feasible box) ⊆ [lo, hi].
// [lo, hi] is always sound (outward-rounded interval arithmetic, every method intersected):
// natural interval extension on the tape, monotonicity from interval gradients (a variable is
// fixed at an end point; the gradient is taken again on the narrower face while that fixes more),
// the mean-value (centred) form at Baumann's optimal centre, and best-first branch and bound that
// bisects the variable with the largest |gradient| x width until `hi - inner_hi` and
// `inner_lo - lo` are both <= tolerance x (inner_hi - inner_lo), or the effort limit is reached.
// Both directions search one tree: a box's split follows from the box alone, so each box is
// evaluated once (one value-and-gradient pass) and the second search reuses the first's boxes.
// Where f is affine in that variable (a polynomial of degree <= 1 in it: f = A·v + B) and there
// are no constraints, f's extremes lie on v's end points, so the box splits into those two faces.
// Linear constraints contract every box; any constraint discards boxes where it certainly fails.
// If that stops at the effort limit, SMP's rewrite of f (symbolic/smp.hpp, an identity wherever
// f is defined) is bounded the same way and the outer bounds are intersected.
// inner_lo / inner_hi are values f attains at the witness points argmin / argmax (each
// checked feasible with interval arithmetic), found from box midpoints, the corner the centre's
// gradient points to, a vertex ascent (a full bound without constraints, up to 32 variables:
// corners the gradient points to and one-variable moves; elsewhere the box's corners, up to 10
// variables) and NLopt (a local search with tape gradients; a global one, DIRECT-L, only where
// branch and bound on a quarter of the budget has not converged against the others). NLopt never
// decides [lo, hi].
//
// Example:
//   symbolic::ExprPool pool;
//   Expr x = pool.variable("x"), y = pool.variable("y");
//   Box box;  box.add(x, -5, 5);  box.add(y, -5, 5);
//   BoundResult r = bound(sin(x) - cos(y) - sin(x) * cos(x), box, {.tolerance = 1e-4});
//   // r.lo <= -2.29904 and r.hi >= 2.29904, r.hi - r.inner_hi <= 1e-4 * (r.inner_hi - r.inner_lo)
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spar/bounds/error.hpp"
#include "spar/bounds/interval.hpp"
#include "spar/common/relation.hpp"
#include "spar/symbolic/expr.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds {

// Variables with their closed ranges; variables[i] ranges over ranges[i].
struct Box {
  std::vector<symbolic::Expr> variables;
  std::vector<Interval> ranges;
  // Throws BoundsError for NaN, lo > hi, or a variable already in the box.
  void add(symbolic::Expr variable, double lo, double hi);
};

// The relation of an inequality or constraint (common/relation.hpp: one name table).
using Relation = spar::Relation;

// g rel 0. Strict relations are bounded as their closure (sound); witnesses satisfy them exactly.
struct Constraint {
  symbolic::Expr g;
  Relation relation{Relation::kLessEqual};
};

// An inequality `f relation threshold` to decide rather than bound tightly (BoundOptions::decide).
struct DecisionTarget {
  Relation relation{Relation::kLessEqual};
  double threshold{0.0};
};

// Which stages run (all on by default; the benchmark switches them to compare).
struct BoundOptions {
  double tolerance{1e-3};  // relative to the attained width inner_hi - inner_lo
  // The effort limit counts work, never time, so a result does not depend on the machine's speed
  // or load: at most max_box_evaluations boxes (both directions together) and at most max_work
  // work units (one per arithmetic tape instruction, 10 per transcendental one; a box costs about
  // 6 passes over f's and the constraints' tapes, an NLopt evaluation one), so a huge expression
  // stops in proportion to its size: the default is a few seconds of work on this machine.
  // The boxes kept in the search tree are capped at about 4M intervals (100 MB) whatever the
  // number of variables.
  std::size_t max_box_evaluations{200'000};
  std::size_t max_work{100'000'000};
  // Optional wall-clock limit in seconds; 0 (the default) is none. When it fires the result says
  // so (time_limited) and, unlike the work limits, depends on the machine.
  double max_seconds{0.0};
  bool inner{true};  // ascent and NLopt (midpoints, corners, deciding's gradient corner always)
  bool monotonicity{true};
  bool centred_form{true};
  bool branch_and_bound{true};
  // If f does not converge within 1/8 of the budget, bound SMP's rewrite of f (fewer repeated
  // variables, equal to f wherever f is defined) with another 1/8 and intersect the outer bounds;
  // only if that does not settle it does f get the whole budget (at most 1.25 budgets in all).
  // Before all that, a small f (at most 256 tape instructions) that SMP rewrites to use every
  // variable once (t/(t + 1) -> 1 - 1/(t + 1)) has that rewrite bounded with 1/8 first: it is
  // exact up to rounding, so it usually settles f alone (at most 1.375 budgets in all). Deciding
  // (below) runs f's first stage before any rewrite: it settles most inequalities without SMP.
  bool simplify{true};
  // The box widths (one per variable, >= 0) that choose SMP's rewrite above; empty: the bounded
  // box's own. SMP weighs a repeated variable by its width, so the rewrite depends on them, and a
  // BoundProblem keeps the last few rewrites by widths. Boxes that differ only in scale (reverse
  // analysis: one precondition at many scales) can share one rewrite by passing the same widths.
  // Any widths give a rewrite equal to f wherever f is defined: bounds stay sound, only which
  // rewrite (and so how tight) may differ.
  std::vector<double> rewrite_widths{};
  // Deciding, not bounding: with a target, only the side of f the relation limits is searched
  // (hi for `<`, `<=`; lo for `>`, `>=`), and the search stops as soon as decide()
  // (bounds/inequality.hpp) would answer: that side's sound bound proves the inequality, or an
  // attained witness value breaks it. The corner the gradient at the box centre points to is
  // tried first (one point; for a nearly linear f it is the extremum, so a violation is usually
  // found there). Branch and bound then runs on a quarter of the budget with the box centre and
  // the boxes' midpoints as witnesses (a proof needs no witness); if that leaves the verdict
  // open, the corners are tried and branch and bound goes on with the rest; only if the verdict
  // is still open does NLopt (with `inner`) look for a violating point. The other side is the
  // root box's enclosure (sound, loose). The verdict is the one the full bound would give
  // whenever both decide; the bound is only as tight as deciding needed, and its status is
  // kEffortLimit unless that side converged.
  std::optional<DecisionTarget> decide{};
  // With `decide`: a witness that breaks the target before any box is bounded (the box centre, or
  // the gradient's corner tried first) ends the search there, and the bound's sides are the root
  // box's natural enclosure (sound, looser than deciding's root box gives otherwise; the result
  // says so: BoundResult::stopped_at_witness). The verdict is the same. For callers that need only
  // verdicts (phase 2's repair search): bounding the root box costs several gradient passes.
  bool stop_at_witness{false};
};

enum class BoundStatus {
  kConverged,    // both gaps within tolerance
  kEffortLimit,  // sound but not within tolerance (max_box_evaluations or max_seconds hit)
  kUnbounded,    // lo = -inf or hi = +inf: the range is (or could not be shown not to be) unbounded
  kInfeasible,   // no point of the box satisfies the constraints: lo = +inf, hi = -inf
};
[[nodiscard]] const char* to_string(BoundStatus status);

// Invariant (checked by check_invariants(), on every result path in debug builds): when witnesses
// exist, lo <= inner_lo <= inner_hi <= hi (or, witness values too loose, [hi, lo]). Without
// witnesses (argmin_value and argmax_value empty: no feasible point where f is defined was
// verified) inner_lo = hi and inner_hi = lo, an empty inner range. (With no variables at all a
// witness is the empty point: argmin is then empty too.)
struct BoundResult {
  double lo{0.0}, hi{0.0};  // sound: lo <= f <= hi on the feasible box
  // Attained: the values of f at argmin and argmax, i.e. argmin_value.hi and argmax_value.lo
  // clamped into [lo, hi]; if those cross by a rounding (f varies less than that between the
  // witnesses) both are their midpoint. If they cross by more (an overflow enclosed by
  // [DBL_MAX, inf], a point on atan2's cut by [-pi, pi]) nothing attained is known: inner_lo = hi
  // and inner_hi = lo, as without witnesses (has_inner_range() is false).
  double inner_lo{0.0}, inner_hi{0.0};
  std::vector<double> argmin, argmax;  // witness points in Box::variables order
  // Rigorous enclosures of f at argmin and argmax (outward-rounded evaluations): f(argmin) <=
  // argmin_value.hi and f(argmax) >= argmax_value.lo exactly. decide() uses these. Empty when
  // there is no witness.
  Interval argmin_value{Interval::empty()}, argmax_value{Interval::empty()};
  BoundStatus status{BoundStatus::kConverged};
  bool possibly_undefined{false};  // f may be undefined somewhere in the box (domain error)
  bool time_limited{false};        // BoundOptions::max_seconds stopped it (machine-dependent)
  std::size_t evaluations{0};      // boxes evaluated (each once, for both directions)
  // BoundOptions::stop_at_witness ended the search before any box: [lo, hi] is f's natural
  // enclosure over the root box.
  bool stopped_at_witness{false};
  // Whether [inner_lo, inner_hi] is a range of attained values (witnesses with values enclosed
  // within rounding); false for no witness, an infeasible box, or too loose witness values.
  [[nodiscard]] bool has_inner_range() const {
    return !argmin_value.is_empty() && !argmax_value.is_empty() && inner_lo <= inner_hi;
  }
  // Why there is no inner range ("" when has_inner_range()): for messages and the JSON record.
  [[nodiscard]] std::string_view why_no_inner_range() const;
  // Measured tightness: max(hi - inner_hi, inner_lo - lo) / (inner_hi - inner_lo).
  [[nodiscard]] double relative_gap() const;
  // Throws std::logic_error naming the broken invariant (see above).
  void check_invariants() const;
};

// Final inner bounds from the witnesses' enclosures (BoundResult's rule, the one every bound
// uses): without witnesses inner_lo = hi and inner_hi = lo; else argmin_value.hi and
// argmax_value.lo clamped into [lo, hi], and their midpoint for both if they cross by a rounding
// (1e-12 relative); crossing by more, inner_lo = hi and inner_hi = lo (nothing attained known).
// For code that re-encloses the witnesses' values (kinematics' pickup template).
void order_inner_bounds(BoundResult& result);

// f and its constraints compiled once over an ordered list of variables, bounded over any number
// of boxes: the tapes, their evaluators, the linear constraints' forms and (lazily, per box widths)
// SMP's rewrite of f are built once and reused. bound(ranges) gives exactly what the free bound()
// gives for the same box: nothing carried from one call to the next changes a result, so results
// do not depend on the order of calls. No random numbers are used (NLopt's global stages are
// DIRECT-L and, with constraints, the original DIRECT-L, both deterministic), so no RNG is seeded.
// The expressions' pool must outlive the problem. Not thread-safe: one problem per thread.
//
// Example:
//   BoundProblem problem(f, std::vector{x, y});
//   for (double w : {0.1, 0.2, 0.4}) {
//     const std::vector<Interval> ranges{{-w, w}, {-w, w}};
//     if (problem.bound(ranges).hi < 1) std::cout << "holds up to " << w << '\n';
//   }
class BoundProblem {
 public:
  // Throws BoundsError if a variable is not a variable or repeats, or if f or a constraint uses a
  // variable that is not among `variables`.
  BoundProblem(symbolic::Expr f, std::span<const symbolic::Expr> variables,
               std::span<const Constraint> constraints = {});
  BoundProblem(BoundProblem&&) noexcept;
  BoundProblem& operator=(BoundProblem&&) noexcept;
  ~BoundProblem();

  [[nodiscard]] const std::vector<symbolic::Expr>& variables() const;
  // ranges[i] is the range of variables()[i]. Throws BoundsError for a wrong count, a NaN,
  // infinite or empty range, or a negative tolerance.
  [[nodiscard]] BoundResult bound(std::span<const Interval> ranges,
                                  const BoundOptions& options = {});

  // Per variable i, the share of the width of f's mean-value enclosure over the box that pinning
  // variable i to pins[i] removes (which variables take up the bound: phase 2's blame). With G
  // enclosing f's gradient over the box (one reverse-mode interval pass),
  //   f(X) ⊆ f(p) + Σ_j G_j·(X_j - p_j),
  // and pinning x_i to p_i removes exactly the term T_i = G_i·(X_i - p_i), so
  //   share_i = width(T_i) / width(enclosure),
  // each in [0, 1], summing to at most 1 (f(p)'s rounding takes the rest). Where G has no finite
  // enclosure (f not differentiable somewhere in the box), the natural interval extension F
  // stands in: share_i = (width F(X) - width F(X, x_i = p_i)) / width F(X), clamped to [0, 1].
  // All are 0 when the enclosure has zero or unbounded width. Constraints are not used.
  // Cost: one value-and-gradient pass over f's tape (or n + 1 interval passes).
  // Throws BoundsError for wrong counts, a bad range, or a pin outside its range.
  [[nodiscard]] std::vector<double> width_shares(std::span<const Interval> ranges,
                                                 std::span<const double> pins);

 private:
  friend class ConditionSet;  // builds its problems on slices of its own tape
  // f without constraints, on `tape_of_f`: what Tape::compile({f}, variables) would give (a
  // slice of a tape compiled with f among its outputs over these variables, already checked).
  BoundProblem(symbolic::Expr f, std::span<const symbolic::Expr> variables,
               symbolic::Tape tape_of_f);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// BoundProblem(f, box.variables, constraints).bound(box.ranges, options).
// Throws BoundsError if f or a constraint uses a variable that is not in the box.
[[nodiscard]] BoundResult bound(symbolic::Expr f, const Box& box, const BoundOptions& options = {},
                                std::span<const Constraint> constraints = {});

}  // namespace spar::bounds
