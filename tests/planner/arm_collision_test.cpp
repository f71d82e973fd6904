// Arm collisions (issue 23): the links of the arm, posed by forward kinematics at a step's IK
// solution, are checked against the table (the IK branch is chosen among those clear of it) and
// against the other objects (the step is refused, blaming the link, the branch and the object).
// The table check is verified here with the URDF's own meshes, posed independently of the world
// model's collision bodies.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "spar/planner/plan.hpp"

namespace spar::planner {
namespace {

using kinematics::Transform;

const std::string kUr5 = std::string(SPAR_SOURCE_DIR) + "/examples/ur5_peg_block.yaml";

// The lowest world z of the moving links' collision meshes at q (+inf without meshes).
double lowest_link_z(const RobotSpec& robot, const std::vector<double>& q) {
  const std::vector<Transform> poses = robot.arm.link_poses(q);
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t l = 0; l < robot.arm.links().size(); ++l) {
    const kinematics::RobotLinkInfo& link = robot.arm.links()[l];
    if (link.body == 0) continue;
    for (const kinematics::LinkShape& shape : link.collision)
      if (shape.mesh)
        for (const Eigen::Vector3d& v : shape.mesh->vertices)
          lowest = std::min(lowest, (robot.base * poses[l] * shape.origin * v).z());
  }
  return lowest;
}

// Gripper poses of the UR5 at random joint values: no link of the branch reach() chooses is
// below the table, and at some of them the solver's first in-limit branch was (so the choice is
// exercised, not vacuous).
TEST(ArmCollision, ReachChoosesABranchAboveTheTable) {
  const WorldModel world(load_scenario(kUr5));
  const RobotSpec& robot = world.scenario().robot;
  std::mt19937 random(2323);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  int reached = 0, avoided = 0;
  for (int sample = 0; sample < 2000; ++sample) {
    std::vector<double> q(robot.arm.dof());
    for (double& value : q) value = angle(random);
    const Transform gripper = robot.base * robot.arm.forward(q) * robot.tool;
    const Reach reach = world.reach(gripper);
    if (!reach.solution) continue;
    ++reached;
    EXPECT_GE(lowest_link_z(robot, reach.solution->q), -geometry::kTableTolerance)
        << reach.solution->configuration;
    for (const kinematics::JointSolution& s : robot.arm.inverse(world.flange_in_base(gripper)))
      if (s.within_limits) {
        avoided += s.configuration != reach.solution->configuration;
        break;
      }
  }
  EXPECT_GT(reached, 0);
  EXPECT_GT(avoided, 0);
}

// An object standing where the forearm passes: the grasp is refused and the message names the
// arm's link, the IK branch and the object.
TEST(ArmCollision, AnObjectAtTheForearmBlocksTheGrasp) {
  const WorldModel world(load_scenario(kUr5));
  const RobotSpec& robot = world.scenario().robot;
  const int peg = world.object_index("peg"), block = world.object_index("block");
  const Transform& peg_pose = world.scenario().objects[peg].initial_pose;
  int grasp = -1;
  for (std::size_t g = 0; g < world.object(peg).grasps.size() && grasp < 0; ++g)
    if (world.object(peg).reachable[g][0]) grasp = static_cast<int>(g);
  ASSERT_GE(grasp, 0);
  const Reach reach = world.reach(peg_pose * world.object(peg).grasps[grasp].gripper_in_object);
  ASSERT_TRUE(reach.solution);
  // The forearm's mesh centre in the world, and the block's centre put there.
  const auto& links = robot.arm.links();
  const auto forearm = std::find_if(links.begin(), links.end(),
                                    [](const auto& link) { return link.name == "forearm_link"; });
  ASSERT_NE(forearm, links.end());
  ASSERT_FALSE(forearm->collision.empty());
  const kinematics::LinkShape& shape = forearm->collision.front();
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : shape.mesh->vertices) box.extend(v);
  const Eigen::Vector3d centre = robot.base *
                                 robot.arm.link_poses(reach.solution->q)[forearm - links.begin()] *
                                 shape.origin * box.center();
  Eigen::AlignedBox3d block_box;
  for (const Eigen::Vector3d& v : world.scenario().objects[block].model.mesh().vertices)
    block_box.extend(v);
  WorldState state = world.initial_state();
  state.poses[block] = Eigen::Translation3d(centre - block_box.center()) * Transform::Identity();
  const StepCheck check = world.check_grasp(state, peg, grasp, peg_pose, false);
  EXPECT_FALSE(check.clear);
  EXPECT_EQ(check.conflict.rfind("the arm's ", 0), 0u) << check.conflict;
  EXPECT_NE(check.conflict.find("(IK branch " + reach.solution->configuration + ") hits block"),
            std::string::npos)
      << check.conflict;
  // Without the block there, the same grasp is clear.
  EXPECT_TRUE(world.check_grasp(world.initial_state(), peg, grasp, peg_pose, false).clear);
}

}  // namespace
}  // namespace spar::planner
