// RobotModel: forward kinematics of the built-in UR5 and Panda against independent
// implementations written here from published numbers, inverse kinematics round trips of every
// solver, and the Puma's answers unchanged through the model.
#include "spar/kinematics/robot.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/kinematics/puma.hpp"
#include "spar/kinematics/robots.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::kinematics {
namespace {

using units::kPi;

Transform translation(double x, double y, double z) {
  return Transform(Eigen::Translation3d(x, y, z));
}
Transform rotation(const Eigen::Vector3d& axis, double angle) {
  return Transform(Eigen::AngleAxisd(angle, axis));
}
Transform rot_x(double angle) { return rotation(Eigen::Vector3d::UnitX(), angle); }
Transform rot_y(double angle) { return rotation(Eigen::Vector3d::UnitY(), angle); }
Transform rot_z(double angle) { return rotation(Eigen::Vector3d::UnitZ(), angle); }

double pose_error(const Transform& a, const Transform& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

// UR5, base_link -> tool0, composed by hand from ur5_robot.urdf's joint origins and axes (exact
// quarter turns where the file writes 1.57079632679).
Transform ur5_by_hand(const std::vector<double>& q) {
  return translation(0, 0, 0.089159) * rot_z(q[0]) *                  // shoulder_pan
         translation(0, 0.13585, 0) * rot_y(kPi / 2) * rot_y(q[1]) *  // shoulder_lift
         translation(0, -0.1197, 0.425) * rot_y(q[2]) *               // elbow
         translation(0, 0, 0.39225) * rot_y(kPi / 2) * rot_y(q[3]) *  // wrist_1
         translation(0, 0.093, 0) * rot_z(q[4]) *                     // wrist_2
         translation(0, 0, 0.09465) * rot_y(q[5]) *                   // wrist_3
         translation(0, 0.0823, 0) * rot_x(-kPi / 2);                 // tool0
}

// Panda, panda_link0 -> panda_link8, from Franka's published modified-DH table (Craig:
// Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(q_i) Tz(d_i)), the flange 0.107 m along z7.
Transform panda_by_hand(const std::vector<double>& q) {
  const double a[7] = {0, 0, 0, 0.0825, -0.0825, 0, 0.088};
  const double d[7] = {0.333, 0, 0.316, 0, 0.384, 0, 0};
  const double alpha[7] = {0, -kPi / 2, kPi / 2, kPi / 2, -kPi / 2, kPi / 2, kPi / 2};
  Transform pose = Transform::Identity();
  for (int i = 0; i < 7; ++i)
    pose = pose * rot_x(alpha[i]) * translation(a[i], 0, 0) * rot_z(q[i]) * translation(0, 0, d[i]);
  return pose * translation(0, 0, 0.107);
}

std::vector<double> random_within_limits(const RobotModel& robot, std::mt19937_64& random) {
  std::vector<double> q;
  for (const MovingJoint& joint : robot.joints()) {
    const double lower = std::max(joint.limits.lower, -kPi);
    const double upper = std::min(joint.limits.upper, kPi);
    q.push_back(std::uniform_real_distribution<double>(lower, upper)(random));
  }
  return q;
}

bool same_joints(const std::vector<double>& a, const std::vector<double>& b, double tolerance) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::abs(std::remainder(a[i] - b[i], 2 * kPi)) > tolerance) return false;
  return true;
}

// The built-in robot's ends and its FK against `by_hand` at random joint values within limits.
void expect_forward_kinematics(const char* name, const char* base, const char* tip, std::size_t dof,
                               Transform (*by_hand)(const std::vector<double>&)) {
  const RobotModel& robot = builtin_robot_model(name);
  EXPECT_EQ(robot.base_link(), base);
  EXPECT_EQ(robot.tip_link(), tip);
  ASSERT_EQ(robot.dof(), dof);
  std::mt19937_64 random(23);
  for (int trial = 0; trial < 200; ++trial) {
    const std::vector<double> q = random_within_limits(robot, random);
    EXPECT_LT(pose_error(robot.forward(q), by_hand(q)), 1e-9);
  }
}

