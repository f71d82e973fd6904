// Instance selection (issue 10): SPAR examines plan instances in order until one has no error and
// otherwise keeps the one with the fewest errors; ties go to the earliest, so the choice is
// deterministic.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

std::vector<InstanceAnalysis> with_errors(const std::vector<int>& errors) {
  std::vector<InstanceAnalysis> examined;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    InstanceAnalysis analysis;
    analysis.instance = 10 + i;  // not the position: choose_instance returns the position
    analysis.errors = errors[i];
    examined.push_back(std::move(analysis));
  }
  return examined;
}

TEST(ChooseInstance, PicksTheFewestErrors) {
  EXPECT_EQ(choose_instance(with_errors({3, 1, 2})), 1u);
  EXPECT_EQ(choose_instance(with_errors({4, 3, 2, 1})), 3u);
  EXPECT_EQ(choose_instance(with_errors({5})), 0u);
  EXPECT_EQ(choose_instance(with_errors({2, 2, 0})), 2u);
}

TEST(ChooseInstance, TiesGoToTheEarliest) {
  EXPECT_EQ(choose_instance(with_errors({2, 1, 3, 1})), 1u);
  EXPECT_EQ(choose_instance(with_errors({1, 1, 1})), 0u);
  EXPECT_EQ(choose_instance(with_errors({3, 0, 0})), 1u);
}

TEST(ChooseInstance, NothingExaminedIsAnError) {
  try {
    (void)choose_instance({});
    ADD_FAILURE() << "an empty list was accepted";
  } catch (const PlanError& error) {
    EXPECT_NE(std::string(error.what()).find("no plan instance"), std::string::npos)
        << error.what();
  }
}

using testing::quick_options;

// The examined instances are the enumeration's first ones, in order; every one but the last has
// an error; the chosen one is the earliest with the fewest.
void expect_chosen_as_spar_would(const PlanResult& result) {
  ASSERT_FALSE(result.examined.empty());
  std::size_t best = 0;
  for (std::size_t i = 0; i < result.examined.size(); ++i) {
    EXPECT_EQ(result.examined[i].instance, result.instances.instances[i].index);
    if (i + 1 < result.examined.size()) {
      EXPECT_GT(result.examined[i].errors, 0) << "instance " << i;
    }
    if (result.examined[i].errors < result.examined[best].errors) best = i;
  }
  EXPECT_EQ(result.chosen_index, result.examined[best].instance);
  ASSERT_NE(result.chosen_analysis(), nullptr);
  EXPECT_EQ(result.chosen_analysis()->errors, result.examined[best].errors);
}

// The face-down experiment's first instance has no error (after sensing): phase 2 looks no further.
TEST(ChooseInstance, PlanStopsAtTheFirstInstanceWithoutErrors) {
  const PlanResult result =
      plan(load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/peg_block_face_down.yaml"),
           builtin_domain(), quick_options(3));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  ASSERT_GT(result.instances.instances.size(), 1u);
  expect_chosen_as_spar_would(result);
  ASSERT_EQ(result.examined.size(), 1u);
  EXPECT_EQ(result.chosen_analysis()->errors, 0);
}

// Without a sensor and with a clearance no instance can meet, every instance allowed is examined
// and the earliest of those with the fewest errors is chosen.
TEST(ChooseInstance, PlanKeepsTheEarliestWithTheFewestWhenNoneIsFree) {
  Scenario scenario =
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/peg_block_face_down.yaml");
  scenario.range_scan.reset();
  const PlanResult result = plan(scenario, builtin_domain(), quick_options(3));
  ASSERT_TRUE(result.planned()) << result.family.reason;
  ASSERT_EQ(result.examined.size(), result.instances.instances.size());
  expect_chosen_as_spar_would(result);
  EXPECT_GT(result.chosen_analysis()->errors, 0);
  // Deterministic: the same choice again.
  const PlanResult again = plan(scenario, builtin_domain(), quick_options(3));
  EXPECT_EQ(again.chosen_index, result.chosen_index);
  ASSERT_EQ(again.examined.size(), result.examined.size());
  for (std::size_t i = 0; i < result.examined.size(); ++i)
    EXPECT_EQ(again.examined[i].errors, result.examined[i].errors);
}

}  // namespace
}  // namespace spar::planner
