// Symbolic half of kinematics/: transforms over expressions, uncertain poses, symbolic DH forward
// kinematics and SPAR's pickup preconditions, checked against the numeric (Eigen) side.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/kinematics/pickup.hpp"
#include "spar/kinematics/pickup_check.hpp"
#include "spar/kinematics/puma.hpp"
#include "spar/kinematics/symbolic_dh.hpp"
#include "spar/kinematics/symbolic_transform.hpp"
#include "spar/kinematics/uncertain_pose.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/smp.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::kinematics {
namespace {

using symbolic::Expr;
using symbolic::ExprPool;

double max_difference(const Transform& a, const Transform& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

// A double in [-limit, limit] with 1e-6 resolution.
rc::Gen<double> coordinate(double limit) {
  const int steps = static_cast<int>(limit * 1e6);
  return rc::gen::map(rc::gen::inRange(-steps, steps + 1),
                      [](int k) { return static_cast<double>(k) * 1e-6; });
}

Transform numeric_rotz(double theta) {
  return Transform(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
}

TEST(SymbolicTransform, ElementaryTransformsMatchEigen) {
  ExprPool pool;
  const Expr x = pool.variable("x"), a = pool.variable("a"), b = pool.variable("b");
  const SymbolicTransform chain =
      trans(x, pool.integer(2), x * 3) * rotx(a) * roty(b) * rotz(a + b);
  const Transform expected = Eigen::Translation3d(0.7, 2, 2.1) *
                             Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(-0.9, Eigen::Vector3d::UnitZ());
  EXPECT_LT(max_difference(chain.evaluate({{"x", 0.7}, {"a", 0.3}, {"b", -1.2}}), expected), 1e-14);
}

TEST(SymbolicTransform, IdentityFactorsBuildNoNode) {
  ExprPool pool;
  const SymbolicTransform frame =
      trans(pool.variable("x"), pool.variable("y"), pool.integer(1)) * rotz(pool.variable("t"));
  const SymbolicTransform identity(pool);
  const std::size_t before = pool.size();
  const SymbolicTransform left = identity * frame, right = frame * identity;
  EXPECT_EQ(pool.size(), before);
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) {
      EXPECT_EQ(left.entry(row, column), frame.entry(row, column));
      EXPECT_EQ(right.entry(row, column), frame.entry(row, column));
    }
  }
}

TEST(SymbolicTransform, ConstantZerosCostNoWork) {
  // rotz(t) * rotz(u): each of the 4 in-plane entries is a sum of two products; the 5 others are
  // exact 0 / 1 and the translation stays exactly 0.
  ExprPool pool;
  const SymbolicTransform product = rotz(pool.variable("t")) * rotz(pool.variable("u"));
  EXPECT_EQ(product.entry(2, 2), pool.integer(1));
  EXPECT_EQ(product.entry(0, 2), pool.integer(0));
  EXPECT_EQ(product.entry(2, 0), pool.integer(0));
  EXPECT_EQ(product.translation()[0], pool.integer(0));
  EXPECT_EQ(symbolic::dag_size(product.entry(0, 0)), 9u);  // c_t c_u - s_t s_u over t, u
}

// rigid_inverse(T) * T is the identity at every point (T built from every elementary transform).
RC_GTEST_PROP(SymbolicTransform, RigidInverseTimesTransformIsIdentity, ()) {
  ExprPool pool;
  const Expr x = pool.variable("x"), y = pool.variable("y"), a = pool.variable("a"),
             b = pool.variable("b"), c = pool.variable("c");
  const SymbolicTransform frame = trans(x, y, x * y) * rotz(a) * roty(b) * trans(pool, 1, 2, 3) *
                                  rotx(c) * trans(y, pool.integer(0), x);
  const SymbolicTransform both = rigid_inverse(frame) * frame;
  const std::map<std::string, double> point = {{"x", *coordinate(10)},
                                               {"y", *coordinate(10)},
                                               {"a", *coordinate(4)},
                                               {"b", *coordinate(4)},
                                               {"c", *coordinate(4)}};
  RC_ASSERT(max_difference(both.evaluate(point), Transform::Identity()) < 1e-12);
  RC_ASSERT(max_difference((frame * rigid_inverse(frame)).evaluate(point), Transform::Identity()) <
            1e-12);
}

TEST(SymbolicTransform, RigidInverseTimesTransformSimplifiesToTheIdentity) {
  // After SMP (sin^2 + cos^2 = 1 and cancellation) the product is the identity exactly, not just
  // numerically.
  ExprPool pool;
  const Expr x = pool.variable("x"), y = pool.variable("y"), a = pool.variable("a");
  const SymbolicTransform frame = trans(x, y, pool.integer(3)) * rotz(a);
  const SymbolicTransform both = rigid_inverse(frame) * frame;
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) {
      EXPECT_EQ(symbolic::simplify(both.entry(row, column)), pool.integer(row == column ? 1 : 0))
          << row << ", " << column;
    }
  }
}

