// Collision-free planning (issue 21): occupied places are avoided or cleared, the initial world is
// checked on load, every plan's instances pass the independent collision checker
// (collision_checker.hpp), which itself finds collisions planted in a plan, and random scenes of
// 2-6 objects on a table give plans without overlap in any state or along any approach.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
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

// Two 1-inch cubes and two places; lengths in inches.
const std::string kCubes = R"(units: {length: in, angle: deg}
robot:
  tool: {xyz: [0, 0, 8]}
  gripper: {max_opening: 4, finger_length: 3}
  max_tilt: 60
grasping: {approach_step: 90}
objects:
  a:
    builtin: cube
    pose: {stable: P1, at: [16, -12]}
  b:
    builtin: cube
    pose: {stable: P1, at: [20, 4]}
places:
  - {name: left, at: [16, -12]}
  - {name: right, at: [22, -12]}
goals:
  - at: {object: b, place: left}
)";

std::vector<std::vector<geometry::Grasp>> grasps_of(const PlanResult& result) {
  std::vector<std::vector<geometry::Grasp>> grasps;
  for (std::size_t o = 0; o < result.world.object_count(); ++o)
    grasps.push_back(result.world.object(static_cast<int>(o)).grasps);
  return grasps;
}

std::string error_of(const std::string& yaml) {
  try {
    (void)WorldModel(scenario_of(yaml));
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

TEST(CollisionPlanning, OccupiedGoalPlaceIsClearedFirst) {
  const Scenario scenario = scenario_of(kCubes);
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const std::vector<std::string> expected = {"pickup a", "putdown a", "pickup b", "putdown b"};
  EXPECT_EQ(actions(scenario, result.chosen()), expected);
  // a went to `right`, the only other place.
  EXPECT_EQ(result.world.object(0).positions[result.chosen().steps[1].position].place, 1);
}

TEST(CollisionPlanning, GraspAvoidsANeighbour) {
  // b stands 0.1 in from a's +y face: fingers closing on a along world y would hit b, so a is
  // grasped across its other pair of side faces (or from above).
  std::string yaml =
      replaced(kCubes, "  - at: {object: b, place: left}\n", "  - at: {object: a, place: right}\n");
  yaml = replaced(yaml, "    pose: {stable: P1, at: [20, 4]}",
                  "    pose: {stable: P1, at: [16, -10.9]}");
  const Scenario scenario = scenario_of(yaml);
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const InstanceStep& pickup = result.chosen().steps[0];
  ASSERT_EQ(pickup.object, 0);
  const Eigen::Vector3d closing = pickup.gripper_pose.linear().col(1);
  EXPECT_LT(std::abs(closing.y()), 1e-6)
      << "grasp " << result.world.object(0).grasps[pickup.grasp].label << " closes toward b";
}

TEST(CollisionPlanning, ClearanceAndNearestObjectAreReported) {
  const Scenario scenario = scenario_of(kCubes);
  PlanOptions options;
  options.uncertainty = false;
  const PlanResult result = plan(scenario, builtin_domain(), options);
  ASSERT_TRUE(result.planned());
  for (const InstanceStep& step : result.chosen().steps) {
    EXPECT_TRUE(step.collision.clear);
    EXPECT_GE(step.collision.clearance, scenario.collision.margin);
    EXPECT_GE(step.collision.nearest, 0);
    EXPECT_NE(step.collision.nearest, step.object);
  }
}

TEST(InitialWorld, ObjectsThatMeetAreAnErrorAtTheirPoses) {
  EXPECT_EQ(error_of(replaced(kCubes, "at: [20, 4]", "at: [16.5, -12]")),
            "objects.a.pose (test.yaml:10:11) and objects.b.pose (test.yaml:13:11): a and b "
            "interpenetrate or touch in the initial world");
}

TEST(InitialWorld, ObjectBelowTheTableOrFloatingIsAnError) {
  EXPECT_EQ(
      error_of(replaced(kCubes, "pose: {stable: P1, at: [20, 4]}", "pose: {xyz: [20, 4, -0.5]}")),
      "objects.b.pose (test.yaml:13:11): b reaches 0.5 in below the table (the plane z = 0)");
  EXPECT_EQ(
      error_of(replaced(kCubes, "pose: {stable: P1, at: [20, 4]}", "pose: {xyz: [20, 4, 2]}")),
      "objects.b.pose (test.yaml:13:11): b floats 2 in above the table: an object rests on "
      "the table or sits assembled in another (an assembled goal that holds at the start)");
}

TEST(IndependentChecker, FindsACollisionPlantedInAPlan) {
  // The plan puts b at `left` once a has left; the same instance with a's putdown undone (a
  // stays where it was) puts b into a.
  const Scenario scenario = scenario_of(kCubes);
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned());
  PlanInstance planted = result.chosen();
  ASSERT_EQ(planted.steps.size(), 4u);
  planted.steps[1].object_pose = scenario.objects[0].initial_pose;  // a put back where it was
  planted.steps[1].gripper_pose = planted.steps[0].gripper_pose;
  const testing::IndependentCollisionChecker checker(scenario, grasps_of(result));
  const std::vector<std::string> hits = checker.check(planted);
  ASSERT_FALSE(hits.empty());
  EXPECT_NE(hits.front().find("meets a"), std::string::npos) << hits.front();
  // And the planner's own check refuses it too.
  EXPECT_TRUE(check_collisions(planted, result.world, result.domain).has_value());
}

// --- the examples of issue 21 ---

Scenario example(const std::string& name) {
  return load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/" + name + ".yaml");
}

TEST(Examples, FixtureBaseIsTurnedRoundToClearTheWall) {
  const Scenario scenario = example("fixture_two_pins");
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const int base = result.world.object_index("base");
  bool turned = false;
  for (const InstanceStep& step : result.chosen().steps)
    if (step.action_name == "putdown" && step.object == base)
      turned = result.world.object(base).positions[step.position].name == "P3@station/180";
  EXPECT_TRUE(turned);
  // Offered yaw 0 only, the part cannot go in beside the wall, and the base cannot move with
  // the part on it: no plan, and the reason says what refused it.
  Scenario one_yaw = scenario;
  one_yaw.places[0].yaws = {0.0};
  const PlanResult refused = plan_checked(one_yaw);
  EXPECT_FALSE(refused.planned());
  EXPECT_NE(refused.family.reason.find("no grasp of base clears part assembled into it"),
            std::string::npos)
      << refused.family.reason;
}

TEST(Examples, StackedBlockCarriesTheCubeIntoTheTray) {
  const Scenario scenario = example("stack_in_tray");
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const std::vector<std::string> expected = {"pickup cube", "assemble cube", "pickup block",
                                             "assemble block"};
  EXPECT_EQ(actions(scenario, result.chosen()), expected);
  const int cube = result.world.object_index("cube");
  EXPECT_EQ(result.chosen().steps[2].carried, std::vector<int>{cube});
  EXPECT_EQ(result.chosen().steps[3].carried, std::vector<int>{cube});
}

TEST(Examples, CrowdedTableClearsTheOccupiedPlaceFirst) {
  const Scenario scenario = example("crowded_table");
  const PlanResult result = plan_checked(scenario, 2);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const std::vector<std::string> steps = actions(scenario, result.chosen());
  const auto at = [&](const std::string& step) {
    return std::find(steps.begin(), steps.end(), step) - steps.begin();
  };
  EXPECT_LT(at("pickup red"), at("putdown green"));
  EXPECT_EQ(steps.back(), "putdown green");
}

// The conflict tables posting reads (initial_conflicts skips a grasp whose sweeps' boxes lie a
// margin beyond the other object) agree with the exact check of that grasp with only the two
// objects on the table, for every pair of the crowded table's objects.
TEST(Examples, CrowdedTableConflictTablesMatchTheExactCheck) {
  const WorldModel world(example("crowded_table"));
  const WorldState start = world.initial_state();
  const int count = static_cast<int>(world.object_count());
  int conflicts = 0, checked = 0;
  for (int object = 0; object < count; ++object) {
    const ObjectWorld& labels = world.object(object);
    for (int other = 0; other < count; ++other) {
      if (other == object) continue;
      // Everything but the two far above the cell: out of every motion's reach.
      WorldState pair = start;
      for (int o = 0; o < count; ++o)
        if (o != object && o != other)
          pair.poses[static_cast<std::size_t>(o)].translation().z() += 100;
      const WorldModel::Table& table = world.initial_conflicts(object, other);
      for (std::size_t g = 0; g < labels.grasps.size(); ++g)
        for (std::size_t p = 0; p < labels.positions.size(); ++p) {
          if (labels.reachable[g][p] == 0) continue;
          const bool blocked = !world
                                    .check_grasp(pair, object, static_cast<int>(g),
                                                 labels.positions[p].pose, /*measure=*/false)
                                    .clear;
          ASSERT_EQ(table[g][p] != 0, blocked) << labels.positions[p].name << " grasp " << g
                                               << " of object " << object << " against " << other;
          conflicts += blocked ? 1 : 0;
          ++checked;
        }
    }
  }
  EXPECT_GT(conflicts, 0);  // the table is crowded: some grasps do meet a neighbour
  EXPECT_GT(checked, 10 * conflicts);
}

// A crowded task with no plan is proved to have none: no constraint post runs out of the
// network's search budget (forward checking alone spent 105 posts' budgets on it and could only
// say "not a proof").
TEST(CollisionPlanning, CrowdedTaskWithoutPlanIsProvedSo) {
  PlanOptions options;
  options.uncertainty = false;
  const PlanResult result = plan(load_scenario(std::string(SPAR_SOURCE_DIR) +
                                               "/tests/planner/data/crowded_pairs_no_plan.yaml"),
                                 builtin_domain(), options);
  EXPECT_EQ(result.family.status, PostingStatus::kNoPlan);
  EXPECT_EQ(result.family.reason.find("search budget"), std::string::npos) << result.family.reason;
}

// --- subassemblies rest on the table as one body ---

std::string data_file(const std::string& name) {
  return std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/" + name;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Scenario subassembly_moved() { return load_scenario(data_file("subassembly_moved.yaml")); }

// The names of `object`'s positions where `table` is set.
std::vector<std::string> positions_where(const WorldModel& world, int object,
                                         const std::vector<char>& table) {
  std::vector<std::string> names;
  for (std::size_t p = 0; p < table.size(); ++p)
    if (table[p]) names.push_back(world.object(object).positions[p].name);
  return names;
}

TEST(Subassemblies, ThePairGoesOnlyWhereItRestsByItself) {
  const PlanResult result = plan_checked(subassembly_moved());
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const int bar = result.world.object_index("bar");
  const GoalWorld* goal = result.world.goal(result.world.object_index("post"), bar);
  ASSERT_NE(goal, nullptr);
  // The bar's six stable poses at the spare place: P5 (flat, post up) and P2 (on the post's end)
  // hold the pair; on its sides (P3, P4) and its other end (P1) the pair's centre of mass lies
  // outside the footing; upside down (P6) the post goes below the table. The pair also rests
  // where the bar alone does not: tilted on the post's top and an edge of the bar (J1-J3).
  const std::vector<std::string> rests = {"initial",       "P2@spare",      "P5@spare",
                                          "J1+post@spare", "J2+post@spare", "J3+post@spare"};
  EXPECT_EQ(positions_where(result.world, bar, goal->rests_assembled), rests);
  int putdowns = 0;
  for (const PlanInstance& instance : result.instances.instances)
    for (const InstanceStep& step : instance.steps)
      if (step.action_name == "putdown" && step.object == bar) {
        ++putdowns;
        const std::string& where = result.world.object(bar).positions[step.position].name;
        EXPECT_NE(std::find(rests.begin(), rests.end(), where), rests.end()) << where;
      }
  EXPECT_GT(putdowns, 0);
}

// The chosen instance with the bar put down (with every grasp, the pickup's changed to match)
// at each position where the pair does not rest; the ones the collision check lets through come
// back, with what check_collisions says of them.
std::vector<std::pair<PlanInstance, std::string>> toppling_variants(const PlanResult& result) {
  const WorldModel& world = result.world;
  const int bar = world.object_index("bar");
  const GoalWorld* goal = world.goal(world.object_index("post"), bar);
  const ObjectWorld& labels = world.object(bar);
  std::vector<std::pair<PlanInstance, std::string>> variants;
  for (std::size_t p = 1; p < labels.positions.size(); ++p) {
    if (goal->rests_assembled[p]) continue;
    for (std::size_t g = 0; g < labels.grasps.size(); ++g) {
      PlanInstance planted = result.chosen();
      for (InstanceStep& step : planted.steps) {
        if (step.object != bar) continue;
        step.grasp = static_cast<int>(g);
        if (step.action_name == "putdown") {
          step.position = static_cast<int>(p);
          step.stable_pose = labels.positions[p].stable_pose;
          step.object_pose = labels.positions[p].pose;
        }
        step.gripper_pose = step.object_pose * labels.grasps[g].gripper_in_object;
      }
      std::optional<std::string> refusal = check_collisions(planted, world, result.domain);
      if (refusal && refusal->find("assembled into it does not") != std::string::npos)
        variants.emplace_back(std::move(planted), std::move(*refusal));
    }
  }
  return variants;
}

// subassembly_moved.yaml with the post held out 20 in beyond the bar's middle (beside it, not on
// it: a rigid pair whatever joins them), and `extra_objects` (YAML) added: the pair's centre of
// mass lies beyond every footing of the bar's own stable poses (the bar's initial pose counts as
// sensed, so the pair may start there), but the pair rests tilted on an edge of the bar and an
// edge of the post (geometry::joint_stable_poses): the joined positions "J<k>+post@spare".
Scenario post_held_out(const std::string& extra_objects = "") {
  std::string text = read_text(data_file("subassembly_moved.yaml"));
  text.insert(text.find("\nplaces:"), extra_objects);
  Scenario scenario = parse_scenario(text, "subassembly_moved.yaml", data_file(""));
  EXPECT_EQ(scenario.objects[0].name, "bar");
  auto& joined = std::get<AssembledGoal>(scenario.goals[1]);
  joined.relative = Eigen::Translation3d(20 * 0.0254, 0, 0.0254) * Eigen::Isometry3d::Identity();
  scenario.objects[0].initial_stable_pose.reset();
  scenario.objects[1].initial_pose = scenario.objects[0].initial_pose * joined.relative;
  return scenario;
}

TEST(Subassemblies, ThePairRestsWhereTheBarAloneDoesNot) {
  const PlanResult result = plan_checked(post_held_out());  // the independent checker agrees
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const int bar = result.world.object_index("bar");
  const GoalWorld* goal = result.world.goal(result.world.object_index("post"), bar);
  const std::vector<PositionLabel>& positions = result.world.object(bar).positions;
  int joined = 0;
  for (std::size_t p = 1; p < positions.size(); ++p) {
    EXPECT_EQ(goal->rests_assembled[p] != 0, positions[p].joined_goal == 1) << positions[p].name;
    if (positions[p].joined_goal < 0) continue;
    ++joined;
    EXPECT_TRUE(positions[p].name.starts_with("J" + std::to_string(joined) + "+post@spare"))
        << positions[p].name;
    EXPECT_EQ(positions[p].stable_pose, -1);
    EXPECT_FALSE(goal->mating_pose[p]);  // the bar alone does not stand there
  }
  ASSERT_GT(joined, 0);
  // The bar alone at a joined position does not rest: a plan instance putting it there before the
  // join is refused (WorldModel::check_rest).
  WorldState alone = result.world.initial_state();
  alone.carrier[result.world.object_index("post")] = -1;
  ASSERT_EQ(positions.back().joined_goal, 1);
  alone.move(bar, positions.back().pose);
  const std::optional<std::string> why = result.world.check_rest(alone, bar);
  ASSERT_TRUE(why.has_value());
  EXPECT_TRUE(why->starts_with("bar does not ")) << *why;
  int putdowns = 0;
  for (const InstanceStep& step : result.chosen().steps)
    if (step.action_name == "putdown" && step.object == bar) {
      ++putdowns;
      EXPECT_EQ(positions[step.position].joined_goal, 1) << positions[step.position].name;
    }
  EXPECT_EQ(putdowns, 1);
}

TEST(Subassemblies, NoRestingPositionLeftIsTheReason) {
  // As above, with a fixed pillar where the bar would lie in the joined positions the robot
  // reaches (the pair's centre of mass is above the place, so the bar lies 5.5 in towards -x):
  // the bar alone could go to the spare place, the pair cannot.
  const PlanResult result =
      plan_checked(post_held_out("  pillar:\n    mesh: pillar.off\n    fixed: true\n"
                                 "    pose: {xyz: [7.5, -11, 0]}\n"));
  EXPECT_FALSE(result.planned());
  EXPECT_NE(result.family.reason.find(
                "no position left for bar where it rests on the table with post assembled into it"),
            std::string::npos)
      << result.family.reason;
}

TEST(Subassemblies, BeforeTheJoinTheBaseGoesOnlyWhereItRestsAlone) {
  // Seed figure 13 (the block face down: it is turned over before the peg goes in), with the peg
  // moved 3 in along the block's x, beside it (the pair still stands upright, 0.47 in inside the
  // footing, and also rests tilted where the block alone does not: three joined positions per
  // place), and the block must end at the back place: no step before the insertion may put the
  // block alone at a joined position (J<k>+peg). (The planner inserts the peg at the back place.)
  std::string text = read_text(std::string(SPAR_SOURCE_DIR) + "/examples/peg_block_face_down.yaml");
  text += "  - at: {object: block, place: back}\n";
  Scenario scenario =
      parse_scenario(text, "peg_block_face_down.yaml", std::string(SPAR_SOURCE_DIR) + "/examples");
  auto& joined = std::get<AssembledGoal>(scenario.goals[0]);
  joined.relative = Eigen::Translation3d(3 * 0.0254, 0, 0) * joined.relative;
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const int block = result.world.object_index("block");
  const std::vector<PositionLabel>& positions = result.world.object(block).positions;
  ASSERT_TRUE(std::any_of(positions.begin(), positions.end(),
                          [](const PositionLabel& p) { return p.joined_goal == 0; }));
  const PlanFamily& family = result.family;
  const auto insertion = std::find_if(family.steps.begin(), family.steps.end(), [&](const auto& s) {
    return s.action >= 0 && result.domain.actions[s.action].name == "assemble";
  });
  ASSERT_NE(insertion, family.steps.end());
  int before = 0;
  for (const FamilyStep& step : family.steps) {
    if (step.action < 0 || step.id == insertion->id) continue;
    if (!family.ordering.precedes(step.id, insertion->id)) continue;
    for (const Term& term : step.args) {
      if (term.kind != Term::Kind::kVariable) continue;
      const PlanVariable& variable = family.variables[term.index];
      if (variable.object != block || variable.type == ParameterType::kGrasp ||
          variable.type == ParameterType::kObject)
        continue;
      ++before;
      for (const int label : family.network.labels(term.index))
        EXPECT_LT(positions[label].joined_goal, 0)
            << family.describe(step, result.world, result.domain) << ": " << positions[label].name;
    }
  }
  EXPECT_GT(before, 0);  // the block is turned over first
}

TEST(Subassemblies, AnInstanceLeavingThePairToToppleIsRefused) {
  const PlanResult result = plan_checked(subassembly_moved());
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const WorldModel& world = result.world;
  const int bar = world.object_index("bar");
  const GoalWorld* goal = world.goal(world.object_index("post"), bar);
  // check_rest on its own: every position where the pair does not rest says why.
  int outside = 0, not_flat = 0;
  const std::vector<PositionLabel>& positions = world.object(bar).positions;
  EXPECT_FALSE(world.check_rest(world.initial_state(), bar).has_value());
  for (std::size_t p = 1; p < positions.size(); ++p) {
    WorldState state = world.initial_state();
    state.move(bar, positions[p].pose);
    const std::optional<std::string> why = world.check_rest(state, bar);
    EXPECT_EQ(why.has_value(), !goal->rests_assembled[p]) << positions[p].name;
    if (!why) continue;
    outside += why->starts_with(
                   "bar with post assembled into it does not rest on the table there: its "
                   "centre of mass lies ") &&
               why->ends_with(" in outside its footing");
    not_flat +=
        why->starts_with("bar with post assembled into it does not stand flat on the table there");
  }
  EXPECT_GT(outside, 0);
  EXPECT_GT(not_flat, 0);
  // Through the instance check: some putdown the motions allow leaves the pair to topple, and
  // check_collisions refuses it, naming the step.
  const auto variants = toppling_variants(result);
  ASSERT_FALSE(variants.empty());
  EXPECT_TRUE(variants.front().second.starts_with("putdown(bar, G")) << variants.front().second;
}

TEST(InitialWorld, ASubassemblyThatDoesNotStandIsAnError) {
  // The bar on its side with the post sticking out sideways at the height of the bar's middle:
  // their centre of mass lies 0.4545 in beyond the bar's footing.
  std::string yaml =
      replaced(replaced(read_text(data_file("subassembly_moved.yaml")), "pose: {xyz: [16, 6, 0]}",
                        "pose: {xyz: [16, 6, 1], rpy: [90, 0, 0]}"),
               "pose: {xyz: [19.5, 6, 1]}", "pose: {xyz: [19.5, 5, 1], rpy: [90, 0, 0]}");
  try {
    (void)WorldModel(parse_scenario(yaml, "test.yaml", data_file("")));
    ADD_FAILURE() << "no error";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "objects.bar.pose (test.yaml:23:11): bar with post assembled into it does not rest "
              "on the table there: its centre of mass lies 0.4545 in outside its footing");
  }
}

TEST(IndependentChecker, FindsASubassemblyLeftToTopple) {
  const Scenario scenario = subassembly_moved();
  const PlanResult result = plan_checked(scenario);
  ASSERT_TRUE(result.planned()) << result.family.reason;
  const testing::IndependentCollisionChecker checker(scenario, grasps_of(result));
  EXPECT_TRUE(checker.check(result.chosen()).empty());
  const auto variants = toppling_variants(result);
  ASSERT_FALSE(variants.empty());
  for (const auto& [planted, refusal] : variants) {
    const std::vector<std::string> problems = checker.check(planted);
    ASSERT_FALSE(problems.empty()) << refusal;
    EXPECT_NE(problems.front().find("bar with its parts topples after it"), std::string::npos)
        << problems.front();
  }
}

// --- random scenes ---

// 2-6 objects (cubes, pegs, blocks, L-shapes) at random spots of a grid in front of the robot,
// resting in random stable poses and turned by random yaws; places at other grid spots; goals:
// some objects to places, and the peg into the block when both are there.
Scenario random_scene() {
  static const Scenario base = scenario_of(kCubes);
  static const std::vector<ObjectSpec> shapes = [] {
    std::string yaml = kCubes;
    yaml = replaced(
        yaml, "  b:\n    builtin: cube\n    pose: {stable: P1, at: [20, 4]}\n",
        "  b:\n    builtin: cube\n    pose: {stable: P1, at: [20, 4]}\n"
        "  peg:\n    builtin: peg\n    features: {shaft: [11, 12, 13, 14, 15, 16, 17, 18, 19]}\n"
        "    pose: {stable: P1, at: [14, 12]}\n"
        "  block:\n    builtin: block\n    features: {hole: [2, 6, 10, 12, 16]}\n"
        "    pose: {stable: P5, at: [24, 10]}\n"
        "  l:\n    builtin: l-shape\n    pose: {stable: P1, at: [12, 4]}\n");
    return scenario_of(yaml).objects;
  }();
  Scenario scene = base;
  scene.objects.clear();
  scene.goals.clear();
  scene.places.clear();
  // Grid spots 5 in apart, 12-27 in out, -12..12 across.
  std::vector<std::pair<double, double>> spots;
  for (double x = 12; x <= 27; x += 5)
    for (double y = -12; y <= 12; y += 6) spots.emplace_back(x, y);
  const int count = *rc::gen::inRange(2, 7);
  const auto chosen = *rc::gen::unique<std::vector<int>>(
      static_cast<std::size_t>(count + 3), rc::gen::inRange(0, static_cast<int>(spots.size())));
  for (int i = 0; i < count; ++i) {
    ObjectSpec object = shapes.at(*rc::gen::inRange(0, static_cast<int>(shapes.size())));
    object.name = "o" + std::to_string(i);
    const int pose = *rc::gen::inRange(0, static_cast<int>(object.stable_poses.size()));
    const double yaw = *rc::gen::inRange(0, 8) * M_PI / 4;
    const auto [x, y] = spots[chosen[i]];
    object.initial_pose = Eigen::Translation3d(x * 0.0254, y * 0.0254, 0) *
                          Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                          object.stable_poses[pose].object_to_world;
    object.initial_stable_pose = pose;
    scene.objects.push_back(std::move(object));
  }
  for (int p = 0; p < 3; ++p) {
    const auto [x, y] = spots[chosen[count + p]];
    scene.places.push_back({.name = "p" + std::to_string(p),
                            .x = x * 0.0254,
                            .y = y * 0.0254,
                            .yaws = {0.0, M_PI / 2},
                            .location = {}});
  }
  // One or two objects go to places; a peg goes into a block when there are both.
  const int movers = *rc::gen::inRange(1, 3);
  for (int k = 0; k < movers && k < count; ++k)
    scene.goals.emplace_back(AtGoal{
        .object = "o" + std::to_string(k), .place = "p" + std::to_string(k), .location = {}});
  const auto shaped = [&](const std::string& shape, int from) {
    for (int i = from; i < count; ++i)
      if (scene.objects[i].shape == "builtin: " + shape) return i;
    return -1;
  };
  if (const int peg = shaped("peg", movers), block = shaped("block", movers);
      peg >= 0 && block >= 0)
    scene.goals.emplace_back(
        AssembledGoal{.held = scene.objects[peg].name,
                      .fixed = scene.objects[block].name,
                      .held_faces = scene.objects[peg].features.at("shaft"),
                      .fixed_faces = scene.objects[block].features.at("hole"),
                      .relative = Eigen::Translation3d(0, 0, 6 * 0.0254) *
                                  Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()),
                      .mating_vector = {0, 0, -1},
                      .clearance = 0.05 * 0.0254,
                      .angular_clearance = 0,
                      .location = {}});
  return scene;
}

