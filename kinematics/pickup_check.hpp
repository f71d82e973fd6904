// Deciding SPAR's pickup preconditions: bound each inequality over the uncertainty box.
//
// For `expression > 0` the verdict is
//   satisfied  the sound lower bound lo > 0 (holds for every value of the variables),
//   violated   a witness point attains a value <= 0 (inner_lo <= 0, argmin given),
//   undecided  neither (lo <= 0 < inner_lo: the bound is not tight enough to tell);
// and symmetrically with hi, inner_hi and argmax for `expression < 0`.
//
// PickupChecker compiles the four expressions once into one tape (they share the contact points'
// subexpressions) and keeps an interval evaluator on it. check() then costs one natural interval
// evaluation of that tape for the usual well-satisfied case, plus one evaluation at the box
// centre for the inner value; only a condition the natural extension leaves undecided goes to the
// full bounds::bound() (monotonicity, centred form, branch and bound, NLopt witnesses). Checking
// the same conditions over several boxes (widening the uncertainty, sensing that shrinks it)
// reuses the tape. The checker copies the preconditions; their pool must outlive it.
//
// Example:
//   const PickupPreconditions pre = pickup_preconditions(geometry, gripper, peg);
//   PickupChecker checker(pre);
//   for (const PickupCheck& check : checker.check(pre.variables))
//     std::cout << check.condition.name << ' ' << to_string(check.verdict) << '\n';
#pragma once

#include <array>
#include <span>
#include <vector>

#include "bounds/bound.hpp"
#include "kinematics/pickup.hpp"
#include "symbolic/tape.hpp"

namespace spar::kinematics {

enum class Verdict { kSatisfied, kViolated, kUndecided };
[[nodiscard]] const char* to_string(Verdict verdict);

struct PickupCheck {
  PickupCondition condition;
  // Decided by the natural extension: [lo, hi] is that enclosure, argmin = argmax = the box
  // centre, status kEffortLimit (no tightening was attempted). Otherwise bounds::bound()'s result.
  bounds::BoundResult bound;
  Verdict verdict{Verdict::kUndecided};
};

// The box [lower, upper] of every variable, in the order given.
[[nodiscard]] bounds::Box uncertainty_box(symbolic::ExprPool& pool,
                                          std::span<const UncertaintyVariable> variables);

[[nodiscard]] Verdict decide(const PickupCondition& condition, const bounds::BoundResult& bound);

class PickupChecker {
 public:
  explicit PickupChecker(const PickupPreconditions& preconditions);
  // The evaluator points into tape_: neither copied nor moved.
  PickupChecker(const PickupChecker&) = delete;
  PickupChecker& operator=(const PickupChecker&) = delete;

  // `variables` must name the preconditions' variables in the same order (their bounds may
  // differ); throws KinematicsError otherwise. `full` is used for conditions the natural
  // extension leaves undecided.
  [[nodiscard]] std::array<PickupCheck, 4> check(std::span<const UncertaintyVariable> variables,
                                                 const bounds::BoundOptions& full = {});

 private:
  PickupPreconditions preconditions_;
  std::vector<symbolic::Expr> inputs_;  // preconditions_.variables as expressions, same order
  symbolic::Tape tape_;                 // outputs: the four conditions' expressions, in order
  symbolic::TapeEvaluator<bounds::Interval> evaluator_;  // on tape_
  std::vector<bounds::Interval> box_, centre_;           // scratch, one entry per input
};

// PickupChecker(preconditions).check(preconditions.variables, full).
[[nodiscard]] std::array<PickupCheck, 4> check_pickup(const PickupPreconditions& preconditions,
                                                      const bounds::BoundOptions& full = {});

}  // namespace spar::kinematics