// Symbolic FK of the Puma 560 with joint-offset variables, at (q, δq), equals numeric FK at q + δq.
RC_GTEST_PROP(SymbolicDh, ForwardAtAPointEqualsNumericForward, ()) {
  const DhChain& robot = puma560();
  std::vector<double> q(6), shifted(6);
  std::map<std::string, double> offsets;
  for (int i = 0; i < 6; ++i) {
    q[i] = *coordinate(3);
    const double delta = *coordinate(0.01);
    offsets["dq" + std::to_string(i + 1)] = delta;
    shifted[i] = q[i] + delta;
  }
  ExprPool pool;
  const std::vector<double> widths(6, 0.01);
  const UncertainChainPose flange = uncertain_forward(pool, robot, q, widths);
  RC_ASSERT(flange.variables.size() == 6u);
  RC_ASSERT(max_difference(flange.pose.evaluate(offsets), robot.forward(shifted)) < 1e-12);
}

TEST(SymbolicDh, RejectsWrongCountsWithAMessage) {
  ExprPool pool;
  const std::vector<double> q(5, 0.0), widths(6, 0.0);
  EXPECT_THROW_MESSAGE(uncertain_forward(pool, puma560(), q, widths), "got 5 joint values");
}

TEST(UncertainPose, ManipulatorIsIdealTimesErrorOfEquationOne) {
  ExprPool pool;
  const UncertainManipulator gripper(pool, {0.1, 0.2, 0.3, 0.4});
  EXPECT_EQ(gripper.variables()[3].name, "dtheta_g");
  EXPECT_EQ(gripper.variables()[1].lower, -0.2);
  const Transform ideal = Eigen::Translation3d(1, 2, 3) * numeric_rotz(0.5);
  const std::map<std::string, double> point = {
      {"dx_g", 0.05}, {"dy_g", -0.1}, {"dz_g", 0.2}, {"dtheta_g", 0.3}};
  const Transform expected = ideal * Eigen::Translation3d(0.05, -0.1, 0.2) * numeric_rotz(0.3);
  EXPECT_LT(max_difference(gripper.possible_pose(ideal).evaluate(point), expected), 1e-14);
}

TEST(UncertainPose, ObjectRotatesAboutWorldZThroughItsOrigin) {
  // Eq. 2: the object's origin moves only by the displacement error, whatever Δθ_o is, and its
  // rotation error is about the world z axis even when R_O tips the object over.
  ExprPool pool;
  const UncertainObject object(pool, {0.1, 0.1, 0.1, 0.1});
  const Transform ideal = Eigen::Translation3d(5, 6, 1) *
                          Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX());
  const std::map<std::string, double> point = {
      {"dx_o", 0.01}, {"dy_o", 0.02}, {"dz_o", -0.03}, {"dtheta_o", 0.07}};
  Transform expected = Eigen::Translation3d(5.01, 6.02, 0.97) * numeric_rotz(0.07);
  expected.linear() = expected.linear() * ideal.linear();
  EXPECT_LT(max_difference(object.possible_pose(ideal).evaluate(point), expected), 1e-14);
  const SymbolicPoint p = object.possible_point(ideal, constant_point(pool, 1, 2, 3));
  const Eigen::Vector3d expected_point = expected * Eigen::Vector3d(1, 2, 3);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(symbolic::evaluate(p[k], point), expected_point[k], 1e-14);
}

TEST(UncertainPose, RejectsANegativeBoundWithAMessage) {
  ExprPool pool;
  EXPECT_THROW_MESSAGE(UncertainObject(pool, {0.1, -0.1, 0.1, 0.1}), "dy_o must be >= 0");
}

// A tipped-over object seen from a frame that is neither the world nor the object's.
struct PointInFrameCase {
  Transform ideal = Eigen::Translation3d(5, 6, 1) *
                    Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX());
  Transform frame =
      Eigen::Translation3d(4, 7, 2) * Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized());
};

