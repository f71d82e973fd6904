#include "spar/kinematics/dh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/kinematics/puma.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::kinematics {
namespace {

using units::kPi;

TEST(DhChain, ForwardIsTheProductOfLinkTransforms) {
  const DhChain& robot = puma560();
  const std::vector<double> q = {0.3, -1.1, 0.7, 2.0, -0.4, 1.3};
  Transform product = Transform::Identity();
  for (std::size_t i = 0; i < 6; ++i) {
    const DhJoint& joint = robot.joint(i);
    product = product * dh_link_transform(q[i] + joint.offset, joint.d, joint.a, joint.alpha);
  }
  EXPECT_LT((robot.forward(q).matrix() - product.matrix()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(DhChain, LinkTransformFollowsRzTzTxRx) {
  const double theta = 0.4, d = 0.2, a = 0.3, alpha = -0.9;
  const Transform expected = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()) *
                             Eigen::Translation3d(0, 0, d) * Eigen::Translation3d(a, 0, 0) *
                             Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX());
  EXPECT_LT(
      (dh_link_transform(theta, d, a, alpha).matrix() - expected.matrix()).cwiseAbs().maxCoeff(),
      1e-15);
}

TEST(DhChain, OffsetShiftsTheJointZero) {
  const DhChain plain("plain",
                      {{.d = 0.1, .a = 0.5, .alpha = 0.2, .offset = 0.0, .limits = {-3, 3}}});
  const DhChain shifted("shifted",
                        {{.d = 0.1, .a = 0.5, .alpha = 0.2, .offset = 0.25, .limits = {-3, 3}}});
  EXPECT_TRUE(shifted.forward({0.5}).isApprox(plain.forward({0.75}), 1e-15));
}

TEST(DhChain, Puma560ZeroPoseIsTheLShape) {
  const Eigen::Vector3d position = puma560().forward({0, 0, 0, 0, 0, 0}).translation();
  EXPECT_NEAR(position.x(), 0.4318 + 0.0203, 1e-12);
  EXPECT_NEAR(position.y(), -0.15005, 1e-12);
  EXPECT_NEAR(position.z(), 0.67183 + 0.4318, 1e-12);
}

TEST(DhChain, WrongJointCountIsAnError) {
  EXPECT_THROW_MESSAGE(puma560().forward({1.0, 2.0}), "has 6 joints but 2 joint angles");
  EXPECT_THROW_MESSAGE(puma560().within_limits(std::vector<double>(7, 0.0)),
                       "has 6 joints but 7 joint angles");
}

TEST(DhChain, InvertedLimitsAreAnError) {
  EXPECT_THROW_MESSAGE(DhChain("bad", {{.limits = {1.0, -1.0}}}), "joint 1 has lower limit");
  EXPECT_THROW_MESSAGE(DhChain("empty", {}), "has no joints");
}

TEST(DhChain, WithinLimitsChecksEveryJoint) {
  EXPECT_TRUE(puma560().within_limits(std::vector<double>{0, 0, 0, 0, 0, 0}));
  EXPECT_FALSE(puma560().within_limits(std::vector<double>{0, 0, 0, 0, 1.8, 0}));  // q5 > 100 deg
  EXPECT_TRUE(puma560().within_limits(std::vector<double>{0, 0, 0, 4.6, 0, -4.6}));
}

TEST(BuiltinRobot, UnknownNameListsTheKnownOnes) {
  EXPECT_EQ(&builtin_robot("puma762"), &puma762());
  EXPECT_THROW_MESSAGE(builtin_robot("puma600"), "unknown robot 'puma600'; built-in robots are");
}

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(-kPi), kPi);
  EXPECT_NEAR(wrap_angle(3 * kPi / 2), -kPi / 2, 1e-15);
  EXPECT_NEAR(wrap_angle(-7.0), -7.0 + 2 * kPi, 1e-15);
}

TEST(RigidTransform, ParsesRowMajor) {
  const std::vector<double> values = {0, -1, 0, 1.5,  //
                                      1, 0,  0, 2.5,  //
                                      0, 0,  1, 3.5,  //
                                      0, 0,  0, 1};
  const Transform pose = rigid_transform_from_row_major(values);
  EXPECT_EQ(pose.linear()(0, 1), -1.0);
  EXPECT_EQ(pose.translation(), Eigen::Vector3d(1.5, 2.5, 3.5));
}

TEST(RigidTransform, RejectsWhatIsNotARigidMotion) {
  std::vector<double> values = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_THROW_MESSAGE(rigid_transform_from_row_major(std::span(values).first(15)),
                       "needs 16 numbers");
  std::vector<double> scaled = values;
  scaled[0] = 2.0;
  EXPECT_THROW_MESSAGE(rigid_transform_from_row_major(scaled), "not orthonormal");
  std::vector<double> mirrored = values;
  mirrored[10] = -1.0;
  EXPECT_THROW_MESSAGE(rigid_transform_from_row_major(mirrored), "reflection");
  std::vector<double> projective = values;
  projective[12] = 0.5;
  EXPECT_THROW_MESSAGE(rigid_transform_from_row_major(projective), "last row");
  std::vector<double> not_finite = values;
  not_finite[3] = std::nan("");
  EXPECT_THROW_MESSAGE(rigid_transform_from_row_major(not_finite), "non-finite");
}

}  // namespace
}  // namespace spar::kinematics
