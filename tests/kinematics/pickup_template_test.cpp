// PickupTemplate (kinematics/pickup_template.hpp) against the per-instance path
// check_pickup(pickup_preconditions(...)): same verdicts and bounds up to rounding, sound bounds
// at random points of the box, the same argument errors.
#include "spar/kinematics/pickup_template.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/tape.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::kinematics {
namespace {

using bounds::Interval;

// The per-instance path's checks over `variables` (the template's names, any bounds).
std::array<PickupCheck, 4> existing_checks(const PickupGeometry& geometry,
                                           const PoseUncertainty& gripper_bounds,
                                           const PoseUncertainty& object_bounds,
                                           std::span<const UncertaintyVariable> variables,
                                           const bounds::BoundOptions& full = {}) {
  symbolic::ExprPool pool;
  const UncertainManipulator gripper(pool, gripper_bounds);
  const UncertainObject object(pool, object_bounds);
  PickupChecker checker(pickup_preconditions(geometry, gripper, object));
  std::array<PickupCheck, 4> checks = checker.check(variables, full);
  // The expressions die with the pool: keep only what the tests compare.
  for (PickupCheck& check : checks) check.condition.expression = symbolic::Expr();
  return checks;
}

// Equal up to rounding: 1e-12 relative to `scale`, or a few ulps of the geometry's ~1 m numbers
// (both paths fold the same reals, rounded in a different order: Number vs Interval arithmetic).
bool close(double a, double b, double scale) { return std::abs(a - b) <= 1e-12 * scale + 1e-15; }

TEST(PickupTemplate, PaperExampleMatchesThePerInstancePath) {
  const PickupGeometry geometry = peg_pickup_example();
  PickupTemplate pickup(kTable2Gripper, kTable2Object);
  const std::array<PickupCheck, 4> ours = pickup.check(geometry);
  const std::array<PickupCheck, 4> theirs =
      existing_checks(geometry, kTable2Gripper, kTable2Object, pickup.variables());
  for (int k = 0; k < 4; ++k) {
    SCOPED_TRACE(theirs[k].condition.name);
    EXPECT_EQ(ours[k].condition.name, theirs[k].condition.name);
    EXPECT_EQ(ours[k].condition.positive, theirs[k].condition.positive);
    EXPECT_EQ(ours[k].verdict, Verdict::kSatisfied);
    EXPECT_EQ(ours[k].verdict, theirs[k].verdict);
    const double scale = std::abs(theirs[k].bound.lo) + std::abs(theirs[k].bound.hi);
    EXPECT_TRUE(close(ours[k].bound.lo, theirs[k].bound.lo, scale))
        << ours[k].bound.lo << " vs " << theirs[k].bound.lo;
    EXPECT_TRUE(close(ours[k].bound.hi, theirs[k].bound.hi, scale))
        << ours[k].bound.hi << " vs " << theirs[k].bound.hi;
    EXPECT_EQ(ours[k].bound.argmin.size(), 8u);  // the uncertainty coordinates only
    // The inner bounds follow bounds::order_inner_bounds, the rule the per-instance path uses.
    EXPECT_NO_THROW(ours[k].bound.check_invariants());
    ASSERT_TRUE(ours[k].bound.has_inner_range());
    EXPECT_TRUE(close(ours[k].bound.inner_lo, theirs[k].bound.inner_lo, scale))
        << ours[k].bound.inner_lo << " vs " << theirs[k].bound.inner_lo;
    EXPECT_TRUE(close(ours[k].bound.inner_hi, theirs[k].bound.inner_hi, scale))
        << ours[k].bound.inner_hi << " vs " << theirs[k].bound.inner_hi;
  }
}

TEST(PickupTemplate, ConditionsAreOverTheUncertaintyVariablesAndPickupParameters) {
  PickupTemplate pickup(kTable2Gripper, kTable2Object);
  const std::array<PickupCheck, 4> checks = pickup.check(peg_pickup_example());
  for (const symbolic::Expr v : symbolic::free_variables(checks[0].condition.expression)) {
    const std::string name = v.name();
    const bool uncertainty =
        std::any_of(pickup.variables().begin(), pickup.variables().end(),
                    [&](const UncertaintyVariable& u) { return u.name == name; });
    EXPECT_TRUE(uncertainty || name.rfind("pickup_", 0) == 0) << name;
  }
}

TEST(PickupTemplate, ResultsDoNotDependOnEarlierInstances) {
  PickupTemplate pickup(kTable2Gripper, kTable2Object);
  const PickupGeometry example = peg_pickup_example();
  PickupGeometry narrow = example;
  narrow.finger_opening = narrow.object_width * 0.9;  // the fingers close on the object
  const std::array<PickupCheck, 4> first = pickup.check(example);
  const std::array<PickupCheck, 4> violated = pickup.check(narrow);
  const std::array<PickupCheck, 4> again = pickup.check(example);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(first[k].verdict, again[k].verdict);
    EXPECT_EQ(first[k].bound.lo, again[k].bound.lo);
    EXPECT_EQ(first[k].bound.hi, again[k].bound.hi);
  }
  // The contacts lie outside the closed fingers: C2 (at -W_g/2) beyond P1, C1 beyond P2.
  EXPECT_EQ(violated[0].verdict, Verdict::kSatisfied);
  EXPECT_EQ(violated[1].verdict, Verdict::kViolated);
  EXPECT_EQ(violated[2].verdict, Verdict::kViolated);
  EXPECT_EQ(violated[3].verdict, Verdict::kSatisfied);
}