RC_GTEST_PROP(UncertainPose, PointInFrameIsInverseFrameTimesPossiblePose, ()) {
  const PointInFrameCase c;
  ExprPool pool;
  const UncertainObject object(pool, {0.1, 0.1, 0.1, 0.1});
  const SymbolicPoint q = object.possible_point_in(SymbolicTransform::from_numeric(pool, c.frame),
                                                   c.ideal, constant_point(pool, 1, -2, 0.5));
  std::map<std::string, double> point;
  for (const UncertaintyVariable& v : object.variables()) point[v.name] = *coordinate(v.upper);
  const Eigen::Vector3d expected = c.frame.inverse(Eigen::Isometry) *
                                   object.possible_pose(c.ideal).evaluate(point) *
                                   Eigen::Vector3d(1, -2, 0.5);
  for (int k = 0; k < 3; ++k)
    RC_ASSERT(std::abs(symbolic::evaluate(q[k], point) - expected[k]) < 1e-12);
}

TEST(UncertainPose, PointInFrameHasEachObjectVariableOncePerCoordinate) {
  // One flat sum per coordinate: Δx, Δy, Δz once, Δθ twice (in cos Δθ and sin Δθ): occurrence
  // cost 1 with unit widths. Composing the same product as transforms repeats cos Δθ, sin Δθ.
  const PointInFrameCase c;
  ExprPool pool;
  const UncertainObject object(pool, {0.1, 0.1, 0.1, 0.1});
  const SymbolicTransform frame = SymbolicTransform::from_numeric(pool, c.frame);
  const SymbolicPoint local = constant_point(pool, 1, -2, 0.5);
  const SymbolicPoint flat = object.possible_point_in(frame, c.ideal, local);
  const SymbolicPoint composed = frame.apply_inverse(object.possible_point(c.ideal, local));
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(symbolic::occurrence_cost(flat[k]), 1.0) << k;
    EXPECT_GT(symbolic::occurrence_cost(composed[k]), 1.0) << k;
    EXPECT_LT(symbolic::dag_size(flat[k]), symbolic::dag_size(composed[k])) << k;
  }
}

TEST(UncertainPose, PointInFrameRejectsASymbolicFrameWithAMessage) {
  ExprPool pool;
  const UncertainObject object(pool, {0.1, 0.1, 0.1, 0.1});
  EXPECT_THROW_MESSAGE(object.possible_point_in(rotz(pool.variable("t")), Transform::Identity(),
                                                constant_point(pool, 1, 0, 0)),
                       "the frame must have constant entries");
}

// [0,1,0,0] P^-1 C computed numerically with Eigen from the header's definitions.
double numeric_condition(const PickupGeometry& g, const std::map<std::string, double>& v,
                         int finger, int contact) {
  const Transform gripper_error = Eigen::Translation3d(v.at("dx_g"), v.at("dy_g"), v.at("dz_g")) *
                                  numeric_rotz(v.at("dtheta_g"));
  const Transform finger_frame =
      g.object_pose * g.grasp * gripper_error *
      Eigen::Translation3d(0, (finger == 0 ? -0.5 : 0.5) * g.finger_opening, 0);
  Transform ideal_rotation = Transform::Identity();
  ideal_rotation.linear() = g.object_pose.linear();
  const Transform object = Eigen::Translation3d(v.at("dx_o"), v.at("dy_o"), v.at("dz_o")) *
                           Eigen::Translation3d(g.object_pose.translation()) *
                           numeric_rotz(v.at("dtheta_o")) * ideal_rotation;
  const Eigen::Vector3d c =
      object * g.grasp * Eigen::Vector3d(0, (contact == 0 ? 0.5 : -0.5) * g.object_width, 0);
  return (finger_frame.inverse(Eigen::Isometry) * c).y();
}

RC_GTEST_PROP(Pickup, ConditionsEqualTheNumericFingerFrameProducts, ()) {
  ExprPool pool;
  const UncertainManipulator gripper(pool, kTable2Gripper);
  const UncertainObject object(pool, kTable2Object);
  const PickupGeometry geometry = peg_pickup_example();
  const PickupPreconditions pre = pickup_preconditions(geometry, gripper, object);
  std::map<std::string, double> point;
  for (const UncertaintyVariable& v : pre.variables) point[v.name] = *coordinate(v.upper);
  for (int finger = 0; finger < 2; ++finger) {
    for (int contact = 0; contact < 2; ++contact) {
      const double value =
          symbolic::evaluate(pre.conditions[finger * 2 + contact].expression, point);
      RC_ASSERT(std::abs(value - numeric_condition(geometry, point, finger, contact)) <
                1e-12 * units::kInch);
    }
  }
}

