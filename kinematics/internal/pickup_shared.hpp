// What the pickup paths (pickup_preconditions, PickupChecker, PickupTemplate) share: the argument
// checks, so each mistake gets one message whichever path meets it, and the last steps of the
// conditions, so both builds give every variable the same occurrences. Not public API.
#pragma once

#include <array>
#include <span>

#include "spar/bounds/interval.hpp"
#include "spar/kinematics/pickup.hpp"

namespace spar::kinematics::internal {

// Throws KinematicsError unless 0 < finger_opening and 0 < object_width. (pickup.cpp)
void check_pickup_geometry(const PickupGeometry& geometry);

// ranges[i] = [given[i].lower, given[i].upper]. Throws KinematicsError unless `given` names the
// `expected` variables in the same order with non-empty ranges; ranges.size() == expected.size().
// (pickup_check.cpp)
void pickup_ranges(std::span<const UncertaintyVariable> expected,
                   std::span<const UncertaintyVariable> given, std::span<bounds::Interval> ranges);

// The four conditions (pickup.hpp's order and names) from the contact points C1, C2 in the ideal
// gripper frame, (T_O T_G)^-1 C (x and y are used), the manipulator error T_ΔM and the finger
// offsets trans(0, ∓W_m/2, 0): [0,1,0,0] offset^-1 T_ΔM^-1 (T_O T_G)^-1 C. (pickup.cpp)
[[nodiscard]] std::array<PickupCondition, 4> conditions_from_contacts(
    const std::array<SymbolicPoint, 2>& in_ideal, const SymbolicTransform& manipulator_error,
    const std::array<SymbolicTransform, 2>& finger_offsets);

}  // namespace spar::kinematics::internal