TEST(PickupTemplate, ViolationWitnessBreaksTheExactCondition) {
  PickupGeometry narrow = peg_pickup_example();
  narrow.finger_opening = narrow.object_width * 0.9;
  PickupTemplate pickup(kTable2Gripper, kTable2Object);
  const std::array<PickupCheck, 4> ours = pickup.check(narrow);
  symbolic::ExprPool pool;
  const UncertainManipulator gripper(pool, kTable2Gripper);
  const UncertainObject object(pool, kTable2Object);
  const PickupPreconditions pre = pickup_preconditions(narrow, gripper, object);
  for (int k = 0; k < 4; ++k) {
    if (ours[k].verdict != Verdict::kViolated) continue;
    const std::vector<double>& point =
        pre.conditions[k].positive ? ours[k].bound.argmin : ours[k].bound.argmax;
    ASSERT_EQ(point.size(), pre.variables.size());
    std::map<std::string, double> values;
    for (std::size_t i = 0; i < point.size(); ++i) values[pre.variables[i].name] = point[i];
    EXPECT_FALSE(pre.conditions[k].holds_at(values)) << pre.conditions[k].name;
  }
}

TEST(PickupTemplate, RejectsWhatThePerInstancePathRejects) {
  EXPECT_THROW_MESSAGE(PickupTemplate({.dx = -1}, kTable2Object), "must be >= 0");
  PickupTemplate pickup(kTable2Gripper, kTable2Object);
  PickupGeometry geometry = peg_pickup_example();
  geometry.object_width = 0;
  EXPECT_THROW_MESSAGE(pickup.check(geometry), "finger opening and object width must be > 0");
  geometry = peg_pickup_example();
  geometry.finger_opening = std::nan("");
  EXPECT_THROW_MESSAGE(pickup.check(geometry), "finger opening and object width must be > 0");
  geometry = peg_pickup_example();
  geometry.finger_opening = std::numeric_limits<double>::infinity();
  EXPECT_THROW_MESSAGE(pickup.check(geometry), "poses and widths must be finite");
  geometry = peg_pickup_example();
  geometry.grasp.translation().x() = std::nan("");
  EXPECT_THROW_MESSAGE(pickup.check(geometry), "poses and widths must be finite");
  geometry = peg_pickup_example();
  std::vector<UncertaintyVariable> variables(pickup.variables().begin(), pickup.variables().end());
  EXPECT_THROW_MESSAGE(pickup.check(geometry, std::span(variables).first(7)),
                       "expected 8 uncertainty variables, got 7");
  variables[2].name = "dz_x";
  EXPECT_THROW_MESSAGE(pickup.check(geometry, variables), "variable 2 is 'dz_x', expected 'dz_g'");
  variables[2].name = "dz_g";
  variables[5].lower = 1;
  EXPECT_THROW_MESSAGE(pickup.check(geometry, variables), "empty range for 'dy_o'");
}

// A double in [lo, hi] on a grid of 2^20 steps (RapidCheck shrinks integers).
double uniform(double lo, double hi) {
  constexpr int kSteps = 1 << 20;
  return lo + (hi - lo) * (*rc::gen::inRange(0, kSteps + 1)) / double(kSteps);
}