// Every returned plan has no overlap in any state and along every approach and retreat.
RC_GTEST_PROP(CollisionProperty, RandomScenesGiveCollisionFreePlans, ()) {
  const Scenario scene = random_scene();
  PlanOptions options;
  options.uncertainty = false;
  options.max_instances = 2;
  options.posting.max_nodes = 3'000;
  std::optional<PlanResult> planned;
  try {
    planned.emplace(plan(scene, builtin_domain(), options));
  } catch (const PlanError&) {
    RC_DISCARD("objects meet in the initial scene");
  }
  const PlanResult& result = *planned;
  RC_CLASSIFY(result.planned(), "planned");
  std::vector<std::vector<geometry::Grasp>> grasps;
  for (std::size_t o = 0; o < scene.objects.size(); ++o)
    grasps.push_back(result.world.object(static_cast<int>(o)).grasps);
  const testing::IndependentCollisionChecker collisions(scene, grasps);
  for (const PlanInstance& instance : result.instances.instances) {
    const std::vector<std::string> problems = testing::check_instance(scene, grasps, instance);
    RC_ASSERT(problems.empty());
    const std::vector<std::string> hits = collisions.check(instance);
    if (!hits.empty()) RC_FAIL(hits.front());
  }
}

}  // namespace
}  // namespace spar::planner
