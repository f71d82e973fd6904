// WorldModel: what SPAR's constraint manipulation system knows about a scenario, computed once:
// each object's grasp labels and position labels, and the geometric predicates of the constraint
// network as tables over label pairs (the planner posts them as arcs and unary constraints).
//
// Labels (SPAR quantizes geometry so plan variables take symbolic values):
//   grasp labels     an object's quantized grasps (geometry/grasps.hpp), "G1", "G2", ...
//   position labels  [0] "initial": the object's initial pose; then, for every stable pose s and
//                    every free place p of the scenario, "P<s>@<place>": resting in s above p,
//                    turned by the place's yaw. Every position is an absolute world pose.
// Predicates (tables indexed [grasp][position]):
//   reachable(g, p)       the grasp is usable in p's stable pose (no contact face on the table, the
//                         gripper not below it) and the robot reaches T = T_O(p) T_G with an
//                         in-limit IK solution whose approach axis lies within the robot's
//                         max_tool_tilt of world -z (SPAR: never reach up through the table);
//   mate_reachable(g, p)  for an assembled goal: the robot reaches T = T_fixed(p) Ta T_G the same
//                         way (held grasp g, fixed position p);
//   grasps_leaving_mating_faces_free   the held object's grasps obscuring none of its mating faces;
//   mating_poses          the fixed object's positions whose stable pose leaves its mating faces
//                         off the table and turn the mating vector into the friction cone (within
//                         kFrictionCone of world -z: the insertion pushes the object onto the
//                         table).
// An initial pose that is not a stable pose has no table lookup: its contact faces count as free
// (SPAR: the sensing system tells), and it is a mating pose only by the mating-vector test.
//
// Example:
//   const WorldModel world(load_scenario("examples/peg_block_face_down.yaml"));
//   const int block = world.object_index("block");
//   world.object(block).positions[0].name;              // "initial"
//   world.object(block).reachable[0][0];                // G1 reachable at the initial pose?
//   const Reach reach = world.reach(gripper_pose);      // joints, configuration, tilt
#pragma once

#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "spar/geometry/grasps.hpp"
#include "spar/kinematics/robot.hpp"
#include "spar/planner/scenario.hpp"

namespace spar::planner {

// Half-angle about world -z within which the world mating vector must lie.
inline constexpr double kFrictionCone = std::numbers::pi / 4;

struct PositionLabel {
  std::string name;     // "initial" or "P5@left"
  int stable_pose{-1};  // index into the object's stable_poses, -1 if the pose is not one
  int place{-1};        // index into Scenario::places, -1 for the initial pose
  kinematics::Transform pose{kinematics::Transform::Identity()};  // object frame in the world
};

struct ObjectWorld {
  std::vector<geometry::Grasp> grasps;
  std::vector<PositionLabel> positions;      // [0] is the initial pose
  std::vector<std::vector<char>> reachable;  // [grasp][position]
};

// The tables of one assembled goal.
struct GoalWorld {
  int held{0};  // object indices
  int fixed{0};
  std::vector<char> grasp_leaves_mating_free;     // [held grasp]
  std::vector<char> mating_pose;                  // [fixed position]
  std::vector<std::vector<char>> mate_reachable;  // [held grasp][fixed position]
};

// One IK query: the gripper frame at `gripper_pose` (world).
struct Reach {
  bool reachable{false};  // an in-limit solution exists and the approach axis points down
  double tilt{0.0};       // angle between the gripper z axis and world -z
  // The first in-limit solution in the robot's order (kinematics/robot.hpp: Puma and UR arms by
  // label, lun first; a 7-joint arm's largest limit margin first); none when the tilt fails.
  std::optional<kinematics::JointSolution> solution;
};

class WorldModel {
 public:
  // Computes every label and table. Throws PlanError if an object has no grasp or no position.
  explicit WorldModel(Scenario scenario);

  [[nodiscard]] const Scenario& scenario() const { return scenario_; }
  [[nodiscard]] std::size_t object_count() const { return objects_.size(); }
  [[nodiscard]] const ObjectWorld& object(int index) const { return objects_.at(index); }
  // Throws PlanError naming the known objects.
  [[nodiscard]] int object_index(std::string_view name) const;
  [[nodiscard]] const std::vector<GoalWorld>& goals() const { return goals_; }
  // The goal tables for assembled(held, fixed), or nullptr.
  [[nodiscard]] const GoalWorld* goal(int held, int fixed) const;
  // The gripper spec used for grasps and usability (the scenario's, with the robot's tilt cone).
  [[nodiscard]] const geometry::GripperSpec& gripper() const { return gripper_; }

  [[nodiscard]] Reach reach(const kinematics::Transform& gripper_pose) const;

  // Why the goals cannot be reached even with the interactions between steps ignored (each object
  // moved alone, places shared), naming the first object or goal that fails; nullopt when that
  // relaxed problem is solvable. Positions reachable by moves: from the initial one, any position
  // a grasp reaches together with the current one (pick up there, put down here).
  [[nodiscard]] std::optional<std::string> relaxed_obstacle() const;
  // The flange pose in the robot's base frame for a gripper pose in the world.
  [[nodiscard]] kinematics::Transform flange_in_base(
      const kinematics::Transform& gripper_pose) const;

 private:
  [[nodiscard]] bool grasp_usable_at(const geometry::Grasp& grasp, const ObjectSpec& object,
                                     const PositionLabel& position) const;

  Scenario scenario_;
  geometry::GripperSpec gripper_;
  std::vector<ObjectWorld> objects_;  // same order as scenario_.objects
  std::vector<GoalWorld> goals_;      // same order as scenario_.goals
};

}  // namespace spar::planner
