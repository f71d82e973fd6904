// The arm's error from joint errors (kinematics/joint_error.hpp): the symbolic ΔT(δq) is the exact
// G(q)^-1 G(q + δq) of the numeric forward kinematics, for the UR5, the Panda and a chain with
// oblique, negative and prismatic axes, and the identity at δq = 0.
#include "spar/kinematics/joint_error.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "spar/kinematics/robots.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::kinematics {
namespace {

// A 4-joint chain whose axes are none of +z: -z, +x, oblique, and a prismatic one along -y.
RobotModel oblique_chain() {
  const auto joint = [](const char* name, const char* parent, const char* child, JointType type,
                        const Eigen::Vector3d& axis, const Eigen::Vector3d& offset) {
    Transform origin = Transform(Eigen::Translation3d(offset));
    origin.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
    return RobotJoint{.name = name,
                      .type = type,
                      .parent_link = parent,
                      .child_link = child,
                      .origin = origin,
                      .axis = axis,
                      .limits = {-2.0, 2.0}};
  };
  RobotDescription description{
      .name = "oblique",
      .source = "test",
      .base_link = "base",
      .tip_link = "tip",
      .chain =
          {joint("j1", "base", "l1", JointType::kRevolute, -Eigen::Vector3d::UnitZ(), {0, 0, 0.3}),
           joint("j2", "l1", "l2", JointType::kRevolute, Eigen::Vector3d::UnitX(), {0.1, 0, 0.2}),
           joint("j3", "l2", "l3", JointType::kRevolute, Eigen::Vector3d(0.6, 0.8, 0), {0, 0.4, 0}),
           joint("j4", "l3", "tip", JointType::kPrismatic, -Eigen::Vector3d::UnitY(),
                 {0.2, 0, 0.1})},
      .attachments = {},
      .links = {},
      .dh = nullptr};
  return RobotModel(description);
}

// ΔT at `dq` against G(q)^-1 G(q + dq) computed numerically; the largest entry difference.
double mismatch(const RobotModel& robot, const std::vector<double>& q, const Transform& tool,
                const std::vector<double>& dq) {
  symbolic::ExprPool pool;
  std::vector<symbolic::Expr> symbols;
  std::map<std::string, double> values;
  std::vector<double> moved = q;
  for (std::size_t i = 0; i < dq.size(); ++i) {
    const std::string name = "dq" + std::to_string(i + 1);
    symbols.push_back(pool.variable(name));
    values[name] = dq[i];
    moved[i] += dq[i];
  }
  const Transform symbolic = joint_error_transform(robot, q, tool, symbols).evaluate(values);
  const Transform numeric =
      (robot.forward(q) * tool).inverse(Eigen::Isometry) * robot.forward(moved) * tool;
  return (symbolic.matrix() - numeric.matrix()).cwiseAbs().maxCoeff();
}

std::vector<double> within_limits(const RobotModel& robot) {
  std::vector<double> q;
  for (const MovingJoint& joint : robot.joints()) {
    const double lower = std::max(joint.limits.lower, -3.0),
                 upper = std::min(joint.limits.upper, 3.0);
    q.push_back(lower + (upper - lower) * *rc::gen::inRange(0, 1001) / 1000.0);
  }
  return q;
}

std::vector<double> small_errors(std::size_t n) {
  std::vector<double> dq;
  for (std::size_t i = 0; i < n; ++i) dq.push_back(*rc::gen::inRange(-500, 501) / 1e4);  // ±0.05
  return dq;
}

const Transform kTool = Transform(Eigen::Translation3d(0.01, -0.02, 0.2)) *
                        Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX());

RC_GTEST_PROP(JointErrorProperty, Ur5ErrorIsTheForwardKinematicsRatio, ()) {
  const RobotModel& ur5 = builtin_robot_model("ur5");
  RC_ASSERT(mismatch(ur5, within_limits(ur5), kTool, small_errors(6)) < 1e-12);
}

RC_GTEST_PROP(JointErrorProperty, PandaErrorIsTheForwardKinematicsRatio, ()) {
  const RobotModel& panda = builtin_robot_model("panda");
  RC_ASSERT(mismatch(panda, within_limits(panda), kTool, small_errors(7)) < 1e-12);
}

RC_GTEST_PROP(JointErrorProperty, ObliqueAndPrismaticAxesAreExact, ()) {
  const RobotModel chain = oblique_chain();
  RC_ASSERT(mismatch(chain, within_limits(chain), kTool, small_errors(4)) < 1e-12);
}

TEST(JointError, IsTheIdentityWithoutErrorsAndMovesWithOne) {
  const RobotModel& panda = builtin_robot_model("panda");
  const std::vector<double> q = {0.1, -0.4, 0.3, -2.0, 0.2, 1.6, 0.7};
  symbolic::ExprPool pool;
  std::vector<symbolic::Expr> dq;
  std::map<std::string, double> values;
  for (int i = 1; i <= 7; ++i) {
    dq.push_back(pool.variable("dq" + std::to_string(i)));
    values["dq" + std::to_string(i)] = 0.0;
  }
  const SymbolicTransform error = joint_error_transform(panda, q, kTool, dq);
  EXPECT_LT((error.evaluate(values).matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(),
            1e-14);
  values["dq4"] = 0.01;  // the elbow: the gripper turns by 0.01 rad and moves
  const Transform moved = error.evaluate(values);
  EXPECT_NEAR(Eigen::AngleAxisd(moved.linear()).angle(), 0.01, 1e-12);
  EXPECT_GT(moved.translation().norm(), 1e-3);
}

TEST(JointError, RefusesACountMismatch) {
  symbolic::ExprPool pool;
  const std::vector<symbolic::Expr> dq = {pool.variable("a"), pool.variable("b")};
  EXPECT_THROW_MESSAGE(
      joint_error_transform(builtin_robot_model("ur5"), std::vector<double>(6, 0.0),
                            Transform::Identity(), dq),
      "ur5 has 6 moving joints, got 2 joint errors");
}

}  // namespace
}  // namespace spar::kinematics