// The same four conditions composed the plain way: full 4x4 products left to right,
// [0,1,0,0] (P^-1 · T_O+Δ T_G trans(0, ±W_g/2, 0)) [0,0,0,1]^T.
std::array<Expr, 4> transform_product_conditions(ExprPool& pool, const PickupGeometry& geometry,
                                                 const UncertainManipulator& gripper,
                                                 const UncertainObject& object) {
  const SymbolicTransform grasp = SymbolicTransform::from_numeric(pool, geometry.grasp);
  const SymbolicTransform fingers =
      SymbolicTransform::from_numeric(pool, geometry.object_pose) * grasp * gripper.error();
  const SymbolicTransform contacts = object.possible_pose(geometry.object_pose) * grasp;
  std::array<Expr, 4> conditions;
  for (int finger = 0; finger < 2; ++finger) {
    const SymbolicTransform inverse = rigid_inverse(
        fingers * trans(pool, 0, (finger == 0 ? -0.5 : 0.5) * geometry.finger_opening, 0));
    for (int contact = 0; contact < 2; ++contact) {
      conditions[finger * 2 + contact] =
          (inverse * contacts *
           trans(pool, 0, (contact == 0 ? 0.5 : -0.5) * geometry.object_width, 0))
              .translation()[1];
    }
  }
  return conditions;
}

TEST(Pickup, ExpressionsAreSmallerThanTransformProducts) {
  // Each condition is ±W_m/2 + cos Δθ_g (q_y - Δy_g) - sin Δθ_g (q_x - Δx_g) with q_x, q_y flat
  // sums in the object's variables (UncertainObject::possible_point_in). Measured: 35 nodes
  // each, 50 for all four (shared; in inches q_y's constant folded to an exact 0: 34 / 48, in
  // metres a 3e-17 m rounding residue stays); the transform products are larger and repeat the
  // variables more (occurrence cost with Table 2's widths).
  ExprPool pool;
  const UncertainManipulator gripper(pool, kTable2Gripper);
  const UncertainObject object(pool, kTable2Object);
  const PickupGeometry geometry = peg_pickup_example();
  const PickupPreconditions pre = pickup_preconditions(geometry, gripper, object);
  const std::array<Expr, 4> products =
      transform_product_conditions(pool, geometry, gripper, object);
  std::map<std::string, double> widths;
  for (const UncertaintyVariable& v : pre.variables) widths[v.name] = v.upper - v.lower;
  std::vector<Expr> ours;
  for (int i = 0; i < 4; ++i) {
    const Expr e = pre.conditions[i].expression;
    ours.push_back(e);
    EXPECT_LE(symbolic::dag_size(e), 35u) << pre.conditions[i].name;
    EXPECT_LT(symbolic::dag_size(e), symbolic::dag_size(products[i])) << pre.conditions[i].name;
    EXPECT_LT(symbolic::occurrence_cost(e, widths), symbolic::occurrence_cost(products[i], widths))
        << pre.conditions[i].name;
    EXPECT_EQ(symbolic::free_variables(e).size(), 7u) << pre.conditions[i].name;
  }
  EXPECT_LE(symbolic::dag_size(ours), 50u);
  EXPECT_LT(symbolic::dag_size(ours), symbolic::dag_size(products));
  EXPECT_EQ(pre.conditions[2].name, "0 > [0,1,0,0] P2^-1 C1");
  EXPECT_EQ(pre.variables.size(), 8u);
}

// The paper's peg pickup with Table 2's gripper bounds and the given object bounds.
struct PegPickup {
  explicit PegPickup(const PoseUncertainty& object_bounds = kTable2Object)
      : gripper(pool, kTable2Gripper),
        object(pool, object_bounds),
        pre(pickup_preconditions(peg_pickup_example(), gripper, object)) {}
  ExprPool pool;
  UncertainManipulator gripper;
  UncertainObject object;
  PickupPreconditions pre;
};

std::array<PickupCheck, 4> check_example(const PoseUncertainty& object_bounds) {
  return check_pickup(PegPickup(object_bounds).pre);
}

TEST(Pickup, PaperExampleIsSatisfiedUnderTable2) {
  // The tightest pair (P1·C2 and P2·C1) has 0.5 in of nominal clearance; Table 2's worst case
  // eats about 0.27 in of it, so all four are proved.
  for (const PickupCheck& check : check_example(kTable2Object)) {
    EXPECT_EQ(check.verdict, Verdict::kSatisfied) << check.condition.name;
    EXPECT_LE(check.bound.lo, check.bound.hi);
  }
}

