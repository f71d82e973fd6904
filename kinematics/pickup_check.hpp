// Deciding SPAR's pickup preconditions: bound each inequality over the uncertainty box.
//
// For `expression > 0` the verdict is
//   satisfied  the sound lower bound lo > 0 (holds for every value of the variables),
//   violated   a witness point attains a value <= 0 (inner_lo <= 0, argmin given),
//   undecided  neither (lo <= 0 < inner_lo: the bound is not tight enough to tell);
// and symmetrically with hi, inner_hi and argmax for `expression < 0`.
// check_pickup first bounds with the cheap stages only (natural interval extension,
// monotonicity, centred form), which decides the usual well-satisfied case in microseconds, and
// runs the full bound() (branch and bound, NLopt witnesses) only on what that leaves undecided.
//
// Example:
//   const PickupPreconditions pre = pickup_preconditions(geometry, gripper, peg);
//   for (const PickupCheck& check : check_pickup(pre))
//     std::cout << check.condition.name << ' ' << to_string(check.verdict) << '\n';
#pragma once

#include <array>
#include <span>

#include "bounds/bound.hpp"
#include "kinematics/pickup.hpp"

namespace spar::kinematics {

enum class Verdict { kSatisfied, kViolated, kUndecided };
[[nodiscard]] const char* to_string(Verdict verdict);

struct PickupCheck {
  PickupCondition condition;
  bounds::BoundResult bound;
  Verdict verdict{Verdict::kUndecided};
};

// The box [lower, upper] of every variable, in the order given.
[[nodiscard]] bounds::Box uncertainty_box(symbolic::ExprPool& pool,
                                          std::span<const UncertaintyVariable> variables);

[[nodiscard]] Verdict decide(const PickupCondition& condition, const bounds::BoundResult& bound);

// `full` is used for conditions the cheap pass leaves undecided.
[[nodiscard]] std::array<PickupCheck, 4> check_pickup(const PickupPreconditions& preconditions,
                                                      const bounds::BoundOptions& full = {});

}  // namespace spar::kinematics
