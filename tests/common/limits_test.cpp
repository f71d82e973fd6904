// The table of numeric limits (common/limits.hpp, issue 22): every row is well formed, the bounds
// hold exactly, and the messages show the range in the unit the value was given in.
#include "spar/common/limits.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

#include "spar/common/units.hpp"

namespace spar {
namespace {

TEST(NumericLimits, EveryRowIsWellFormed) {
  std::set<std::string_view> keys;
  for (const NumericLimit& limit : numeric_limits()) {
    SCOPED_TRACE(std::string(limit.key));
    EXPECT_TRUE(keys.insert(limit.key).second) << "a key appears twice";
    EXPECT_TRUE(std::isfinite(limit.low) && std::isfinite(limit.high));
    EXPECT_LT(limit.low, limit.high);
    EXPECT_FALSE(limit.reason.empty());
    EXPECT_TRUE(limit.contains(limit.high));
    EXPECT_EQ(limit.contains(limit.low), !limit.low_exclusive);
    EXPECT_FALSE(limit.contains(std::nextafter(limit.high, HUGE_VAL)));
    EXPECT_FALSE(limit.contains(std::numeric_limits<double>::quiet_NaN()));
    EXPECT_FALSE(limit.contains(std::numeric_limits<double>::infinity()));
    EXPECT_EQ(&numeric_limit(limit.key), &limit);
  }
  EXPECT_THROW((void)numeric_limit("no.such.key"), std::logic_error);
}

TEST(NumericLimits, TheValuesOfIssue22AreRefused) {
  EXPECT_FALSE(numeric_limit("robot.gripper.max_opening").contains(1e308));
  EXPECT_FALSE(numeric_limit("grasping.approach_step").contains(1e-9));
  EXPECT_FALSE(numeric_limit("grasping.positions_per_axis").contains(1e6));
  EXPECT_FALSE(numeric_limit("grasping.positions_per_axis").contains(2.5));  // a count is whole
  EXPECT_FALSE(numeric_limit("scenario.places").contains(100'000));
  // The seed's values pass: a 4 in gripper, 45 deg steps, one position.
  EXPECT_TRUE(numeric_limit("robot.gripper.max_opening").contains(4 * units::kInch));
  EXPECT_TRUE(numeric_limit("grasping.approach_step").contains(45 * units::kDegree));
  EXPECT_TRUE(numeric_limit("grasping.positions_per_axis").contains(1));
}

TEST(NumericLimits, MessagesUseTheGivenUnit) {
  const NumericLimit& opening = numeric_limit("robot.gripper.max_opening");
  EXPECT_EQ(limit_problem(opening, 0.1), std::nullopt);
  EXPECT_EQ(*limit_problem(opening, 1e308 * units::kInch, {units::kInch, "in"}, "1e308"),
            "must be a length > 0 and <= 78.7402 in (the widest parallel gripper spar models), "
            "got 1e308 in");
  EXPECT_EQ(*limit_problem(opening, 3),
            "must be a length > 0 and <= 2 m (the widest parallel "
            "gripper spar models), got 3 m");
  EXPECT_EQ(describe_limit(numeric_limit("pose.angle"), {units::kDegree, "deg"}),
            "an angle from -360 deg to 360 deg");
  EXPECT_EQ(*limit_problem(numeric_limit("grasping.positions_per_axis"), 0),
            "must be a whole number >= 1 and <= 20 (a face pair gets the square of it as contact "
            "positions), got 0");
}

}  // namespace
}  // namespace spar
