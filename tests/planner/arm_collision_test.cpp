// Arm collisions (issue 23): the links of the arm, posed by forward kinematics at a step's IK
// branch, are checked against the table (the branch is chosen among those clear of it) and
// against the other objects, at the step's configuration and along the gripper's straight lines
// from it; a step takes the first branch that is clear and is refused, naming what each branch
// hits, only when none is. The verdicts are verified here with the URDF's own meshes, posed
// independently of the world model's collision bodies.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "spar/planner/plan.hpp"
#include "spar/planner/sense_planning.hpp"

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

// The world model's per-grasp tables and arm links are built on its threads, one task per grasp
// or link: on one thread and on three the UR5 example's tables are the same, and an insertion
// check (which reads the per-grasp pair conflicts) gives the same verdict for every held grasp.
TEST(ArmCollision, TheWorldModelDoesNotDependOnItsThreads) {
  const WorldModel one(load_scenario(kUr5), 1), three(load_scenario(kUr5), 3);
  ASSERT_EQ(one.scenario().objects.size(), three.scenario().objects.size());
  for (std::size_t o = 0; o < one.scenario().objects.size(); ++o)
    EXPECT_EQ(one.object(static_cast<int>(o)).reachable,
              three.object(static_cast<int>(o)).reachable);
  ASSERT_EQ(one.goals().size(), three.goals().size());
  for (std::size_t g = 0; g < one.goals().size(); ++g) {
    const GoalWorld& a = one.goals()[g];
    const GoalWorld& b = three.goals()[g];
    EXPECT_EQ(a.mate_reachable, b.mate_reachable);
    EXPECT_EQ(a.grasp_clears_assembled, b.grasp_clears_assembled);
    if (a.kind != GoalWorld::Kind::kAssembled) continue;
    const Transform fixed_pose = one.object(a.fixed).positions[0].pose;
    for (std::size_t grasp = 0; grasp < one.object(a.held).grasps.size(); ++grasp) {
      const StepCheck x = one.check_insertion(one.initial_state(), static_cast<int>(g),
                                              static_cast<int>(grasp), fixed_pose, false);
      const StepCheck y = three.check_insertion(three.initial_state(), static_cast<int>(g),
                                                static_cast<int>(grasp), fixed_pose, false);
      EXPECT_EQ(x.clear, y.clear);
      EXPECT_EQ(x.conflict, y.conflict);
    }
  }
}

// The UR5 example with one more object (`entry`: its YAML under `objects:`).
WorldModel ur5_with(const std::string& entry) {
  std::ifstream file(kUr5);
  std::stringstream text;
  text << file.rdbuf();
  std::string yaml = text.str();
  const std::string objects = "objects:\n";
  yaml.insert(yaml.find(objects) + objects.size(), entry);
  return WorldModel(parse_scenario(yaml, kUr5, std::string(SPAR_SOURCE_DIR) + "/examples"));
}

// The UR5 example with a 1 in cube far from the others (the tests move it where they need it).
WorldModel ur5_with_cube() {
  return ur5_with("  cube:\n    builtin: cube\n    pose: {stable: P5, at: [-20, -20]}\n");
}

// The moving links' meshes, except those on the last body (next to the gripper), as bodies of
// their own (link index, body).
std::vector<std::pair<std::size_t, geometry::Body>> checked_links(const RobotSpec& robot) {
  std::vector<std::pair<std::size_t, geometry::Body>> bodies;
  for (std::size_t l = 0; l < robot.arm.links().size(); ++l) {
    const kinematics::RobotLinkInfo& link = robot.arm.links()[l];
    if (link.body == 0 || link.body == static_cast<int>(robot.arm.dof())) continue;
    for (const kinematics::LinkShape& shape : link.collision)
      if (shape.mesh)
        bodies.emplace_back(l, geometry::Body(link.name, geometry::CollisionShape(*shape.mesh)));
  }
  return bodies;
}

