// UncertaintySpace (issue 10): every allocation makes fresh, uniquely named variables with their
// ranges and provenance; ranges can be replaced (validated) and are produced in the order asked.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "spar/planner/error.hpp"
#include "spar/planner/uncertainty/space.hpp"

namespace spar::planner {
namespace {

const kinematics::PoseUncertainty kHalfWidths{0.001, 0.002, 0.003, 0.04};

std::vector<std::string> names(const UncertaintySpace& space) {
  std::vector<std::string> out;
  for (const SpaceVariable& v : space.variables()) out.push_back(v.name);
  return out;
}

TEST(UncertaintySpace, AllocatesFourNamedVariablesWithRangesAndProvenance) {
  symbolic::ExprPool pool;
  UncertaintySpace space(pool);
  const kinematics::PoseError peg = space.allocate_pose(
      kHalfWidths, {.source = UncertaintySource::kInitial, .object = 1, .step = -1}, "peg");
  EXPECT_EQ(names(space), (std::vector<std::string>{"dx_peg", "dy_peg", "dz_peg", "dtheta_peg"}));
  EXPECT_EQ(peg.dx.name(), "dx_peg");
  EXPECT_EQ(peg.dtheta.name(), "dtheta_peg");
  const std::vector<SpaceVariable>& v = space.variables();
  const double widths[4] = {0.001, 0.002, 0.003, 0.04};
  const PoseComponent components[4] = {PoseComponent::kDx, PoseComponent::kDy, PoseComponent::kDz,
                                       PoseComponent::kDtheta};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(v[i].lower, -widths[i]);
    EXPECT_EQ(v[i].upper, widths[i]);
    EXPECT_EQ(v[i].component, components[i]);
    EXPECT_EQ(v[i].provenance.source, UncertaintySource::kInitial);
    EXPECT_EQ(v[i].provenance.object, 1);
    EXPECT_EQ(v[i].provenance.step, -1);
    EXPECT_EQ(space.symbols()[i], pool.variable(v[i].name));
    EXPECT_EQ(space.id_of(space.symbols()[i]), VariableId{static_cast<std::uint32_t>(i)});
  }
  EXPECT_EQ(&space.pool(), &pool);
  EXPECT_STREQ(to_string(UncertaintySource::kInitial), "initial");
  EXPECT_STREQ(to_string(UncertaintySource::kManipulator), "manipulator");
  EXPECT_STREQ(to_string(UncertaintySource::kSensor), "sensor");
}

TEST(UncertaintySpace, ClashingTagsGetSuffixesAndStayDistinct) {
  symbolic::ExprPool pool;
  UncertaintySpace space(pool);
  // Two objects both called "peg" (or a tag that looks like another's suffix) never share.
  const kinematics::PoseError first =
      space.allocate_pose(kHalfWidths, {.source = UncertaintySource::kInitial, .object = 0}, "peg");
  const kinematics::PoseError second =
      space.allocate_pose(kHalfWidths, {.source = UncertaintySource::kInitial, .object = 1}, "peg");
  const kinematics::PoseError third = space.allocate_pose(
      kHalfWidths, {.source = UncertaintySource::kSensor, .object = 1, .step = 3}, "peg");
  const kinematics::PoseError fourth = space.allocate_pose(
      kHalfWidths, {.source = UncertaintySource::kSensor, .object = 0, .step = 4}, "peg_2");
  EXPECT_NE(first.dx, second.dx);
  EXPECT_EQ(second.dx.name(), "dx_peg_2");
  EXPECT_EQ(third.dtheta.name(), "dtheta_peg_3");
  EXPECT_NE(fourth.dx, second.dx);
  const std::vector<std::string> all = names(space);
  EXPECT_EQ(std::set<std::string>(all.begin(), all.end()).size(), all.size());
  EXPECT_EQ(all.size(), 16u);
  // Provenance, not the name, tells which object and step a variable belongs to.
  EXPECT_EQ(space.variable(*space.id_of(second.dy)).provenance.object, 1);
  EXPECT_EQ(space.variable(*space.id_of(third.dy)).provenance.source, UncertaintySource::kSensor);
  EXPECT_EQ(space.variable(*space.id_of(third.dy)).provenance.step, 3);
  EXPECT_EQ(space.variable(*space.id_of(fourth.dz)).provenance.object, 0);
}

TEST(UncertaintySpace, CopiesAllocateIndependently) {
  symbolic::ExprPool pool;
  UncertaintySpace space(pool);
  (void)space.allocate_pose(kHalfWidths, {}, "g1");
  UncertaintySpace copy = space;
  (void)copy.allocate_pose(kHalfWidths, {}, "g2");
  copy.set_range(VariableId{0}, -1.0, 1.0);
  EXPECT_EQ(space.variables().size(), 4u);
  EXPECT_EQ(copy.variables().size(), 8u);
  EXPECT_EQ(space.variables()[0].upper, 0.001);
}

TEST(UncertaintySpace, SetRangeReplacesAndValidates) {
  symbolic::ExprPool pool;
  UncertaintySpace space(pool);
  (void)space.allocate_pose(kHalfWidths, {}, "o");
  space.set_range(VariableId{1}, -0.5, 0.25);
  EXPECT_EQ(space.variables()[1].lower, -0.5);
  EXPECT_EQ(space.variables()[1].upper, 0.25);
  space.set_range(VariableId{2}, 0.1, 0.1);  // a point is a range
  EXPECT_EQ(space.variables()[2].lower, 0.1);
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [lower, upper] : std::vector<std::pair<double, double>>{
           {0.2, 0.1}, {-inf, 0.0}, {0.0, inf}, {nan, 0.0}, {0.0, nan}}) {
    try {
      space.set_range(VariableId{3}, lower, upper);
      ADD_FAILURE() << "accepted [" << lower << ", " << upper << "]";
    } catch (const PlanError& error) {
      EXPECT_NE(std::string(error.what()).find("dtheta_o"), std::string::npos) << error.what();
    }
  }
  EXPECT_EQ(space.variables()[3].upper, 0.04) << "a refused range changed the variable";
  EXPECT_THROW(space.set_range(VariableId{4}, 0.0, 0.0), std::out_of_range);
}