TEST(Pickup, WidenedObjectUncertaintyIsDetectedAsViolated) {
  // +-0.4 in of object displacement moves a contact by up to 0.4 (|cos 30| + |sin 30|) = 0.55 in
  // across the fingers: past the 0.5 in clearance, so the two inner conditions fail at a witness.
  PoseUncertainty wide = kTable2Object;
  wide.dx = wide.dy = wide.dz = 0.4 * units::kInch;
  const std::array<PickupCheck, 4> checks = check_example(wide);
  EXPECT_EQ(checks[0].verdict, Verdict::kSatisfied) << checks[0].condition.name;
  EXPECT_EQ(checks[1].verdict, Verdict::kViolated) << checks[1].condition.name;
  EXPECT_EQ(checks[2].verdict, Verdict::kViolated) << checks[2].condition.name;
  EXPECT_EQ(checks[3].verdict, Verdict::kSatisfied) << checks[3].condition.name;
  // The witness really violates the inequality.
  std::map<std::string, double> witness;
  const PegPickup example(wide);
  const PickupPreconditions& pre = example.pre;
  for (std::size_t i = 0; i < pre.variables.size(); ++i) {
    witness[pre.variables[i].name] = checks[1].bound.argmin.at(i);
  }
  EXPECT_FALSE(pre.conditions[1].holds_at(witness));
}

TEST(PickupChecker, RecheckOverAWiderBoxMatchesAFreshCheck) {
  // One compiled checker, three boxes: Table 2, widened (two conditions fail), Table 2 again.
  PegPickup example;
  ExprPool& pool = example.pool;
  const PickupPreconditions& pre = example.pre;
  PickupChecker checker(pre);
  PoseUncertainty wide = kTable2Object;
  wide.dx = wide.dy = wide.dz = 0.4 * units::kInch;
  const UncertainObject wide_object(pool, wide);
  std::vector<UncertaintyVariable> wide_variables = pre.variables;
  std::copy(wide_object.variables().begin(), wide_object.variables().end(),
            wide_variables.begin() + 4);
  const std::array<PickupCheck, 4> fresh = check_example(wide);
  const std::array<PickupCheck, 4> rechecked = checker.check(wide_variables);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(rechecked[i].verdict, fresh[i].verdict) << fresh[i].condition.name;
  }
  EXPECT_EQ(rechecked[1].verdict, Verdict::kViolated);
  for (const PickupCheck& check : checker.check(pre.variables)) {
    EXPECT_EQ(check.verdict, Verdict::kSatisfied) << check.condition.name;
  }
}

RC_GTEST_PROP(PickupChecker, NaturalBoundsEncloseEveryPointOfTheBox, ()) {
  PegPickup example;
  const PickupPreconditions& pre = example.pre;
  const std::array<PickupCheck, 4> checks = check_pickup(pre);
  std::map<std::string, double> point;
  for (const UncertaintyVariable& v : pre.variables) point[v.name] = *coordinate(v.upper);
  for (const PickupCheck& check : checks) {
    RC_ASSERT(check.bound.evaluations == 1u);  // decided by the natural extension alone
    const double value = symbolic::evaluate(check.condition.expression, point);
    RC_ASSERT(check.bound.lo <= value);
    RC_ASSERT(value <= check.bound.hi);
  }
}

TEST(PickupChecker, RejectsVariablesInAnotherOrderWithAMessage) {
  PegPickup example;
  const PickupPreconditions& pre = example.pre;
  PickupChecker checker(pre);
  std::vector<UncertaintyVariable> swapped = pre.variables;
  std::swap(swapped[0], swapped[4]);
  EXPECT_THROW_MESSAGE(checker.check(swapped), "variable 0 is 'dx_o', expected 'dx_g'");
  swapped.pop_back();
  EXPECT_THROW_MESSAGE(checker.check(swapped), "expected 8 uncertainty variables, got 7");
}

TEST(Pickup, RejectsAZeroOpeningWithAMessage) {
  ExprPool pool;
  const UncertainManipulator gripper(pool, {});
  const UncertainObject object(pool, {});
  PickupGeometry geometry = peg_pickup_example();
  geometry.finger_opening = 0;
  EXPECT_THROW_MESSAGE(pickup_preconditions(geometry, gripper, object), "must be > 0");
}

}  // namespace
}  // namespace spar::kinematics
