// The JSON form of a planning run (`spar plan --json`). Keys named normative in the planner issues
// are kept exactly: status (planned | no_plan) and reason, units, robot {base, tool}, family {steps,
// ordering, variables, arcs}, instances {count, limit_reached}, chosen {steps: [...]} whose steps
// carry id, action, object, grasp {label, faces, width, gripper_in_object}, object_pose,
// stable_pose, gripper_pose, joints (radians), configuration, and for assemblies fixed_object,
// fixed_pose, held_pose. Lengths are in the scenario's length unit; joint angles in radians.
//
// Example:
//   const planner::PlanResult result = planner::plan(scenario, planner::builtin_domain());
//   std::cout << plan_json(result).dump(2) << '\n';
#pragma once

#include <nlohmann/json.hpp>

#include "planner/plan.hpp"

namespace spar::reports {

[[nodiscard]] nlohmann::ordered_json plan_json(const planner::PlanResult& result);

}  // namespace spar::reports
