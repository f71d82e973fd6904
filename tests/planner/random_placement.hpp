// A RapidCheck generator step the planner properties share: random initial poses for a
// scenario's objects.
#pragma once

#include <rapidcheck.h>

#include <Eigen/Geometry>
#include <cmath>
#include <utility>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/planner/scenario.hpp"

namespace spar::planner::testing {

// Puts each object (at most three) at its own spot among three in front of the robot, resting
// in a random one of its stable poses, turned about world z by a random multiple of 45 degrees.
inline void place_objects_at_random(Scenario& scenario) {
  const std::vector<std::pair<double, double>> spots = {{20, 0}, {14, 12}, {24, 4}};  // inches
  const auto spot_indices = *rc::gen::unique<std::vector<int>>(
      scenario.objects.size(), rc::gen::inRange(0, static_cast<int>(spots.size())));
  for (std::size_t o = 0; o < scenario.objects.size(); ++o) {
    ObjectSpec& object = scenario.objects[o];
    const int pose = *rc::gen::inRange(0, static_cast<int>(object.stable_poses.size()));
    const int yaw_step = *rc::gen::inRange(0, 8);
    const auto [x, y] = spots[spot_indices[o]];
    kinematics::Transform placed = kinematics::Transform::Identity();
    placed.translate(Eigen::Vector3d(x * units::kInch, y * units::kInch, 0));
    placed.rotate(Eigen::AngleAxisd(yaw_step * M_PI / 4, Eigen::Vector3d::UnitZ()));
    object.initial_pose = placed * object.stable_poses[pose].object_to_world;
    object.initial_stable_pose = pose;
  }
}

}  // namespace spar::planner::testing