// The first of those links at q within the margin of `obstacle`, or nullopt.
std::optional<std::string> link_hit(const RobotSpec& robot, const std::vector<double>& q,
                                    const geometry::PlacedBody& obstacle, double margin) {
  static const auto bodies = checked_links(robot);  // the UR5's: every test here uses it
  const std::vector<Transform> poses = robot.arm.link_poses(q);
  for (const auto& [l, body] : bodies) {
    const Transform pose = robot.base * poses[l] * robot.arm.links()[l].collision.front().origin;
    if (geometry::collide({&body, pose}, obstacle, margin)) return body.name();
  }
  return std::nullopt;
}

// The in-limit IK solution with branch `label` for a gripper pose, or nullopt.
std::optional<std::vector<double>> branch_at(const WorldModel& world, const Transform& gripper,
                                             const std::string& label) {
  for (const kinematics::JointSolution& s :
       world.scenario().robot.arm.inverse(world.flange_in_base(gripper)))
    if (s.within_limits && s.configuration == label) return s.q;
  return std::nullopt;
}

// The peg's first grasp reachable where it starts, and the gripper pose there.
struct PegGrasp {
  int peg{0}, grasp{-1};
  Transform peg_pose, gripper;
};
PegGrasp peg_grasp(const WorldModel& world) {
  PegGrasp out;
  out.peg = world.object_index("peg");
  out.peg_pose = world.scenario().objects[out.peg].initial_pose;
  for (std::size_t g = 0; g < world.object(out.peg).grasps.size() && out.grasp < 0; ++g)
    if (world.object(out.peg).reachable[g][0]) out.grasp = static_cast<int>(g);
  if (out.grasp >= 0)
    out.gripper = out.peg_pose * world.object(out.peg).grasps[out.grasp].gripper_in_object;
  return out;
}

// The cube's pose with its centre at `point`.
Transform cube_at(const Eigen::Vector3d& point) {
  const double half = 0.0254 / 2;
  return Eigen::Translation3d(point - Eigen::Vector3d::Constant(half)) * Transform::Identity();
}

// The UR5 example with the cube, the peg's grasp, and the first branch reaching it.
struct CubeScene {
  WorldModel world = ur5_with_cube();
  const RobotSpec& robot = world.scenario().robot;
  int cube = world.object_index("cube");
  PegGrasp peg = peg_grasp(world);
  std::optional<kinematics::JointSolution> first = world.reach(peg.gripper).solution;
  geometry::Body cube_body{"cube",
                           geometry::CollisionShape(world.scenario().objects[cube].model.mesh())};
};

// World points on the checked links' meshes at q (every `stride`-th vertex).
std::vector<Eigen::Vector3d> link_points(const RobotSpec& robot, const std::vector<double>& q,
                                         std::size_t stride) {
  std::vector<Eigen::Vector3d> points;
  const std::vector<Transform> poses = robot.arm.link_poses(q);
  for (const auto& [l, body] : checked_links(robot)) {
    const kinematics::LinkShape& shape = robot.arm.links()[l].collision.front();
    for (std::size_t v = 0; v < shape.mesh->vertices.size(); v += stride)
      points.push_back(robot.base * poses[l] * shape.origin * shape.mesh->vertices[v]);
  }
  return points;
}

// One CubeScene for every test (building the world takes a while).
const CubeScene& cube_scene() {
  static const CubeScene scene;
  return scene;
}