TEST(RobotModel, Ur5ForwardKinematicsMatchesTheUrdfComposedByHand) {
  expect_forward_kinematics("ur5", "base_link", "tool0", 6, ur5_by_hand);
}

TEST(RobotModel, PandaForwardKinematicsMatchesFrankasDhTable) {
  expect_forward_kinematics("panda", "panda_link0", "panda_link8", 7, panda_by_hand);
}

TEST(RobotModel, BuiltInRobotsChooseTheirSolvers) {
  EXPECT_EQ(builtin_robot_model("puma560").ik_method(), IkMethod::kPumaClosedForm);
  EXPECT_EQ(builtin_robot_model("ur5").ik_method(), IkMethod::kUrClosedForm);
  EXPECT_EQ(builtin_robot_model("panda").ik_method(), IkMethod::kRedundantClosedForm);
  EXPECT_THROW_MESSAGE(builtin_robot_model("ur6"), "unknown robot 'ur6'; built-in robots: puma560");
}

TEST(RobotModel, PumaThroughTheModelGivesIkHppsAnswersBitForBit) {
  const RobotModel puma = RobotModel::from_dh(puma560());
  const PumaIk solver(puma560());
  std::mt19937_64 random(560);
  for (int trial = 0; trial < 100; ++trial) {
    const std::vector<double> q = random_within_limits(puma, random);
    const Transform pose = puma560().forward(q);
    EXPECT_LT(pose_error(puma.forward(q), pose), 1e-14);
    const IkResult expected = solver.solve(pose);
    const std::vector<JointSolution> got = puma.inverse(pose);
    ASSERT_EQ(got.size(), 8u);
    for (std::size_t i = 0; i < 8; ++i) {
      EXPECT_EQ(got[i].configuration, expected.solutions[i].configuration.label());
      EXPECT_EQ(got[i].within_limits, expected.solutions[i].within_limits);
      EXPECT_EQ(got[i].singularities, expected.solutions[i].singularities);
      for (int j = 0; j < 6; ++j) EXPECT_EQ(got[i].q[j], expected.solutions[i].q[j]);
    }
  }
}

TEST(RobotModel, Ur5SolutionsComeLabelledInOrder) {
  const RobotModel& ur5 = builtin_robot_model("ur5");
  const std::vector<double> q = {0.3, -1.1, 1.4, -0.9, 1.2, 0.4};
  const std::vector<JointSolution> solutions = ur5.inverse(ur5.forward(q));
  ASSERT_EQ(solutions.size(), 8u);
  const char* order[8] = {"lun", "luf", "ldn", "ldf", "run", "ruf", "rdn", "rdf"};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(solutions[i].configuration, order[i]);
  // Wrist flips come in pairs with the same arm (q1, and q2 + q3 + q4 up to the flip's pi).
  for (std::size_t i = 0; i < 8; i += 2)
    EXPECT_NEAR(std::remainder(solutions[i].q[0] - solutions[i + 1].q[0], 2 * kPi), 0.0, 1e-12);
}

TEST(RobotModel, UnreachablePoseHasNoSolution) {
  const Transform far = translation(3.0, 0.0, 0.5);
  EXPECT_TRUE(builtin_robot_model("ur5").inverse(far).empty());
  EXPECT_TRUE(builtin_robot_model("panda").inverse(far).empty());
}

