// A RapidCheck generator step the planner properties share: random initial poses for a
// scenario's objects, and planning them (a placement whose objects touch is discarded).
#pragma once

#include <rapidcheck.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string_view>
#include <utility>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
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

// plan() of a scene placed by place_objects_at_random; a case whose random spots, poses and yaws
// made two objects touch is discarded (the world model refuses such a start with a PlanError: the
// properties are about the plans of valid scenes).
inline PlanResult plan_placed(const Scenario& scenario, const Domain& domain,
                              const PlanOptions& options) {
  try {
    return plan(scenario, domain, options);
  } catch (const PlanError& error) {
    if (std::string_view(error.what()).find("interpenetrate or touch") != std::string_view::npos)
      RC_DISCARD("the random placement made two objects touch");
    throw;
  }
}

}  // namespace spar::planner::testing