// Tests on the cube scene, which must have the peg's grasp and a branch reaching it.
class ArmCube : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_GE(peg_grip.grasp, 0);
    ASSERT_TRUE(first);
  }
  const WorldModel& world = cube_scene().world;
  const RobotSpec& robot = cube_scene().robot;
  const int cube = cube_scene().cube;
  const PegGrasp& peg_grip = cube_scene().peg;
  const std::optional<kinematics::JointSolution>& first = cube_scene().first;
  const geometry::Body& cube_body = cube_scene().cube_body;

  // Cubes on `branch`'s links where the gripper is approach_distance above `gripper` (the far
  // end of the step's lines), clear of the branch at `gripper` by three margins: the step
  // (`check` with the cube there) never takes the branch, and when no branch is clear the message
  // names it and contains `where`. Returns how many placements reached the arm check.
  int expect_line_blocks(const Transform& gripper, const kinematics::JointSolution& branch,
                         const std::string& where,
                         const std::function<StepCheck(const WorldState&)>& check) const {
    const Transform above =
        Eigen::Translation3d(-robot.approach_distance * gripper.linear().col(2)) * gripper;
    const std::optional<std::vector<double>> raised = branch_at(world, above, branch.configuration);
    if (!raised) ADD_FAILURE() << branch.configuration << " does not reach above the step";
    WorldState state = world.initial_state();
    int placements = 0;
    for (const Eigen::Vector3d& point :
         raised ? link_points(robot, *raised, 97) : std::vector<Eigen::Vector3d>()) {
      state.poses[cube] = cube_at(point);
      const geometry::PlacedBody placed_cube{&cube_body, state.poses[cube]};
      if (link_hit(robot, branch.q, placed_cube, 3 * world.margin())) continue;
      EXPECT_TRUE(link_hit(robot, *raised, placed_cube, world.margin()));
      const StepCheck result = check(state);
      const bool arm_refused = result.conflict.rfind("every IK branch of the arm", 0) == 0;
      if (!result.clear && !arm_refused) continue;  // the gripper or the held object hit it
      ++placements;
      if (result.clear) {
        EXPECT_NE(result.arm->configuration, branch.configuration);
      } else {
        EXPECT_NE(result.conflict.find(branch.configuration + ": "), std::string::npos)
            << result.conflict;
        EXPECT_NE(result.conflict.find(where), std::string::npos) << result.conflict;
      }
    }
    return placements;
  }
};

// A block standing where the forearm passes hits every branch clear of the table: the grasp is
// refused, naming per branch the link and what it hits.
TEST(ArmCollision, AnObjectHittingEveryBranchBlocksTheGrasp) {
  const WorldModel world(load_scenario(kUr5));
  const RobotSpec& robot = world.scenario().robot;
  const int block = world.object_index("block");
  const auto [peg, grasp, peg_pose, gripper] = peg_grasp(world);
  ASSERT_GE(grasp, 0);
  const Reach reach = world.reach(gripper);
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
  EXPECT_EQ(
      check.conflict,
      "every IK branch of the arm is blocked: lun: forearm_link hits block; luf: "
      "forearm_link hits block; run: upper_arm_link hits block; ruf: forearm_link hits block");
  // Each branch named does hit the block (checked here with the URDF's meshes).
  const geometry::Body block_body(
      "block", geometry::CollisionShape(world.scenario().objects[block].model.mesh()));
  for (const std::string label : {"lun", "luf", "run", "ruf"}) {
    const std::optional<std::vector<double>> q = branch_at(world, gripper, label);
    ASSERT_TRUE(q) << label;
    EXPECT_TRUE(link_hit(robot, *q, {&block_body, state.poses[block]}, world.margin())) << label;
  }
  // Without the block there, the same grasp is clear.
  EXPECT_TRUE(world.check_grasp(world.initial_state(), peg, grasp, peg_pose, false).clear);
}

// A cube on the first branch's arm but clear of another branch's: the grasp takes that branch
// (the first clear one), and says so.
TEST_F(ArmCube, AnObjectOnTheFirstBranchMakesTheStepTakeAnother) {
  const auto& [peg, grasp, peg_pose, gripper] = peg_grip;
  WorldState state = world.initial_state();
  std::optional<StepCheck> taken;
  for (const Eigen::Vector3d& point : link_points(robot, first->q, 97)) {
    state.poses[cube] = cube_at(point);
    const StepCheck check = world.check_grasp(state, peg, grasp, peg_pose, false);
    if (check.clear && check.arm && check.arm->configuration != first->configuration) {
      taken = check;
      break;
    }
  }
  ASSERT_TRUE(taken) << "no cube placement on branch " << first->configuration
                     << " leaves another branch clear";
  // The first branch does hit the cube, the one taken does not, and it reaches the grasp.
  const geometry::PlacedBody placed_cube{&cube_body, state.poses[cube]};
  EXPECT_TRUE(link_hit(robot, first->q, placed_cube, world.margin()));
  EXPECT_FALSE(link_hit(robot, taken->arm->q, placed_cube, world.margin()));
  EXPECT_TRUE(taken->arm->within_limits);
  EXPECT_TRUE((robot.base * robot.arm.forward(taken->arm->q) * robot.tool).isApprox(gripper, 1e-9));
  // Without the cube there, the first branch is the step's.
  state.poses[cube] = world.initial_state().poses[cube];
  const StepCheck free = world.check_grasp(state, peg, grasp, peg_pose, false);
  ASSERT_TRUE(free.clear && free.arm);
  EXPECT_EQ(free.arm->configuration, first->configuration);
}