Transform random_pose(double reach) {
  Eigen::Vector3d axis(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
  if (axis.norm() < 1e-3) axis = Eigen::Vector3d::UnitZ();
  return Eigen::Translation3d(uniform(-reach, reach), uniform(-reach, reach),
                              uniform(-reach, reach)) *
         Eigen::AngleAxisd(uniform(-std::numbers::pi, std::numbers::pi), axis.normalized());
}

// The exact condition's enclosure at `point` (the per-instance expression, outward rounded).
Interval exact_value_at(const PickupCondition& condition, const std::vector<symbolic::Expr>& inputs,
                        std::span<const double> point) {
  const symbolic::Tape tape = symbolic::Tape::compile({&condition.expression, 1}, inputs);
  symbolic::TapeEvaluator<Interval> evaluator(tape);
  std::vector<Interval> at(point.begin(), point.end());
  Interval value;
  evaluator.evaluate(at, {&value, 1});
  return value;
}

// Over random geometries (object pose, grasp, widths with fingers from too narrow to wide) and
// scaled boxes: (1) the verdict is the per-instance path's unless that one's bound is within
// rounding of 0 (then the template may say undecided); (2) the exact condition at random points
// of the box lies in the template's [lo, hi].
RC_GTEST_PROP(PickupTemplateProperty, AgreesWithThePerInstancePathAndEnclosesTheExactValue, ()) {
  static PickupTemplate pickup(kTable2Gripper, kTable2Object);
  PickupGeometry geometry;
  geometry.object_pose = random_pose(1.0);
  geometry.grasp = random_pose(0.05);
  geometry.object_width = uniform(0.01, 0.1);
  geometry.finger_opening = geometry.object_width + uniform(-0.002, 0.02);  // near the edge
  const double scale = uniform(0.01, 2.0);
  std::vector<UncertaintyVariable> variables(pickup.variables().begin(), pickup.variables().end());
  for (UncertaintyVariable& v : variables) {
    v.lower *= scale;
    v.upper *= scale;
  }
  const bounds::BoundOptions full{.max_box_evaluations = 2000};
  const std::array<PickupCheck, 4> ours = pickup.check(geometry, variables, full);

  symbolic::ExprPool pool;
  const UncertainManipulator gripper(pool, kTable2Gripper);
  const UncertainObject object(pool, kTable2Object);
  const PickupPreconditions pre = pickup_preconditions(geometry, gripper, object);
  PickupChecker checker(pre);
  const std::array<PickupCheck, 4> theirs = checker.check(variables, full);
  std::vector<symbolic::Expr> inputs;
  for (const UncertaintyVariable& v : pre.variables) inputs.push_back(pool.variable(v.name));

  int satisfied = 0, violated = 0, undecided = 0, full_bounds = 0, wider = 0;
  for (int k = 0; k < 4; ++k) {
    const bounds::BoundResult& bound = ours[k].bound;
    satisfied += ours[k].verdict == Verdict::kSatisfied ? 1 : 0;
    violated += ours[k].verdict == Verdict::kViolated ? 1 : 0;
    undecided += ours[k].verdict == Verdict::kUndecided ? 1 : 0;
    full_bounds += bound.evaluations > 1 ? 1 : 0;
    wider += bound.hi - bound.lo > 1.01 * (theirs[k].bound.hi - theirs[k].bound.lo) ? 1 : 0;
    if (ours[k].verdict != theirs[k].verdict) {
      const double edge = std::min(std::abs(theirs[k].bound.lo), std::abs(theirs[k].bound.hi));
      RC_ASSERT(ours[k].verdict == Verdict::kUndecided);
      RC_ASSERT(edge <= 1e-12 * (theirs[k].bound.hi - theirs[k].bound.lo));
    }
    if (ours[k].bound.evaluations == 1 && theirs[k].bound.evaluations == 1) {
      const double magnitude = std::abs(theirs[k].bound.lo) + std::abs(theirs[k].bound.hi);
      RC_ASSERT(close(bound.lo, theirs[k].bound.lo, magnitude));
      RC_ASSERT(close(bound.hi, theirs[k].bound.hi, magnitude));
    }
    for (int sample = 0; sample < 4; ++sample) {
      std::vector<double> point;
      for (const UncertaintyVariable& v : variables) point.push_back(uniform(v.lower, v.upper));
      const Interval exact = exact_value_at(pre.conditions[k], inputs, point);
      RC_ASSERT(exact.hi >= bound.lo);
      RC_ASSERT(exact.lo <= bound.hi);
    }
  }
  RC_TAG(satisfied, violated, undecided);  // the verdicts' distribution over the cases
  RC_CLASSIFY(full_bounds > 0, "some condition went to bound()");
  RC_CLASSIFY(wider > 0, "some bound over 1% wider than the per-instance path's");
}

}  // namespace
}  // namespace spar::kinematics