TEST(UncertaintySpace, AllocationRefusesBadHalfWidths) {
  symbolic::ExprPool pool;
  UncertaintySpace space(pool);
  for (const kinematics::PoseUncertainty bad :
       {kinematics::PoseUncertainty{-0.001, 0, 0, 0}, kinematics::PoseUncertainty{0, 0, 0, NAN},
        kinematics::PoseUncertainty{0, INFINITY, 0, 0}}) {
    try {
      (void)space.allocate_pose(bad, {}, "peg");
      ADD_FAILURE() << "a bad half-width was accepted";
    } catch (const PlanError& error) {
      EXPECT_NE(std::string(error.what()).find("peg"), std::string::npos) << error.what();
    }
  }
  EXPECT_TRUE(space.variables().empty()) << "a refused allocation left variables behind";
}

TEST(UncertaintySpace, RangesFollowTheOrderAsked) {
  symbolic::ExprPool pool;
  UncertaintySpace space(pool);
  const kinematics::PoseError e = space.allocate_pose(kHalfWidths, {}, "o");
  space.set_range(VariableId{0}, -0.3, 0.1);
  const std::vector<VariableId> order = {*space.id_of(e.dtheta), *space.id_of(e.dx),
                                         *space.id_of(e.dz), *space.id_of(e.dx)};
  const std::vector<bounds::Interval> box = space.ranges(order);
  ASSERT_EQ(box.size(), 4u);
  EXPECT_EQ(box[0].lo, -0.04);
  EXPECT_EQ(box[0].hi, 0.04);
  EXPECT_EQ(box[1].lo, -0.3);
  EXPECT_EQ(box[1].hi, 0.1);
  EXPECT_EQ(box[2].hi, 0.003);
  EXPECT_EQ(box[3].lo, -0.3);
  EXPECT_TRUE(space.ranges({}).empty());
  // Another expression, even a variable of the pool, is no variable of the space.
  EXPECT_FALSE(space.id_of(pool.variable("dx_other")).has_value());
  EXPECT_FALSE(space.id_of(e.dx + e.dy).has_value());
  EXPECT_THROW((void)space.ranges(std::vector{VariableId{4}}), std::out_of_range);
}

}  // namespace
}  // namespace spar::planner
