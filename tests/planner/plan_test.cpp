// Phase 1 of the planner on the seed's four peg-and-block experiments, every instance checked by an
// independent simulation (plan_checker.hpp), and a property over random initial poses.
#include "spar/planner/plan.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "tests/planner/checked_plan.hpp"
#include "tests/planner/collision_checker.hpp"
#include "tests/planner/plan_checker.hpp"
#include "tests/planner/plan_options.hpp"
#include "tests/planner/random_placement.hpp"

namespace spar::planner {
namespace {

using testing::actions;
using testing::check_instance;

Scenario example(const std::string& name) {
  return load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/" + name + ".yaml");
}

std::vector<std::vector<geometry::Grasp>> grasps_of(const Scenario& scenario) {
  geometry::GripperSpec gripper = scenario.robot.gripper;
  gripper.max_approach_tilt = scenario.robot.max_tool_tilt;
  std::vector<std::vector<geometry::Grasp>> grasps;
  for (const ObjectSpec& object : scenario.objects)
    grasps.push_back(geometry::compute_grasps(object.model, gripper, scenario.grasping));
  return grasps;
}

PlanOptions phase1_only() {
  PlanOptions options;
  options.uncertainty = false;
  return options;
}

void expect_every_instance_valid(const Scenario& scenario, const PlanResult& result) {
  const auto grasps = grasps_of(scenario);
  const testing::IndependentCollisionChecker collisions(scenario, grasps);
  ASSERT_FALSE(result.instances.instances.empty());
  for (const PlanInstance& instance : result.instances.instances) {
    const std::vector<std::string> problems = check_instance(scenario, grasps, instance);
    EXPECT_TRUE(problems.empty()) << "instance " << instance.index << ": " << problems.front();
    const std::vector<std::string> hits = collisions.check(instance);
    EXPECT_TRUE(hits.empty()) << "instance " << instance.index << ": " << hits.front();
  }
}

TEST(PlanSeedExperiments, BlockFaceDownIsPutDownTwiceThenThePegGoesIn) {
  const Scenario scenario = example("peg_block_face_down");
  const PlanResult result = plan(scenario, builtin_domain(), phase1_only());
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const std::vector<std::string> steps = actions(scenario, result.chosen());
  const std::vector<std::string> expected = {"pickup block",  "putdown block", "pickup block",
                                             "putdown block", "pickup peg",    "assemble peg"};
  EXPECT_EQ(steps, expected);
  // The first putdown leaves the block on a side, the second on its back (hole up, P5).
  const InstanceStep& first = result.chosen().steps[1];
  const InstanceStep& second = result.chosen().steps[3];
  const auto& poses = scenario.object("block").stable_poses;
  EXPECT_NE(poses[first.stable_pose].label, "P5");
  EXPECT_NE(poses[first.stable_pose].label, "P6");
  EXPECT_EQ(poses[second.stable_pose].label, "P5");
  expect_every_instance_valid(scenario, result);
}

TEST(PlanSeedExperiments, BlockOnItsBackIsNotMoved) {
  for (const char* name : {"peg_block_on_back", "peg_block_face_up"}) {
    const Scenario scenario = example(name);
    const PlanResult result = plan(scenario, builtin_domain(), phase1_only());
    ASSERT_TRUE(result.planned()) << name << ": " << result.family.reason;
    for (const std::string& step : actions(scenario, result.chosen()))
      EXPECT_EQ(step.find("block"), std::string::npos) << name << ": " << step;
    expect_every_instance_valid(scenario, result);
  }
}

TEST(PlanSeedExperiments, BlockOnItsSideIsTurnedOnce) {
  const Scenario scenario = example("peg_block_on_sides");
  const PlanResult result = plan(scenario, builtin_domain(), phase1_only());
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const std::vector<std::string> steps = actions(scenario, result.chosen());
  EXPECT_EQ(std::count(steps.begin(), steps.end(), "putdown block"), 1);
  EXPECT_EQ(steps.back(), "assemble peg");
  expect_every_instance_valid(scenario, result);
}

TEST(PlanFamily, OrderingIsAcyclicAndNetworkConsistent) {
  const Scenario scenario = example("peg_block_face_down");
  const PlanResult result = plan(scenario, builtin_domain(), phase1_only());
  ASSERT_TRUE(result.planned());
  result.family.ordering.check_invariants();
  result.family.network.check_invariants();
  EXPECT_EQ(result.family.network.consistent(), cms::Consistency::kConsistent);
  for (std::size_t a = 0; a < result.family.steps.size(); ++a)
    EXPECT_FALSE(result.family.ordering.precedes(static_cast<int>(a), static_cast<int>(a)));
}

TEST(PlanFamily, NodeLimitIsReportedNotHidden) {
  PlanOptions options = phase1_only();
  options.posting.max_nodes = 3;
  const PlanResult result = plan(example("peg_block_face_down"), builtin_domain(), options);
  EXPECT_EQ(result.family.status, PostingStatus::kNodeLimit);
  EXPECT_NE(result.family.reason.find("max_nodes"), std::string::npos);
}

TEST(PlanFamily, StepLimitGivesNoPlan) {
  PlanOptions options = phase1_only();
  options.posting.max_steps = 3;  // the face-down task needs 6 actions
  const PlanResult result = plan(example("peg_block_face_down"), builtin_domain(), options);
  EXPECT_EQ(result.family.status, PostingStatus::kNoPlan);
}

TEST(PlanFamily, ProgressNamesEachStageInOrder) {
  PlanOptions options = testing::quick_options(2);
  std::vector<std::string> stages;
  options.progress = [&](std::string_view stage) { stages.emplace_back(stage); };
  const PlanResult result = plan(example("peg_block_face_down"), builtin_domain(), options);
  ASSERT_TRUE(result.planned());
  std::vector<std::string> expected = {"world model: grasps and reachability",
                                       "phase 1: constraint posting", "phase 1: plan instances",
                                       "phase 2: plan instance 1 of 2"};
  // The chosen instance's extras, task by task: the tolerance allocation, the probability's
  // Monte Carlo, then the margins: with reverse analysis and Monte Carlo off, one tight bound per
  // distinct expression of a step (planner/uncertainty/margins.hpp).
  expected.emplace_back("phase 2: margins, probability, tolerance allocation");
  std::size_t tasks = 2;
  ASSERT_NE(result.chosen_analysis(), nullptr);
  for (const AnalysedStep& step : result.chosen_analysis()->steps) {
    std::set<std::uint32_t> expressions;
    for (const PreconditionResult& precondition : step.preconditions)
      expressions.insert(precondition.inequality.expression.id());
    tasks += expressions.size();
  }
  ASSERT_GT(tasks, 2u);
  for (std::size_t k = 1; k <= tasks; ++k)
    expected.push_back("phase 2: extras: " + std::to_string(k) + " of " + std::to_string(tasks) +
                       " done");
  EXPECT_EQ(stages, expected);
}

// Every instance of every plan found from random initial stable poses, places and yaws passes the
// independent checker.
RC_GTEST_PROP(PlanProperty, RandomInitialPosesGiveValidPlans, ()) {
  static const Scenario base = example("peg_block_face_down");
  static const auto grasps = grasps_of(base);
  Scenario scenario = base;
  testing::place_objects_at_random(scenario);
  PlanOptions options = phase1_only();
  options.max_instances = 4;
  options.posting.max_nodes = 20'000;
  const PlanResult result = testing::plan_placed(scenario, builtin_domain(), options);
  RC_CLASSIFY(result.planned(), "planned");
  if (!result.planned()) return;
  const testing::IndependentCollisionChecker collisions(scenario, grasps);
  for (const PlanInstance& instance : result.instances.instances) {
    const std::vector<std::string> problems = check_instance(scenario, grasps, instance);
    RC_ASSERT(problems.empty());
    RC_ASSERT(collisions.check(instance).empty());
  }
}

}  // namespace
}  // namespace spar::planner

namespace spar::planner {
namespace {

TEST(PlanFamily, NoPlanNamesTheObjectOutOfReach) {
  Scenario scenario = example("peg_block_face_down");
  ObjectSpec& peg =
      scenario.objects[static_cast<std::size_t>(&scenario.object("peg") - scenario.objects.data())];
  peg.initial_pose.translation().x() += 3.0;  // 3 m further out: beyond the Puma's reach
  const PlanResult result = plan(scenario, builtin_domain(), phase1_only());
  EXPECT_EQ(result.family.status, PostingStatus::kNoPlan);
  EXPECT_NE(result.family.reason.find("peg: no grasp reaches it at its initial pose"),
            std::string::npos)
      << result.family.reason;
}

}  // namespace
}  // namespace spar::planner