TEST(RobotModel, PandaSolutionsAreWithinLimitsAndSortedByMargin) {
  const RobotModel& panda = builtin_robot_model("panda");
  const std::vector<double> q = {0.2, -0.4, 0.1, -2.0, 0.3, 1.8, 0.35};
  const std::vector<JointSolution> solutions = panda.inverse(panda.forward(q));
  ASSERT_GT(solutions.size(), 10u);
  for (const JointSolution& solution : solutions) {
    EXPECT_TRUE(solution.within_limits);
    EXPECT_TRUE(panda.within_limits(solution.q));
    EXPECT_NE(solution.configuration.find("@q7="), std::string::npos);
  }
  const auto margin = [&](const JointSolution& solution) {
    double smallest = 1.0;
    for (std::size_t i = 0; i < 7; ++i) {
      const JointLimits& limits = panda.joints()[i].limits;
      smallest =
          std::min(smallest, std::min(solution.q[i] - limits.lower, limits.upper - solution.q[i]) /
                                 (limits.upper - limits.lower));
    }
    return smallest;
  };
  for (std::size_t i = 1; i < solutions.size(); ++i)
    EXPECT_GE(margin(solutions[i - 1]), margin(solutions[i]) - 1e-15);
}

TEST(RobotModel, PandaRedundancyStepSetsTheSamples) {
  const RobotModel& panda = builtin_robot_model("panda");
  const std::vector<double> q = {0.2, -0.4, 0.1, -2.0, 0.3, 1.8, 0.35};
  const Transform pose = panda.forward(q);
  for (const JointSolution& solution : panda.inverse(pose, {.redundancy_step = kPi / 18})) {
    const double steps = solution.q[6] / (kPi / 18);
    EXPECT_NEAR(steps, std::round(steps), 1e-6) << solution.configuration;
  }
  EXPECT_THROW_MESSAGE(panda.inverse(pose, {.redundancy_step = 0.0}),
                       "the redundancy step must be a positive angle");
}

// One sample of the sweep (redundancy_at): exactly the sweep's solutions with that q7, bit for bit
// and with their labels (what following one branch along a line relies on).
TEST(RobotModel, PandaOneRedundancySampleIsThatPartOfTheSweep) {
  const RobotModel& panda = builtin_robot_model("panda");
  const std::vector<double> q = {0.2, -0.4, 0.1, -2.0, 0.3, 1.8, 0.35};
  const Transform pose = panda.forward(q);
  const std::vector<JointSolution> sweep = panda.inverse(pose);
  int compared = 0;
  for (const double q7 : {sweep.front().q[6], sweep.back().q[6]}) {
    std::vector<JointSolution> part;
    for (const JointSolution& solution : sweep)
      if (solution.q[6] == q7) part.push_back(solution);
    const std::vector<JointSolution> alone = panda.inverse(pose, {.redundancy_at = q7});
    ASSERT_EQ(alone.size(), part.size());
    std::ranges::sort(part, {}, &JointSolution::configuration);
    std::vector<JointSolution> sorted = alone;
    std::ranges::sort(sorted, {}, &JointSolution::configuration);
    for (std::size_t i = 0; i < part.size(); ++i, ++compared) {
      EXPECT_EQ(sorted[i].configuration, part[i].configuration);
      EXPECT_EQ(sorted[i].q, part[i].q) << part[i].configuration;
    }
  }
  EXPECT_GT(compared, 1);
  // Out of q7's limits: nothing (no numeric fallback).
  EXPECT_TRUE(panda.inverse(pose, {.redundancy_at = 3.5}).empty());
}

TEST(RobotModel, ForwardKinematicsRefusesBadJointValues) {
  const RobotModel& ur5 = builtin_robot_model("ur5");
  EXPECT_THROW_MESSAGE(ur5.forward(std::vector<double>(5, 0.0)),
                       "robot 'ur5' has 6 joints but 5 joint values were given");
  EXPECT_THROW_MESSAGE(ur5.forward(std::vector<double>{0, 0, NAN, 0, 0, 0}),
                       "the value of joint 3 ('elbow_joint') is not a finite number");
}

