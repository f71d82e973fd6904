#include "spar/kinematics/ik.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/kinematics/puma.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::kinematics {
namespace {

using units::kPi;

Transform fk(const DhChain& robot, const JointVector& q) {
  return robot.forward(std::span<const double>(q.data(), 6));
}

double pose_error(const Transform& a, const Transform& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

bool same_angles(const JointVector& a, const JointVector& b, double tolerance) {
  for (int i = 0; i < 6; ++i)
    if (std::abs(wrap_angle(a[i] - b[i])) > tolerance) return false;
  return true;
}

// Every solution is finite and reaches the pose.
void expect_all_solutions_reach(const DhChain& robot, const IkResult& result,
                                const Transform& pose) {
  ASSERT_TRUE(result.solved());
  for (const IkSolution& solution : result.solutions) {
    SCOPED_TRACE(solution.configuration.label());
    ASSERT_TRUE(solution.q.allFinite());
    EXPECT_LT(pose_error(fk(robot, solution.q), pose), 1e-9);
  }
}

TEST(ArmConfiguration, LabelRoundTrips) {
  for (const char* label : {"lun", "luf", "ldn", "ldf", "run", "ruf", "rdn", "rdf"})
    EXPECT_EQ(ArmConfiguration::from_label(label).label(), label);
  EXPECT_THROW_MESSAGE(ArmConfiguration::from_label("rux"), "bad configuration label 'rux'");
}

TEST(PumaIk, SolutionsComeInTheDocumentedOrderWithFlipPairs) {
  const IkResult result =
      PumaIk(puma560()).solve(fk(puma560(), JointVector(0.2, 0.3, 0.4, 0.5, 0.6, 0.7)));
  ASSERT_TRUE(result.solved());
  const char* order[8] = {"lun", "luf", "ldn", "ldf", "run", "ruf", "rdn", "rdf"};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(result.solutions[i].configuration.label(), order[i]);
  for (int i = 0; i < 8; i += 2) {
    const JointVector& no_flip = result.solutions[i].q;
    const JointVector& flip = result.solutions[i + 1].q;
    EXPECT_LE(no_flip[4], 0.0);
    EXPECT_NEAR(flip[4], -no_flip[4], 1e-12);
    EXPECT_NEAR(std::abs(wrap_angle(flip[3] - no_flip[3])), kPi, 1e-12);
    EXPECT_NEAR(std::abs(wrap_angle(flip[5] - no_flip[5])), kPi, 1e-12);
  }
}

TEST(PumaIk, ElbowUpMeansElbowAboveTheShoulderWristLine) {
  const DhChain& robot = puma560();
  const IkResult result =
      PumaIk(robot).solve(fk(robot, JointVector(0.5, -0.4, 0.8, 0.1, -0.9, 0.2)));
  ASSERT_TRUE(result.solved());
  for (const IkSolution& solution : result.solutions) {
    SCOPED_TRACE(solution.configuration.label());
    // Elbow = origin of frame 2; shoulder = origin of frame 1; wrist centre = origin of frame 4.
    std::vector<double> q(solution.q.data(), solution.q.data() + 6);
    const DhChain upper("upper", {robot.joint(0), robot.joint(1)});
    const DhChain to_wrist("to_wrist",
                           {robot.joint(0), robot.joint(1), robot.joint(2), robot.joint(3)});
    const Eigen::Vector3d elbow = upper.forward(std::span(q).first(2)).translation();
    const Eigen::Vector3d wrist = to_wrist.forward(std::span(q).first(4)).translation();
    const Eigen::Vector3d shoulder(0, 0, robot.joint(0).d);
    const double t = (elbow - shoulder).dot(wrist - shoulder) / (wrist - shoulder).squaredNorm();
    const double height_above_line = elbow.z() - (shoulder.z() + t * (wrist.z() - shoulder.z()));
    EXPECT_EQ(height_above_line > 0.0, solution.configuration.elbow == Elbow::up);
  }
}

TEST(PumaIk, WristSingularityIsFlaggedAndStillReachesThePose) {
  const DhChain& robot = puma560();
  const Transform pose = fk(robot, JointVector(0.3, 0.2, 0.4, 0.7, 0.0, -0.5));
  const IkResult result = PumaIk(robot).solve(pose);
  EXPECT_TRUE(result.singularities & kWristSingularity);
  expect_all_solutions_reach(robot, result, pose);
  // The generating arm configuration has q5 = 0 in both wrist solutions: n takes the documented
  // q4 = 0 and q6 carries q4 + q6; f is its flip.
  int singular = 0;
  for (const IkSolution& solution : result.solutions) {
    if (!(solution.singularities & kWristSingularity)) continue;
    ++singular;
    const bool flip = solution.configuration.wrist == Wrist::flip;
    EXPECT_NEAR(solution.q[3], flip ? kPi : 0.0, 1e-12);
    EXPECT_NEAR(wrap_angle(solution.q[5] - (0.7 - 0.5) - (flip ? kPi : 0.0)), 0.0, 1e-9);
  }
  EXPECT_EQ(singular, 2);
}

TEST(PumaIk, ShoulderSingularityIsFlaggedAndStillReachesThePose) {
  // Wrist centre on the shoulder axis line: a2 c2 + a3 c23 - d4 s23 = 0 with q3 = 0.
  const DhChain& robot = puma560();
  const double q2 = std::atan2(0.4318 + 0.0203, 0.4318);
  const Transform pose = fk(robot, JointVector(0.4, q2, 0.0, 0.3, -0.6, 0.2));
  const IkResult result = PumaIk(robot).solve(pose);
  EXPECT_TRUE(result.singularities & kShoulderSingularity);
  expect_all_solutions_reach(robot, result, pose);
}

TEST(PumaIk, ElbowSingularityIsFlaggedAndStillReachesThePose) {
  // Fully stretched: q3 = -atan2(d4, a3).
  const DhChain& robot = puma560();
  const Transform pose =
      fk(robot, JointVector(-0.7, 0.5, -std::atan2(0.4318, 0.0203), 1.0, 0.8, -0.3));
  const IkResult result = PumaIk(robot).solve(pose);
  EXPECT_TRUE(result.singularities & kElbowSingularity);
  expect_all_solutions_reach(robot, result, pose);
  EXPECT_EQ(singularity_names(result.singularities), "elbow");
}

TEST(PumaIk, OutOfReachIsUnreachableWithNoSolutionsInLimits) {
  const PumaIk solver(puma560());
  Transform far = Transform::Identity();
  far.translation() << 2.0, 0.0, 0.5;
  EXPECT_EQ(solver.solve(far).status, IkStatus::unreachable);
  EXPECT_EQ(solver.solve(far).count_within_limits(), 0);
  EXPECT_FALSE(solver.solve(far).first_within_limits().has_value());
  Transform inside_shoulder_cylinder = Transform::Identity();  // closer to the axis than d3
  inside_shoulder_cylinder.translation() << 0.05, 0.05, 1.0;
  EXPECT_EQ(solver.solve(inside_shoulder_cylinder).status, IkStatus::unreachable);
}

TEST(PumaIk, RejectsChainsThatAreNotPumaLike) {
  EXPECT_THROW_MESSAGE(PumaIk(DhChain("two", {{}, {}})), "robot 'two' is not a Puma-type arm");
  std::vector<DhJoint> joints = puma560().joints();
  joints[4].a = 0.1;
  EXPECT_THROW_MESSAGE(PumaIk(DhChain("offset_wrist", joints)), "spherical wrist");
  joints = puma560().joints();
  joints[0].alpha = -joints[0].alpha;
  EXPECT_THROW_MESSAGE(PumaIk(DhChain("lee_signs", joints)), "Paul's signs");
}

TEST(PumaIk, ReportsTheInLimitRepresentativeForAsymmetricLimits) {
  // The toolbox's alternative range q2 in [-45, 225] degrees: q2 = 200 deg must be reported as
  // 200 deg (within limits), not as its wrapped value -160 deg.
  std::vector<DhJoint> joints = puma560().joints();
  joints[1].limits = {-45 * kPi / 180, 225 * kPi / 180};
  const DhChain robot("puma560_alt", joints);
  const JointVector q(0.2, 200 * kPi / 180, -0.5, 0.3, -0.6, 0.1);
  const IkResult result = PumaIk(robot).solve(fk(robot, q));
  ASSERT_TRUE(result.solved());
  bool found = false;
  for (const IkSolution& solution : result.solutions) {
    if (!same_angles(solution.q, q, 1e-9)) continue;
    found = true;
    EXPECT_NEAR(solution.q[1], q[1], 1e-9);
    EXPECT_TRUE(solution.within_limits);
  }
  EXPECT_TRUE(found);
}

TEST(PumaIk, HonoursOffsetsAndToolLength) {
  std::vector<DhJoint> joints = puma560().joints();
  joints[1].offset = 0.3;
  joints[5].d = 0.12;  // a flange-mounted tool length along z6
  const DhChain robot("puma560_tool", joints);
  const JointVector q(-0.4, 0.6, 0.5, -1.0, 0.7, 2.0);
  const Transform pose = fk(robot, q);
  const IkResult result = PumaIk(robot).solve(pose);
  expect_all_solutions_reach(robot, result, pose);
  bool found = false;
  for (const IkSolution& solution : result.solutions) found |= same_angles(solution.q, q, 1e-9);
  EXPECT_TRUE(found);
}

TEST(Reachability, NeedsAnInLimitConfigurationAndTheToolPointingDown) {
  const DhChain& robot = puma560();
  const PumaIk solver(robot);
  // q2 + q3 + q5 = pi with q4 = q6 = 0 points the flange z axis straight down; all in limits.
  const JointVector q_down(0.2, 0.3, 1.3, 0.0, kPi - 1.6, 0.0);
  const Transform down = fk(robot, q_down);
  const Reachability ok = reachable(solver, down);
  EXPECT_TRUE(ok.points_down);
  EXPECT_NEAR(ok.tool_tilt, 0.0, 1e-9);
  EXPECT_TRUE(ok.reachable);

  // The same position with the flange z axis pointing up.
  Transform up = down;
  up.linear() = Eigen::Matrix3d::Identity();
  const Reachability pointing_up = reachable(solver, up);
  EXPECT_FALSE(pointing_up.points_down);
  EXPECT_FALSE(pointing_up.reachable);

  // 60 degrees of tilt (q5 less by pi/3) passes a 70 degree cone, not the 45 degree default.
  JointVector q_tilted = q_down;
  q_tilted[4] -= kPi / 3;
  const Transform tilted = fk(robot, q_tilted);
  EXPECT_NEAR(reachable(solver, tilted).tool_tilt, kPi / 3, 1e-9);
  EXPECT_FALSE(reachable(solver, tilted).reachable);
  EXPECT_TRUE(reachable(solver, tilted, {.max_tool_tilt = 70 * kPi / 180}).reachable);

  // Pointing down but no configuration within limits (q3 would need about 175 degrees).
  Transform low = down;
  low.translation() << 0.5, -0.15, 0.4;
  EXPECT_TRUE(reachable(solver, low).points_down);
  EXPECT_TRUE(reachable(solver, low).inverse_kinematics.solved());
  EXPECT_FALSE(reachable(solver, low).reachable);

  // A tool 0.3 m long along the flange z: its tip 0.3 m lower puts the flange at `down`.
  Transform tool = Transform::Identity();
  tool.translation() << 0, 0, 0.3;
  Transform tip = down;
  tip.translation().z() -= 0.3;
  const Reachability with_tool = reachable(solver, tip, {.tool = tool});
  ASSERT_TRUE(with_tool.reachable);
  const JointVector q = with_tool.inverse_kinematics.first_within_limits()->q;
  EXPECT_LT(pose_error(fk(robot, q), down), 1e-9);
}

TEST(Reachability, ToolboxQnNeedsPerConfigurationLimits) {
  // Only rdn/rdf of qn's pose are within limits; that is enough for reachable() but the pose's
  // flange z axis is horizontal, so a 90 degree cone is needed.
  const Transform pose = puma560().forward({0.0, kPi / 4, kPi, 0.0, kPi / 4, 0.0});
  const Reachability result = reachable(PumaIk(puma560()), pose, {.max_tool_tilt = kPi / 2 + 1e-9});
  EXPECT_TRUE(result.reachable);
  EXPECT_EQ(result.inverse_kinematics.count_within_limits(), 2);
}

// ---- Properties -----------------------------------------------------------------------------

// A uniformly drawn angle in [lower, upper].
double draw(double lower, double upper) {
  constexpr int kSteps = 1 << 30;
  return lower + (upper - lower) * (*rc::gen::inRange(0, kSteps + 1)) / double(kSteps);
}

JointVector draw_within_limits(const DhChain& robot) {
  JointVector q;
  for (int i = 0; i < 6; ++i) {
    const JointLimits& limits = robot.joint(static_cast<std::size_t>(i)).limits;
    q[i] = draw(limits.lower, limits.upper);
  }
  return q;
}

// Away from the three singularities by a margin (sines and distance in metres).
bool far_from_singularities(const DhChain& robot, const JointVector& q) {
  const double a2 = robot.joint(1).a, a3 = robot.joint(2).a, d4 = robot.joint(3).d;
  const double arm_plane_x =
      a2 * std::cos(q[1]) + a3 * std::cos(q[1] + q[2]) - d4 * std::sin(q[1] + q[2]);
  return std::abs(std::sin(q[4])) > 0.05 && std::abs(arm_plane_x) > 0.02 &&
         std::abs(std::sin(q[2] + std::atan2(d4, a3))) > 0.05;
}

RC_GTEST_PROP(PumaIkProperty, InverseOfForwardContainsTheJointVector, ()) {
  for (const DhChain* robot : {&puma560(), &puma762()}) {
    const JointVector q = draw_within_limits(*robot);
    RC_PRE(far_from_singularities(*robot, q));
    const IkResult result = PumaIk(*robot).solve(fk(*robot, q));
    RC_ASSERT(result.solved());
    RC_ASSERT(result.singularities == kNoSingularity);
    int matches = 0;
    for (const IkSolution& solution : result.solutions) {
      if (!same_angles(solution.q, q, 1e-7)) continue;
      ++matches;
      RC_ASSERT(solution.within_limits);  // q itself is within limits
    }
    RC_ASSERT(matches == 1);
  }
}

RC_GTEST_PROP(PumaIkProperty, EverySolutionReachesThePoseAlsoAtSingularities, ()) {
  // Any joint vector (limits ignored), pushed onto the wrist, elbow or shoulder singularity (or
  // several) with some probability; every solution must be finite and reach the pose, and the
  // singularities built in must be flagged.
  const DhChain& robot = **rc::gen::element(&puma560(), &puma762());
  const double a2 = robot.joint(1).a, a3 = robot.joint(2).a, d4 = robot.joint(3).d;
  JointVector q;
  for (int i = 0; i < 6; ++i) q[i] = draw(-kPi, kPi);
  const bool wrist = *rc::gen::arbitrary<bool>();
  const bool elbow = *rc::gen::arbitrary<bool>();
  const bool shoulder = !elbow && *rc::gen::arbitrary<bool>();
  if (wrist) q[4] = 0.0;
  if (elbow) q[2] = -std::atan2(d4, a3);  // fully stretched
  if (shoulder) {                         // wrist centre above the shoulder: x1 = 0 with q3 = 0
    q[2] = 0.0;
    q[1] = std::atan2(a2 + a3, d4) + (*rc::gen::arbitrary<bool>() ? kPi : 0.0);
  }
  const Transform pose = fk(robot, q);
  const IkResult result = PumaIk(robot).solve(pose);
  RC_ASSERT(result.solved());
  RC_ASSERT(!wrist || (result.singularities & kWristSingularity));
  RC_ASSERT(!elbow || (result.singularities & kElbowSingularity));
  RC_ASSERT(!shoulder || (result.singularities & kShoulderSingularity));
  for (const IkSolution& solution : result.solutions) {
    RC_ASSERT(solution.q.allFinite());
    RC_ASSERT(pose_error(fk(robot, solution.q), pose) < 1e-9);
  }
}

}  // namespace
}  // namespace spar::kinematics
