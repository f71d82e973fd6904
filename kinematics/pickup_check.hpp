// Deciding SPAR's pickup preconditions: the four inequalities as a bounds::ConditionSet.
//
// Each PickupCondition `expression > 0` (positive) or `expression < 0` becomes the
// bounds::Inequality with relation kGreater / kLess and threshold 0, and the verdicts are
// bounds::decide's (bounds/inequality.hpp: satisfied by a sound bound, violated at a witness,
// else undecided). PickupChecker compiles the four expressions once into one tape (they share the
// contact points' subexpressions): check() costs one natural interval evaluation of that tape and
// one at the box centre; a condition that is not proved goes on to a full bound (monotonicity,
// centred form, branch and bound, NLopt witnesses) so a violation is reported with its tight
// bound and worst witness. Checking over several boxes (widening the uncertainty, sensing that
// shrinks it) reuses the tape and the full bounds' compiled problems. The checker copies the
// preconditions; their pool must outlive it.
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

#include "spar/bounds/bound.hpp"
#include "spar/bounds/condition_set.hpp"
#include "spar/bounds/inequality.hpp"
#include "spar/kinematics/pickup.hpp"

namespace spar::kinematics {

// The verdict vocabulary is bounds' (one enum, one decide); named here for the pickup's callers.
using bounds::to_string;
using bounds::Verdict;

struct PickupCheck {
  PickupCondition condition;
  // bounds::ConditionCheck::bound: the natural enclosure (evaluations 1) when that proves the
  // condition, else the full bound.
  bounds::BoundResult bound;
  Verdict verdict{Verdict::kUndecided};
};

// The box [lower, upper] of every variable, in the order given.
[[nodiscard]] bounds::Box uncertainty_box(symbolic::ExprPool& pool,
                                          std::span<const UncertaintyVariable> variables);

// `expression > 0` (positive) or `expression < 0` as an inequality.
[[nodiscard]] bounds::Inequality as_inequality(const PickupCondition& condition);

class PickupChecker {
 public:
  explicit PickupChecker(const PickupPreconditions& preconditions);

  // `variables` must name the preconditions' variables in the same order (their bounds may
  // differ); throws KinematicsError otherwise. `full` is used for conditions the natural
  // extension does not prove.
  [[nodiscard]] std::array<PickupCheck, 4> check(std::span<const UncertaintyVariable> variables,
                                                 const bounds::BoundOptions& full = {});

 private:
  PickupPreconditions preconditions_;
  bounds::ConditionSet conditions_;  // the four conditions, in order, over preconditions_.variables
};

// PickupChecker(preconditions).check(preconditions.variables, full).
[[nodiscard]] std::array<PickupCheck, 4> check_pickup(const PickupPreconditions& preconditions,
                                                      const bounds::BoundOptions& full = {});

}  // namespace spar::kinematics