TEST(RobotModel, RejectsBrokenChains) {
  RobotDescription description{
      .name = "arm",
      .source = "test",
      .base_link = "base",
      .tip_link = "tip",
      .chain = {{.name = "j1", .parent_link = "base", .child_link = "l1"},
                {.name = "j2", .parent_link = "elsewhere", .child_link = "tip"}},
      .attachments = {},
      .links = {},
      .dh = nullptr};
  EXPECT_THROW_MESSAGE(RobotModel{description}, "joint 'j2' hangs from 'elsewhere', not from 'l1'");
  description.chain[1].parent_link = "l1";
  description.chain[1].limits = {1.0, -1.0};
  EXPECT_THROW_MESSAGE(RobotModel{description}, "joint 'j2' has its lower limit");
  description.chain[1].limits = {};
  description.chain[1].axis = Eigen::Vector3d::Zero();
  EXPECT_THROW_MESSAGE(RobotModel{description}, "joint 'j2' has no axis direction");
  description.chain[1].axis = Eigen::Vector3d::UnitX();
  description.tip_link = "hand";
  EXPECT_THROW_MESSAGE(RobotModel{description}, "ends at 'tip', not at the tip 'hand'");
  description.tip_link = "tip";
  for (RobotJoint& joint : description.chain) joint.type = JointType::kFixed;
  EXPECT_THROW_MESSAGE(RobotModel{description}, "no joint moves between 'base' and 'tip'");
}

TEST(RobotModel, LinkPosesFollowTheirBodies) {
  const RobotModel& ur5 = builtin_robot_model("ur5");
  const std::vector<double> q = {0.3, -1.1, 1.4, -0.9, 1.2, 0.4};
  const std::vector<Transform> links = ur5.link_poses(q);
  ASSERT_EQ(links.size(), ur5.links().size());
  for (std::size_t i = 0; i < links.size(); ++i)
    if (ur5.links()[i].name == "tool0") {
      EXPECT_LT(pose_error(links[i], ur5.forward(q)), 1e-12);
    }
  EXPECT_FALSE(ur5.links().front().collision.empty());  // base_link's mesh
}

// Every solution reproduces the pose to 1e-9, and the joint vector the pose came from is among
// the UR5's solutions.
RC_GTEST_PROP(RobotModelProperty, Ur5InverseOfForwardContainsTheJoints, ()) {
  const RobotModel& ur5 = builtin_robot_model("ur5");
  std::vector<double> q;
  for (int i = 0; i < 6; ++i)
    q.push_back(*rc::gen::map(rc::gen::inRange(-3140, 3140), [](int v) { return v / 1000.0; }));
  const Transform pose = ur5.forward(q);
  const std::vector<JointSolution> solutions = ur5.inverse(pose);
  bool found = false;
  for (const JointSolution& solution : solutions) {
    RC_ASSERT(pose_error(ur5.forward(solution.q), pose) < 1e-9);
    found |= same_joints(solution.q, q, 1e-7);
  }
  RC_ASSERT(found);
}

// At the Panda's shoulder singularity (q2 = 0: axes 1 and 3 aligned) only q1 + q3 is fixed, and
// the solver reports one split of it, q1 = 0 (kinematics/internal/subproblems.hpp): `solution`
// is then `q` up to that split.
bool same_up_to_split_of_q1_q3(const std::vector<double>& solution, const std::vector<double>& q) {
  std::vector<double> moved = solution;
  moved[2] += moved[0] - q[0];  // the same q1 + q3, split as in q
  moved[0] = q[0];
  return same_joints(moved, q, 1e-7);
}
bool same_up_to_shoulder_split(const JointSolution& solution, const std::vector<double>& q) {
  return (solution.singularities & kShoulderSingularity) &&
         same_up_to_split_of_q1_q3(solution.q, q);
}

// With q7 on the sampling grid, the Panda's joint vector is among its solutions (when within
// limits; up to the split of q1 + q3 at the shoulder singularity), and every solution reproduces
// the pose.
RC_GTEST_PROP(RobotModelProperty, PandaInverseOfForwardContainsTheJointsOnTheGrid, ()) {
  const RobotModel& panda = builtin_robot_model("panda");
  std::vector<double> q;
  for (std::size_t i = 0; i < 6; ++i) {
    const JointLimits& limits = panda.joints()[i].limits;
    const int steps = *rc::gen::inRange(1, 1000);
    q.push_back(limits.lower + (limits.upper - limits.lower) * steps / 1000.0);
  }
  q.push_back(*rc::gen::inRange(-33, 34) * 5.0 * kPi / 180.0);
  const Transform pose = panda.forward(q);
  bool found = false;
  for (const JointSolution& solution : panda.inverse(pose)) {
    RC_ASSERT(pose_error(panda.forward(solution.q), pose) < 1e-9);
    RC_ASSERT(panda.within_limits(solution.q));
    found |= same_joints(solution.q, q, 1e-7) || same_up_to_shoulder_split(solution, q);
  }
  RC_ASSERT(found);
}

