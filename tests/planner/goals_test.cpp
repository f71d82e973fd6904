// Issue 21's scenario keys and goal semantics without collision geometry: fixed objects, places
// with several yaws, at(object, place) goals, goals already true, contradictory goals (one error
// each, before any search), places that hold one object at a time, and no-plan reasons that name
// the goal, the object and the empty constraint.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "tests/planner/checked_plan.hpp"

namespace spar::planner {
namespace {

using testing::actions;
using testing::plan_checked;
using testing::replaced;
using testing::scenario_of;

// The seed's face-up experiment as text, so tests can change one line (inches, degrees).
const std::string kBase = R"(units: {length: in, angle: deg}
robot:
  model: puma560
  tool: {xyz: [0, 0, 8]}
  gripper: {max_opening: 4, finger_length: 3}
  max_tilt: 60
grasping: {approach_step: 45}
objects:
  block:
    builtin: block
    features: {hole: [2, 6, 10, 12, 16]}
    pose: {stable: P5, at: [20, 0]}
  peg:
    builtin: peg
    features: {shaft: [11, 12, 13, 14, 15, 16, 17, 18, 19]}
    pose: {stable: P10, at: [14, 12]}
places:
  - {name: left, at: [14, -12]}
  - {name: right, at: [22, -12]}
goals:
  - assembled:
      held: peg
      fixed: block
      held_faces: shaft
      fixed_faces: hole
      relative: {xyz: [0, 0, 6], rpy: [180, 0, 0]}
)";

std::string error_of(const std::string& yaml) {
  try {
    (void)scenario_of(yaml);
  } catch (const ScenarioError& error) {
    return error.what();
  }
  return "";
}

// --- scenario keys ---

TEST(ScenarioKeys, FixedYawListsAtGoalsMarginAndApproachDistanceLoad) {
  std::string yaml = replaced(kBase, "    pose: {stable: P5, at: [20, 0]}",
                              "    pose: {stable: P5, at: [20, 0]}\n    fixed: true");
  yaml = replaced(yaml, "{name: left, at: [14, -12]}", "{name: left, at: [14, -12], yaw: [0, 90]}");
  yaml = replaced(yaml, "grasping:", "collision: {margin: 0.05}\ngrasping:");
  yaml = replaced(yaml, "  gripper: {max_opening: 4, finger_length: 3}",
                  "  gripper: {max_opening: 4, finger_length: 3}\n  approach_distance: 2");
  const Scenario scenario = scenario_of(yaml);
  EXPECT_TRUE(scenario.object("block").fixed);
  EXPECT_FALSE(scenario.object("peg").fixed);
  ASSERT_EQ(scenario.places[0].yaws.size(), 2u);
  EXPECT_NEAR(scenario.places[0].yaws[1], M_PI / 2, 1e-12);
  EXPECT_NEAR(scenario.collision.margin, 0.05 * 0.0254, 1e-15);
  EXPECT_NEAR(scenario.robot.approach_distance, 2 * 0.0254, 1e-15);
  const Scenario with_at =
      scenario_of(replaced(kBase, "goals:\n", "goals:\n  - at: {object: block, place: right}\n"));
  ASSERT_EQ(with_at.goals.size(), 2u);
  const AtGoal& at = std::get<AtGoal>(with_at.goals[0]);
  EXPECT_EQ(at.object, "block");
  EXPECT_EQ(at.place, "right");
  EXPECT_EQ(describe(with_at.goals[0]), "at(block, right)");
  EXPECT_EQ(describe(with_at.goals[1]), "assembled(peg, block)");
}

TEST(ScenarioKeys, DefaultsAreOneMillimetreAndATenthOfAMetre) {
  const Scenario scenario = scenario_of(kBase);
  EXPECT_EQ(scenario.collision.margin, 0.001);
  EXPECT_EQ(scenario.robot.approach_distance, 0.1);
  EXPECT_EQ(scenario.places[0].yaws, std::vector<double>{0.0});
}

TEST(ScenarioKeyErrors, FixedMustBeTrueOrFalse) {
  EXPECT_EQ(error_of(replaced(kBase, "    pose: {stable: P5, at: [20, 0]}",
                              "    pose: {stable: P5, at: [20, 0]}\n    fixed: yes please")),
            "test.yaml:13:12: objects.block.fixed: expected true or false, got 'yes please'");
}

TEST(ScenarioKeyErrors, YawListsMustBeNonEmptyWithoutRepeats) {
  EXPECT_EQ(error_of(replaced(kBase, "{name: left, at: [14, -12]}",
                              "{name: left, at: [14, -12], yaw: []}")),
            "test.yaml:18:38: places[0].yaw: the list of yaws is empty");
  EXPECT_EQ(error_of(replaced(kBase, "{name: left, at: [14, -12]}",
                              "{name: left, at: [14, -12], yaw: [0, 90, 90]}")),
            "test.yaml:18:46: places[0].yaw[2]: yaw 90 is listed twice");
}

TEST(ScenarioKeyErrors, AtGoalNamesAnUnknownPlaceWithASuggestion) {
  EXPECT_EQ(
      error_of(replaced(kBase, "goals:\n", "goals:\n  - at: {object: block, place: rihgt}\n")),
      "test.yaml:21:32: goals[0].at.place: unknown place 'rihgt' (did you mean 'right'?); "
      "places: left, right");
}

// --- contradictory goals: one error per class, naming both goals ---

const std::string kSecondGoal =
    "  - assembled: {held: peg, fixed: block, relative: {xyz: [0, 0, 7]}}\n";

TEST(ContradictoryGoals, SamePairWithAnotherRelativePose) {
  EXPECT_EQ(error_of(kBase + kSecondGoal),
            "test.yaml:27:5: goals[1]: assembled(peg, block) contradicts assembled(peg, block) of "
            "goals[0] (test.yaml:22:7): the same pair with another relative pose");
}

TEST(ContradictoryGoals, OneObjectHeldInTwoAssemblies) {
  const std::string yaml =
      replaced(kBase, "places:",
               "  cube:\n    builtin: cube\n    pose: {stable: P1, at: [18, 8]}\nplaces:") +
      "  - assembled: {held: peg, fixed: cube, relative: {xyz: [0, 0, 1]}}\n";
  EXPECT_NE(error_of(yaml).find("goals[1]: assembled(peg, cube) contradicts assembled(peg, block) "
                                "of goals[0] (test.yaml:25:7): peg cannot go into two objects"),
            std::string::npos)
      << error_of(yaml);
}

TEST(ContradictoryGoals, AssembliesInACycle) {
  const std::string yaml =
      kBase + "  - assembled: {held: block, fixed: peg, relative: {xyz: [0, 0, 9]}}\n";
  EXPECT_NE(error_of(yaml).find("each would be inside the other"), std::string::npos)
      << error_of(yaml);
  const std::string three =
      replaced(kBase, "places:",
               "  cube:\n    builtin: cube\n    pose: {stable: P1, at: [18, 8]}\nplaces:") +
      "  - assembled: {held: block, fixed: cube, relative: {xyz: [0, 0, 1]}}\n"
      "  - assembled: {held: cube, fixed: peg, relative: {xyz: [0, 0, 9]}}\n";
  EXPECT_NE(error_of(three).find("the assemblies form a cycle through cube"), std::string::npos)
      << error_of(three);
}

TEST(ContradictoryGoals, ObjectAtTwoPlacesOrTwoObjectsAtOnePlace) {
  EXPECT_NE(
      error_of(kBase +
               "  - at: {object: block, place: left}\n  - at: {object: block, place: right}\n")
          .find("goals[2]: at(block, right) contradicts at(block, left) of goals[1] "
                "(test.yaml:27:9): block cannot rest at two places"),
      std::string::npos);
  const std::string with_cube = replaced(
      kBase, "places:", "  cube:\n    builtin: cube\n    pose: {stable: P1, at: [18, 8]}\nplaces:");
  EXPECT_NE(error_of(with_cube +
                     "  - at: {object: block, place: left}\n  - at: {object: cube, place: left}\n")
                .find("goals[2]: at(cube, left) contradicts at(block, left) of goals[1] "
                      "(test.yaml:30:9): place left holds one object at a time"),
            std::string::npos)
      << error_of(with_cube +
                  "  - at: {object: block, place: left}\n  - at: {object: cube, place: left}\n");
}

TEST(ContradictoryGoals, HeldObjectCannotAlsoRestAtAPlace) {
  EXPECT_NE(error_of(kBase + "  - at: {object: peg, place: left}\n")
                .find("goals[1]: at(peg, left) contradicts assembled(peg, block) of goals[0] "
                      "(test.yaml:22:7): peg would rest inside block, not at a place"),
            std::string::npos)
      << error_of(kBase + "  - at: {object: peg, place: left}\n");
}

TEST(ContradictoryGoals, FixedObjectsDoNotMove) {
  const std::string fixed_peg = replaced(kBase, "    pose: {stable: P10, at: [14, 12]}",
                                         "    pose: {stable: P10, at: [14, 12]}\n    fixed: true");
  EXPECT_EQ(error_of(fixed_peg),
            "test.yaml:22:5: goals[0]: assembled(peg, block): object 'peg' is fixed (never moves) "
            "and cannot be the held object");
  const std::string fixed_block = replaced(kBase, "    pose: {stable: P5, at: [20, 0]}",
                                           "    pose: {stable: P5, at: [20, 0]}\n    fixed: true");
  EXPECT_NE(error_of(fixed_block + "  - at: {object: block, place: left}\n")
                .find("object 'block' is fixed (never moves) and does not rest at place 'left'"),
            std::string::npos);
}

// --- planning ---

TEST(GoalSemantics, FixedObjectIsNeverMovedAndNeedsNoGrasp) {
  const Scenario scenario =
      scenario_of(replaced(kBase, "    pose: {stable: P5, at: [20, 0]}",
                           "    pose: {stable: P5, at: [20, 0]}\n    fixed: true"));
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  EXPECT_TRUE(result.world.object(0).grasps.empty());
  ASSERT_EQ(result.world.object(0).positions.size(), 1u);  // only "initial"
  const std::vector<std::string> expected = {"pickup peg", "assemble peg"};
  EXPECT_EQ(actions(scenario, result.chosen()), expected);
}

TEST(GoalSemantics, FixedBlockInAPoseWithoutMatingPoseIsNoPlanNamingIt) {
  const Scenario scenario =
      scenario_of(replaced(kBase, "    pose: {stable: P5, at: [20, 0]}",
                           "    pose: {stable: P6, at: [20, 0]}\n    fixed: true"));
  const PlanResult result = plan_checked(scenario);
  ASSERT_FALSE(result.planned());
  EXPECT_NE(result.family.reason.find(
                "goal assembled(peg, block) (test.yaml:23:7): block: no position leaves its "
                "mating faces off the table with the mating vector pointing down "
                "(in_position_class(position, mating_poses) is empty; it is fixed: its only "
                "position is where it is)"),
            std::string::npos)
      << result.family.reason;
}

TEST(GoalSemantics, AtGoalPutsTheObjectAtThePlace) {
  const Scenario scenario =
      scenario_of(replaced(kBase, "goals:\n", "goals:\n  - at: {object: block, place: right}\n"));
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const PlanInstance& chosen = result.chosen();
  const std::vector<std::string> steps = actions(scenario, chosen);
  ASSERT_GE(std::count(steps.begin(), steps.end(), "putdown block"), 1);
  // The block's last putdown is at `right` (with the peg in it, if it went in first).
  const InstanceStep* last = nullptr;
  for (const InstanceStep& step : chosen.steps)
    if (step.action_name == "putdown" && scenario.objects[step.object].name == "block")
      last = &step;
  EXPECT_EQ(result.world.object(0).positions[last->position].place, 1);
}

TEST(GoalSemantics, GoalsAlreadyTrueNeedNoSteps) {
  // The block starts at `right` (P5, yaw 0); the peg starts inside it.
  std::string yaml = replaced(kBase, "    pose: {stable: P5, at: [20, 0]}",
                              "    pose: {stable: P5, at: [22, -12]}");
  yaml = replaced(yaml, "    pose: {stable: P10, at: [14, 12]}",
                  "    pose: {xyz: [22, -12, 6], rpy: [180, 0, 0]}");
  yaml = replaced(yaml, "goals:\n", "goals:\n  - at: {object: block, place: right}\n");
  // The block's P5 puts its centre of mass above `at`; its frame origin is below the centre.
  Scenario scenario = scenario_of(yaml);
  const ObjectSpec& block = scenario.object("block");
  ObjectSpec& peg = scenario.objects[1];
  const AssembledGoal& goal = std::get<AssembledGoal>(scenario.goals[1]);
  peg.initial_pose = block.initial_pose * goal.relative;
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  EXPECT_TRUE(result.chosen().steps.empty());
  int already = 0;
  for (const SatisfiedGoal& satisfied : result.family.satisfied)
    already += satisfied.how == "already satisfied";
  EXPECT_EQ(already, 2);
}

TEST(GoalSemantics, PlaceWithSeveralYawsOffersEachAsAPosition) {
  const Scenario scenario = scenario_of(
      replaced(kBase, "{name: left, at: [14, -12]}", "{name: left, at: [14, -12], yaw: [0, 180]}"));
  const WorldModel world(scenario);
  const std::vector<PositionLabel>& positions = world.object(0).positions;
  const auto named = [&](const std::string& name) {
    return std::any_of(positions.begin(), positions.end(),
                       [&](const PositionLabel& label) { return label.name == name; });
  };
  EXPECT_TRUE(named("P1@left/0"));
  EXPECT_TRUE(named("P1@left/180"));
  EXPECT_TRUE(named("P1@right"));
}

TEST(GoalSemantics, TwoObjectsNeverShareAPlaceEvenOneAfterTheOther) {
  // The block lies face down (P6) and must be turned at a place; the cube must go to `left`, the
  // only place: the block may not use it too, so there is no plan.
  std::string yaml =
      replaced(kBase, "    pose: {stable: P5, at: [20, 0]}", "    pose: {stable: P6, at: [20, 0]}");
  yaml = replaced(
      yaml, "places:", "  cube:\n    builtin: cube\n    pose: {stable: P1, at: [18, 8]}\nplaces:");
  yaml = replaced(yaml, "  - {name: right, at: [22, -12]}\n", "");
  yaml = replaced(yaml, "goals:\n", "goals:\n  - at: {object: cube, place: left}\n");
  const PlanResult result = plan_checked(scenario_of(yaml));
  EXPECT_FALSE(result.planned());
  // With a second place both plan.
  const PlanResult two = plan_checked(
      scenario_of(replaced(yaml, "  - {name: left, at: [14, -12]}\n",
                           "  - {name: left, at: [14, -12]}\n  - {name: right, at: [22, -12]}\n")));
  EXPECT_TRUE(two.planned()) << two.family.reason;
}

TEST(GoalSemantics, NoPlanReasonBlamesTheObjectOutOfReach) {
  // The block (in a mating pose) is 3 m further out; the peg is within reach.
  Scenario scenario = scenario_of(kBase);
  scenario.objects[0].initial_pose.translation().x() += 3.0;
  const PlanResult result = plan_checked(scenario);
  ASSERT_FALSE(result.planned());
  EXPECT_NE(result.family.reason.find("goal assembled(peg, block) (test.yaml:22:7): block: "),
            std::string::npos)
      << result.family.reason;
  EXPECT_EQ(result.family.reason.find("peg: "), std::string::npos) << result.family.reason;
}

}  // namespace
}  // namespace spar::planner
