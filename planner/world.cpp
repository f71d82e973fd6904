#include "spar/planner/world.hpp"

#include <cmath>

#include "spar/geometry/stable_poses.hpp"
#include "spar/planner/error.hpp"

namespace spar::planner {
namespace {

using kinematics::Transform;

// The angle between the frame's z axis and world -z.
double tilt_from_down(const Transform& pose) {
  const double cosine = -pose.linear().col(2).z();
  return std::acos(std::clamp(cosine, -1.0, 1.0));
}

Transform place_pose(const Place& place, const geometry::StablePose& stable) {
  Transform pose = Transform::Identity();
  pose.translate(Eigen::Vector3d(place.x, place.y, 0.0));
  pose.rotate(Eigen::AngleAxisd(place.yaw, Eigen::Vector3d::UnitZ()));
  return pose * stable.object_to_world;
}

std::vector<PositionLabel> position_labels(const Scenario& scenario, const ObjectSpec& object) {
  std::vector<PositionLabel> labels;
  labels.push_back({.name = "initial",
                    .stable_pose = object.initial_stable_pose.value_or(-1),
                    .place = -1,
                    .pose = object.initial_pose});
  for (std::size_t s = 0; s < object.stable_poses.size(); ++s)
    for (std::size_t p = 0; p < scenario.places.size(); ++p)
      labels.push_back({.name = object.stable_poses[s].label + "@" + scenario.places[p].name,
                        .stable_pose = static_cast<int>(s),
                        .place = static_cast<int>(p),
                        .pose = place_pose(scenario.places[p], object.stable_poses[s])});
  return labels;
}

}  // namespace

WorldModel::WorldModel(Scenario scenario) : scenario_(std::move(scenario)) {
  gripper_ = scenario_.robot.gripper;
  gripper_.max_approach_tilt = scenario_.robot.max_tool_tilt;
  for (const ObjectSpec& spec : scenario_.objects) {
    ObjectWorld object;
    object.grasps = geometry::compute_grasps(spec.model, gripper_, scenario_.grasping);
    if (object.grasps.empty())
      throw PlanError(spec.location.str() + ": object '" + spec.name +
                      "' has no grasp the gripper can make (opening " +
                      std::to_string(gripper_.max_opening) + " m)");
    object.positions = position_labels(scenario_, spec);
    object.reachable.assign(object.grasps.size(), std::vector<char>(object.positions.size(), 0));
    for (std::size_t g = 0; g < object.grasps.size(); ++g)
      for (std::size_t p = 0; p < object.positions.size(); ++p)
        object.reachable[g][p] =
            grasp_usable_at(object.grasps[g], spec, object.positions[p]) &&
            reach(object.positions[p].pose * object.grasps[g].gripper_in_object).reachable;
    objects_.push_back(std::move(object));
  }
  for (const Goal& goal : scenario_.goals) {
    const AssembledGoal& assembled = std::get<AssembledGoal>(goal);
    GoalWorld tables;
    tables.held = object_index(assembled.held);
    tables.fixed = object_index(assembled.fixed);
    const ObjectWorld& held = objects_[tables.held];
    const ObjectWorld& fixed = objects_[tables.fixed];
    const ObjectSpec& fixed_spec = scenario_.objects[tables.fixed];
    for (const geometry::Grasp& grasp : held.grasps)
      tables.grasp_leaves_mating_free.push_back(
          geometry::grasp_leaves_free(grasp, assembled.held_faces));
    for (const PositionLabel& position : fixed.positions) {
      const bool faces_free =
          position.stable_pose < 0 ||
          geometry::pose_leaves_free(fixed_spec.stable_poses[position.stable_pose],
                                     assembled.fixed_faces);
      const Eigen::Vector3d mating = position.pose.linear() * assembled.mating_vector;
      tables.mating_pose.push_back(faces_free && -mating.z() >= std::cos(kFrictionCone));
    }
    tables.mate_reachable.assign(held.grasps.size(), std::vector<char>(fixed.positions.size(), 0));
    for (std::size_t g = 0; g < held.grasps.size(); ++g)
      for (std::size_t p = 0; p < fixed.positions.size(); ++p)
        tables.mate_reachable[g][p] =
            reach(fixed.positions[p].pose * assembled.relative * held.grasps[g].gripper_in_object)
                .reachable;
    goals_.push_back(std::move(tables));
  }
}

int WorldModel::object_index(std::string_view name) const {
  for (std::size_t i = 0; i < scenario_.objects.size(); ++i)
    if (scenario_.objects[i].name == name) return static_cast<int>(i);
  std::string known;
  for (const ObjectSpec& object : scenario_.objects)
    known += (known.empty() ? "" : ", ") + object.name;
  throw PlanError("no object '" + std::string(name) + "' (known: " + known + ")");
}

const GoalWorld* WorldModel::goal(int held, int fixed) const {
  for (const GoalWorld& tables : goals_)
    if (tables.held == held && tables.fixed == fixed) return &tables;
  return nullptr;
}

Transform WorldModel::flange_in_base(const Transform& gripper_pose) const {
  return scenario_.robot.base.inverse(Eigen::Isometry) * gripper_pose *
         scenario_.robot.tool.inverse(Eigen::Isometry);
}

Reach WorldModel::reach(const Transform& gripper_pose) const {
  Reach result;
  result.tilt = tilt_from_down(gripper_pose);
  if (result.tilt > scenario_.robot.max_tool_tilt) return result;  // SPAR: never reach up
  for (kinematics::JointSolution& solution :
       scenario_.robot.arm.inverse(flange_in_base(gripper_pose)))
    if (solution.within_limits) {
      result.solution = std::move(solution);
      break;
    }
  result.reachable = result.solution.has_value();
  return result;
}

std::optional<std::string> WorldModel::relaxed_obstacle() const {
  // reachable_positions[o][p]: object o can be brought to position p by moves alone.
  std::vector<std::vector<char>> reachable_positions;
  for (const ObjectWorld& object : objects_) {
    std::vector<char> seen(object.positions.size(), 0);
    std::vector<std::size_t> queue = {0};
    seen[0] = 1;
    while (!queue.empty()) {
      const std::size_t from = queue.back();
      queue.pop_back();
      for (std::size_t to = 0; to < object.positions.size(); ++to) {
        if (seen[to] || object.positions[to].place < 0) continue;
        for (std::size_t g = 0; g < object.grasps.size(); ++g)
          if (object.reachable[g][from] && object.reachable[g][to]) {
            seen[to] = 1;
            queue.push_back(to);
            break;
          }
      }
    }
    reachable_positions.push_back(std::move(seen));
  }
  for (const GoalWorld& goal : goals_) {
    const std::string& held = scenario_.objects[goal.held].name;
    const std::string& fixed = scenario_.objects[goal.fixed].name;
    const ObjectWorld& h = objects_[goal.held];
    bool held_graspable = false, fixed_placeable = false, insertable = false;
    for (std::size_t g = 0; g < h.grasps.size(); ++g)
      for (std::size_t p = 0; p < h.positions.size(); ++p)
        held_graspable |= reachable_positions[goal.held][p] && h.reachable[g][p] != 0;
    for (std::size_t p = 0; p < goal.mating_pose.size(); ++p)
      fixed_placeable |= reachable_positions[goal.fixed][p] && goal.mating_pose[p];
    for (std::size_t g = 0; g < h.grasps.size(); ++g) {
      bool graspable = false;
      for (std::size_t p = 0; p < h.positions.size(); ++p)
        graspable |= reachable_positions[goal.held][p] && h.reachable[g][p] != 0;
      for (std::size_t p = 0; p < goal.mating_pose.size() && graspable; ++p)
        insertable |= goal.grasp_leaves_mating_free[g] && reachable_positions[goal.fixed][p] &&
                      goal.mating_pose[p] && goal.mate_reachable[g][p];
    }
    if (!held_graspable)
      return "the robot cannot grasp " + held +
             " at its initial pose (no grasp within reach and "
             "the tilt limit)";
    if (!fixed_placeable)
      return fixed + " cannot be brought into a pose for assembled(" + held + ", " + fixed +
             ") (its mating faces off the table, the mating vector pointing down) by moves the "
             "robot can make";
    if (!insertable)
      return "no grasp of " + held +
             " that leaves its mating faces free both picks it up and "
             "reaches the insertion into " +
             fixed + " at a pose " + fixed + " can be brought to";
  }
  return std::nullopt;
}

bool WorldModel::grasp_usable_at(const geometry::Grasp& grasp, const ObjectSpec& object,
                                 const PositionLabel& position) const {
  if (position.stable_pose < 0) return true;  // no table lookup: the IK tilt test still applies
  return geometry::grasp_usable(grasp, object.stable_poses[position.stable_pose], gripper_);
}

}  // namespace spar::planner