// Regression (random-seed hunt, seed 2690832172): q2 = 0 exactly puts the Panda at its shoulder
// singularity, where only q1 + q3 = 2.90 is fixed; the split q1 = 0 leaves q3 = 2.90 beyond its
// limit 2.8973, and the branch was dropped. A split within both limits is among the solutions.
TEST(RobotModel, PandaAtTheShoulderSingularityKeepsQ1PlusQ3) {
  const RobotModel& panda = builtin_robot_model("panda");
  std::vector<double> q;
  const int steps[6] = {717, 500, 784, 1, 1, 1};
  for (std::size_t i = 0; i < 6; ++i) {
    const JointLimits& limits = panda.joints()[i].limits;
    q.push_back(limits.lower + (limits.upper - limits.lower) * steps[i] / 1000.0);
  }
  q.push_back(-33 * 5.0 * kPi / 180.0);
  const Transform pose = panda.forward(q);
  bool split = false;  // a solution flagged singular holds q up to the split
  for (const JointSolution& solution : panda.inverse(pose)) {
    EXPECT_LT(pose_error(panda.forward(solution.q), pose), 1e-9);
    split |= same_up_to_shoulder_split(solution, q);
  }
  EXPECT_TRUE(split);
}

// Near the shoulder singularity (q2 within a few 1e-10 of 0, where the subproblem may still
// call axes 1 and 3 aligned and the split of q1 + q3 is moved into the limits), every solution
// still reproduces the pose and keeps the limits, and q is among them up to that split: off the
// singularity the pose fixes the split only to about 1e-16 / |q2| (1e-5 at q2 = 1e-11), so the
// split is compared only where q2 is that small.
TEST(RobotModel, PandaNearTheShoulderSingularityReproducesThePose) {
  const RobotModel& panda = builtin_robot_model("panda");
  for (const double q2 : {0.0, 1e-13, -1e-12, 1e-11, -1e-10, 1e-9, 1e-8, 1e-6}) {
    std::vector<double> q;
    const int steps[6] = {717, 500, 784, 1, 1, 1};
    for (std::size_t i = 0; i < 6; ++i) {
      const JointLimits& limits = panda.joints()[i].limits;
      q.push_back(limits.lower + (limits.upper - limits.lower) * steps[i] / 1000.0);
    }
    q[1] = q2;
    q.push_back(-33 * 5.0 * kPi / 180.0);
    const Transform pose = panda.forward(q);
    bool found = false;
    for (const JointSolution& solution : panda.inverse(pose)) {
      EXPECT_LT(pose_error(panda.forward(solution.q), pose), 1e-9) << "q2 " << q2;
      EXPECT_TRUE(panda.within_limits(solution.q)) << "q2 " << q2;
      found |= same_joints(solution.q, q, 1e-7) ||
               (std::abs(q2) < 1e-8 && same_up_to_split_of_q1_q3(solution.q, q));
    }
    EXPECT_TRUE(found) << "q2 " << q2;
  }
}