// A cube clear of the first branch's arm at the grasp, but on it where the gripper starts its
// approach (approach_distance above): the branch is not taken, and when no other is clear the
// message says where it hits.
TEST_F(ArmCube, AnObjectBesideTheApproachLineStopsTheBranch) {
  // Members, not structured bindings: clang 14 (Debian 12) cannot capture those in a lambda.
  const PegGrasp& grip = peg_grip;
  EXPECT_GT(expect_line_blocks(grip.gripper, *first, " hits cube along the approach",
                               [&](const WorldState& state) {
                                 return world.check_grasp(state, grip.peg, grip.grasp,
                                                          grip.peg_pose, false);
                               }),
            0);
}

// The same for an insertion of the peg into the block (its retreat line, which here runs with
// the insertion's: both go straight up).
TEST_F(ArmCube, AnObjectBesideTheInsertionLinesStopsTheBranch) {
  const GoalWorld& goal = world.goals().at(0);
  const auto& relative = std::get<AssembledGoal>(world.scenario().goals[0]).relative;
  for (std::size_t g = 0; g < goal.mate_reachable.size(); ++g)
    for (std::size_t p = 0; p < goal.mate_reachable[g].size(); ++p) {
      if (!goal.mate_reachable[g][p]) continue;
      const Transform& fixed_pose = world.object(goal.fixed).positions[p].pose;
      const Transform gripper =
          fixed_pose * relative * world.object(goal.held).grasps[g].gripper_in_object;
      const std::optional<kinematics::JointSolution> branch = world.reach(gripper).solution;
      ASSERT_TRUE(branch);
      EXPECT_GT(expect_line_blocks(gripper, *branch, " hits cube along the ",
                                   [&](const WorldState& state) {
                                     return world.check_insertion(state, 0, static_cast<int>(g),
                                                                  fixed_pose, false);
                                   }),
                0);
      return;  // one insertion is enough
    }
  FAIL() << "no insertion of the peg into the block is reachable";
}

// Sense planning's wrist viewpoints: with a 30 in pillar standing beside the block, gripper poses
// (pointing down) around it that reach() reaches and where the open gripper is clear: the range
// scanner's viewpoint there is kept exactly when some in-limit branch above the table keeps its
// links clear of every object (checked with the URDF's meshes), and some are refused (every
// branch reach() could take hits the pillar).
TEST(ArmCollision, AWristViewpointNeedsABranchClearOfTheObjects) {
  const WorldModel world = ur5_with("  pillar:\n    mesh: " + std::string(SPAR_SOURCE_DIR) +
                                    "/tests/planner/data/pillar.off\n    fixed: true\n"
                                    "    pose: {xyz: [19, -15, 0], rpy: [0, 0, 0]}\n");
  const RobotSpec& robot = world.scenario().robot;
  const SensingContext context(world.scenario(), world);
  const sensing::SelectionOptions options = context.options();
  const sensing::SensorModel scanner = scenario_sensors(world.scenario()).front();
  ASSERT_EQ(scanner.mount, sensing::Mount::kWrist);
  const WorldState start = world.initial_state();
  std::vector<geometry::PlacedBody> objects;
  for (std::size_t o = 0; o < start.poses.size(); ++o)
    objects.push_back({&world.body(static_cast<int>(o)), start.poses[o]});
  const geometry::Body open = geometry::gripper_body(world.gripper(), world.gripper().max_opening);
  const double inch = 0.0254;
  int kept = 0, refused = 0;
  for (int x = 12; x <= 28; x += 4)
    for (int y = -24; y <= -6; y += 3)
      for (int z = 2; z <= 14; z += 4) {
        const Transform gripper = Eigen::Translation3d(x * inch, y * inch, z * inch) *
                                  Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());
        if (!world.reach(gripper).solution) continue;
        const geometry::PlacedBody gripper_there{&open, gripper};
        if (std::ranges::any_of(objects, [&](const geometry::PlacedBody& object) {
              return geometry::collide(gripper_there, object, world.margin());
            }))
          continue;  // the gripper's own case, not the arm's
        bool clear_branch = false;
        for (const kinematics::JointSolution& s : robot.arm.inverse(world.flange_in_base(gripper)))
          if (s.within_limits && lowest_link_z(robot, s.q) >= -geometry::kTableTolerance)
            clear_branch |= std::ranges::none_of(objects, [&](const geometry::PlacedBody& object) {
              return link_hit(robot, s.q, object, world.margin()).has_value();
            });
        const bool viewed = options.reachable(0, gripper * scanner.pose);
        EXPECT_EQ(viewed, clear_branch) << x << ", " << y << ", " << z << " in";
        ++(viewed ? kept : refused);
      }
  EXPECT_GT(kept, 0);
  EXPECT_GT(refused, 0);
}

