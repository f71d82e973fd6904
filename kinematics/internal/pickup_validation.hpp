// The argument checks shared by the pickup paths (pickup_preconditions, PickupChecker,
// PickupTemplate), so each mistake gets one message whichever path meets it. Not public API.
#pragma once

#include <span>

#include "bounds/interval.hpp"
#include "kinematics/pickup.hpp"

namespace spar::kinematics::internal {

// Throws KinematicsError unless 0 < finger_opening and 0 < object_width. (pickup.cpp)
void check_pickup_geometry(const PickupGeometry& geometry);

// ranges[i] = [given[i].lower, given[i].upper]. Throws KinematicsError unless `given` names the
// `expected` variables in the same order with non-empty ranges; ranges.size() == expected.size().
// (pickup_check.cpp)
void pickup_ranges(std::span<const UncertaintyVariable> expected,
                   std::span<const UncertaintyVariable> given, std::span<bounds::Interval> ranges);

}  // namespace spar::kinematics::internal