// Any in-limit joint vector's pose, q7 off the grid too, gets an in-limit solution from the
// closed form (the sweep's samples, the arcs of q7 that keep the wrist within reach, the numeric
// fallback).
RC_GTEST_PROP(RobotModelProperty, PandaInverseReachesRandomReachablePoses, ()) {
  const RobotModel& panda = builtin_robot_model("panda");
  std::vector<double> q;
  for (const MovingJoint& joint : panda.joints())
    q.push_back(joint.limits.lower +
                (joint.limits.upper - joint.limits.lower) * *rc::gen::inRange(1, 10000) / 1e4);
  const Transform pose = panda.forward(q);
  const std::vector<JointSolution> solutions = panda.inverse(pose);
  RC_ASSERT(!solutions.empty());
  for (const JointSolution& solution : solutions) {
    RC_ASSERT(pose_error(panda.forward(solution.q), pose) < 1e-9);
    RC_ASSERT(panda.within_limits(solution.q));
  }
}

// Regression (kinematics_bench, 4 of 10 000 random poses): with q2 near its limit and the arm
// nearly stretched, only q7 in a band around 102 degrees narrower than the step keeps the wrist
// point within reach; no 5-degree sample was within reach, so neither were the numeric fallback's
// conditions met, and the closed form returned nothing.
TEST(RobotModel, PandaReachedOnlyBetweenTheSamplesOfQ7) {
  const RobotModel& panda = builtin_robot_model("panda");
  const std::vector<double> q = {2.4427, 1.7138, -0.0439, -0.4724, 0.0058, 0.2016, 1.7809};
  const Transform pose = panda.forward(q);
  EXPECT_TRUE(panda.inverse(pose, {.redundancy_at = 100 * kPi / 180}).empty());
  EXPECT_TRUE(panda.inverse(pose, {.redundancy_at = 105 * kPi / 180}).empty());
  const std::vector<JointSolution> solutions = panda.inverse(pose);
  ASSERT_FALSE(solutions.empty());
  EXPECT_LT(pose_error(panda.forward(solutions.front().q), pose), 1e-9);
  EXPECT_TRUE(panda.within_limits(solutions.front().q));
}

// Regression (random-seed hunt, seed 3024810286): a Panda pose with q4 at its lower limit and q6
// near its own. Clamping only the step of a joint at its limit left the other joints' steps
// computed for a motion q4 could not make: every start stalled there, and no solution was found.
TEST(RobotModel, NumericSolverReachesAPoseWithAJointAtItsLimit) {
  const RobotModel& panda = builtin_robot_model("panda");
  std::vector<double> q;
  const int steps[7] = {184, 20, 61, 0, 210, 14, 116};
  for (std::size_t i = 0; i < 7; ++i) {
    const double lower = std::max(panda.joints()[i].limits.lower, -kPi);
    const double upper = std::min(panda.joints()[i].limits.upper, kPi);
    q.push_back(lower + (upper - lower) * steps[i] / 1000.0);
  }
  const Transform pose = panda.forward(q);
  const std::vector<JointSolution> solutions =
      panda.inverse_numeric(pose, {.numeric_solutions = 1});
  ASSERT_FALSE(solutions.empty());
  EXPECT_LT(pose_error(panda.forward(solutions.front().q), pose), 1e-9);
  EXPECT_TRUE(panda.within_limits(solutions.front().q));
}

// The numeric solver finds an in-limit solution of a reachable pose of either arm.
RC_GTEST_PROP(RobotModelProperty, NumericSolverReachesRandomReachablePoses, ()) {
  const RobotModel& robot = builtin_robot_model(*rc::gen::element("ur5", "panda"));
  std::vector<double> q;
  for (const MovingJoint& joint : robot.joints()) {
    const double lower = std::max(joint.limits.lower, -kPi);
    const double upper = std::min(joint.limits.upper, kPi);
    q.push_back(lower + (upper - lower) * *rc::gen::inRange(0, 1001) / 1000.0);
  }
  const Transform pose = robot.forward(q);
  const std::vector<JointSolution> solutions =
      robot.inverse_numeric(pose, {.numeric_solutions = 1});
  RC_ASSERT(!solutions.empty());
  RC_ASSERT(pose_error(robot.forward(solutions.front().q), pose) < 1e-9);
  RC_ASSERT(robot.within_limits(solutions.front().q));
}

}  // namespace
}  // namespace spar::kinematics