// A cube at random near the first branch's arm somewhere along the approach: when the grasp is
// clear, the branch it takes keeps half the margin from the cube at 200 evenly spaced points of
// the line (the branch followed by its label), and the margin at the grasp itself.
RC_GTEST_PROP(ArmCollisionProperty, AClearBranchKeepsHalfTheMarginAlongTheApproach, ()) {
  // Plain references, not structured bindings: clang 14 (Debian 12) cannot capture those.
  const CubeScene& scene = cube_scene();
  const WorldModel& world = scene.world;
  const RobotSpec& robot = scene.robot;
  const int cube = scene.cube, peg = scene.peg.peg, grasp = scene.peg.grasp;
  const std::optional<kinematics::JointSolution>& first = scene.first;
  const geometry::Body& cube_body = scene.cube_body;
  const Transform &peg_pose = scene.peg.peg_pose, &gripper = scene.peg.gripper;
  RC_ASSERT(grasp >= 0 && first.has_value());
  const Eigen::Vector3d line = -robot.approach_distance * gripper.linear().col(2);
  const auto on_line = [&](double s) { return Eigen::Translation3d(s * line) * gripper; };
  const double s = *rc::gen::inRange(0, 101) / 100.0;
  const std::optional<std::vector<double>> q = branch_at(world, on_line(s), first->configuration);
  RC_PRE(q.has_value());
  const std::vector<Eigen::Vector3d> points = link_points(robot, *q, 211);
  const Eigen::Vector3d offset(*rc::gen::inRange(-30, 31) * 1e-3, *rc::gen::inRange(-30, 31) * 1e-3,
                               *rc::gen::inRange(-30, 31) * 1e-3);
  WorldState state = world.initial_state();
  state.poses[cube] = cube_at(points[*rc::gen::inRange<std::size_t>(0, points.size())] + offset);
  const StepCheck check = world.check_grasp(state, peg, grasp, peg_pose, false);
  RC_CLASSIFY(check.clear, "clear");
  RC_CLASSIFY(check.clear && check.arm->configuration != first->configuration, "another branch");
  if (!check.clear) return;
  const geometry::PlacedBody placed_cube{&cube_body, state.poses[cube]};
  RC_ASSERT(!link_hit(robot, check.arm->q, placed_cube, world.margin()));
  for (int k = 0; k <= 200; ++k) {
    const std::optional<std::vector<double>> at =
        branch_at(world, on_line(k / 200.0), check.arm->configuration);
    RC_ASSERT(at.has_value());
    if (const std::optional<std::string> hit =
            link_hit(robot, *at, placed_cube, world.margin() / 2))
      RC_FAIL(*hit + " of " + check.arm->configuration + " within half the margin of the cube at " +
              std::to_string(k) + "/200 of the approach");
  }
}

}  // namespace
}  // namespace spar::planner
