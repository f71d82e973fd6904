// Scenario keys of sense planning (docs/scenario.md: `identity`, `pose: {stable: [...]}`,
// `sensors.cameras`, `sensors.range_scan`'s sensor keys, `sensing`) and planner/sense_planning.hpp
// on the example examples/sensing_block_pose.yaml.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "spar/common/units.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/scenario.hpp"
#include "spar/planner/sense_planning.hpp"
#include "spar/planner/vision.hpp"
#include "spar/planner/world.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

using testing::kExamples;

// A scenario with one object `part` whose entry is `object` (YAML flow map).
Scenario with_part(const std::string& object, const std::string& extra = "") {
  return parse_scenario(
      "units: {length: in, angle: deg}\nobjects:\n  part: " + object + "\n" + extra, "test.yaml",
      ".");
}

std::string part_error(const std::string& object, const std::string& extra = "") {
  try {
    (void)with_part(object, extra);
  } catch (const ScenarioError& error) {
    return error.what();
  }
  return "";
}

std::vector<std::string> labels(const ObjectSpec& object) {
  std::vector<std::string> out;
  for (const ObjectHypothesis& hypothesis : object.hypotheses) out.push_back(hypothesis.label);
  return out;
}

TEST(SensingScenario, AListOfStablePosesIsAHypothesisSet) {
  const Scenario scenario = with_part("{builtin: block, pose: {stable: [P1, P2], at: [20, 0]}}");
  const ObjectSpec& part = scenario.object("part");
  ASSERT_TRUE(part.uncertain());
  EXPECT_EQ(labels(part), (std::vector<std::string>{"P1", "P2"}));
  EXPECT_EQ(part.hypotheses[1].stable_pose, 1);
  EXPECT_TRUE(part.hypotheses[1].pose.isApprox(Eigen::Translation3d(20 * units::kInch, 0, 0) *
                                               part.stable_poses[1].object_to_world));
  EXPECT_TRUE(part.initial_pose.isApprox(part.hypotheses[0].pose));
  // One listed pose is no uncertainty.
  EXPECT_FALSE(
      with_part("{builtin: block, pose: {stable: [P3], at: [20, 0]}}").object("part").uncertain());
}

TEST(SensingScenario, IdentitiesTimesStablePoses) {
  const Scenario all = with_part("{identity: [block, cube], pose: {at: [20, 0], yaw: 30}}");
  EXPECT_EQ(all.object("part").hypotheses.size(), 12U);  // 6 stable poses each
  EXPECT_EQ(all.object("part").hypotheses[6].label, "cube:P1");
  EXPECT_EQ(all.object("part").identities.size(), 2U);
  const Scenario listed =
      with_part("{identity: [block, cube], pose: {stable: [P1, P5], at: [20, 0]}}");
  EXPECT_EQ(labels(listed.object("part")),
            (std::vector<std::string>{"block:P1", "block:P5", "cube:P1", "cube:P5"}));
  const Scenario placed =
      with_part("{identity: [block, cube], pose: {xyz: [20, 0, 0], rpy: [0, 0, 0]}}");
  EXPECT_EQ(labels(placed.object("part")), (std::vector<std::string>{"block", "cube"}));
  EXPECT_EQ(placed.object("part").hypotheses[1].identity, 1);
}

TEST(SensingScenario, ResolvedMakesOneHypothesisTheTruth) {
  const Scenario scenario =
      with_part("{identity: [block, cube], pose: {stable: [P5], at: [20, 0]}}");
  const Scenario cube = scenario.resolved("part", 1);
  const ObjectSpec& part = cube.object("part");
  EXPECT_FALSE(part.uncertain());
  EXPECT_TRUE(part.identities.empty());
  EXPECT_EQ(part.shape, "builtin: cube");
  EXPECT_EQ(part.model.faces().size(), 6U);
  EXPECT_EQ(part.initial_stable_pose, 4);
  EXPECT_THROW((void)scenario.resolved("part", 2), ScenarioError);
}

TEST(SensingScenario, CamerasAndSensingKeys) {
  const Scenario scenario =
      with_part("{builtin: cube, pose: {stable: [P1, P2], at: [20, 0]}}",
                "sensors:\n"
                "  range_scan: {residual: {dx: 0.02}, position_noise: 0.04, normal_noise: 0.6,"
                " detection_probability: 0.9}\n"
                "  cameras:\n"
                "    - {name: top, pose: {xyz: [20, 0, 30], rpy: [180, 0, 0]},"
                " intrinsics: {fx: 800, fy: 800, cx: 320, cy: 240, width: 640, height: 480},"
                " noise_px: 0.7, detection_probability: 0.8}\n"
                "    - {name: wrist, mount: wrist, pose: {xyz: [0, 0, 2]},"
                " intrinsics: {fx: 500, fy: 500, cx: 160, cy: 120, width: 320, height: 240}}\n"
                "sensing: {ambiguity_threshold: 0.2, max_operations: 2, standoff: 10}\n");
  ASSERT_EQ(scenario.cameras.size(), 2U);
  const CameraSensor& top = scenario.cameras[0];
  EXPECT_EQ(top.mount, sensing::Mount::kFixed);
  EXPECT_EQ(top.intrinsics.width, 640);
  EXPECT_DOUBLE_EQ(top.noise_px, 0.7);
  EXPECT_DOUBLE_EQ(top.detection_probability, 0.8);
  EXPECT_TRUE(top.pose.linear().col(2).isApprox(Eigen::Vector3d(0, 0, -1)));  // looks down
  EXPECT_NEAR(top.pose.translation().z(), 30 * units::kInch, 1e-12);
  EXPECT_EQ(scenario.cameras[1].mount, sensing::Mount::kWrist);
  ASSERT_TRUE(scenario.range_scan);
  EXPECT_NEAR(scenario.range_scan->model.position_noise, 0.04 * units::kInch, 1e-15);
  EXPECT_NEAR(scenario.range_scan->model.normal_noise, 0.6 * units::kDegree, 1e-15);
  EXPECT_EQ(scenario.range_scan->model.mount, sensing::Mount::kWrist);
  EXPECT_DOUBLE_EQ(scenario.sensing.ambiguity_threshold, 0.2);
  EXPECT_EQ(scenario.sensing.max_operations, 2);
  EXPECT_NEAR(scenario.sensing.standoff, 10 * units::kInch, 1e-15);
}

// One camera description (sensors.cameras) for PSEIKI and for sense planning: the sidewalk
// camera of `spar vision` is a sense-planning sensor with the same numbers, and the sensing
// example's overhead camera is one `spar vision` renders from.
TEST(SensingScenario, VisionAndSensePlanningReadOneCameraDescription) {
  const Scenario sidewalk = load_scenario(kExamples / "vision" / "pseiki_sidewalk.yaml");
  const CameraSensor& front = sidewalk.camera("front");
  const sensing::SensorModel model = front.sensor_model();
  EXPECT_EQ(model.name, "front");
  EXPECT_EQ(model.kind, sensing::SensorKind::kCamera);
  EXPECT_EQ(model.mount, sensing::Mount::kFixed);
  EXPECT_TRUE(model.pose.isApprox(front.pose));
  EXPECT_EQ(model.intrinsics.fx, 400);
  EXPECT_EQ(model.intrinsics.width, 640);
  EXPECT_EQ(model.noise_px, 0.5);
  EXPECT_EQ(model.detection_probability, 0.8);
  EXPECT_GT(front.uncertainty.dx, 0);  // PSEIKI's pose uncertainty, kept beside the model

  const Scenario block = load_scenario(kExamples / "sensing_block_pose.yaml");
  const VisionSetup setup(block, "overhead");
  EXPECT_EQ(setup.camera().intrinsics().width, 640);
  EXPECT_TRUE(setup.camera().pose().isApprox(block.camera("overhead").pose));
  const std::vector<sensing::SensorModel> sensors = scenario_sensors(block);
  ASSERT_EQ(sensors.size(), 2U);  // the range scanner, then the cameras
  EXPECT_EQ(sensors[1].name, "overhead");
  EXPECT_EQ(sensors[1].detection_probability, 0.9);
}

// A wrist camera's pose is in the gripper frame: it has no pose uncertainty of its own, and
// `spar vision` (which renders from a pose in the world) refuses it by name.
TEST(SensingScenario, AWristCameraIsForSensePlanningOnly) {
  const std::string wrist =
      "sensors:\n  cameras:\n    - {name: hand, mount: wrist, pose: {xyz: [0, 0, 2]}, "
      "intrinsics: {fx: 500, fy: 500, cx: 160, cy: 120, width: 320, height: 240}";
  const Scenario scenario =
      with_part("{builtin: cube, pose: {stable: P1, at: [20, 0]}}", wrist + "}\n");
  EXPECT_EQ(scenario.camera("hand").sensor_model().mount, sensing::Mount::kWrist);
  try {
    (void)VisionSetup(scenario, "hand");
    ADD_FAILURE() << "expected a ScenarioError";
  } catch (const ScenarioError& error) {
    EXPECT_STREQ(error.what(),
                 "test.yaml:6:7: camera 'hand' is on the wrist (mount: wrist); vision needs a "
                 "fixed camera, posed in the world");
  }
  EXPECT_NE(part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                       wrist + ", uncertainty: {dx: 1}}\n")
                .find("test.yaml:6:146: sensors.cameras[0].uncertainty: a camera on the wrist is "
                      "where the robot puts it; 'uncertainty' is for a fixed camera"),
            std::string::npos)
      << part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                    wrist + ", uncertainty: {dx: 1}}\n");
  // Phase 2 verifies with fixed cameras only (issue 27).
  const std::string residual_error = part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                                                wrist + ", residual: {dx: 0.01}}\n");
  EXPECT_NE(residual_error.find("test.yaml:6:143: sensors.cameras[0].residual: phase 2 verifies "
                                "with fixed cameras only (a wrist camera's view depends on where "
                                "the robot puts it)"),
            std::string::npos)
      << residual_error;
  EXPECT_NE(part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                       "sensors:\n  cameras:\n    - {name: range_scan, pose: {xyz: [0, 0, 1]}, "
                       "intrinsics: {fx: 1, fy: 1, cx: 0, cy: 0, width: 1, height: 1}}\n")
                .find("sensors.cameras[0].name: 'range_scan' is the range scanner's name; name "
                      "the camera otherwise"),
            std::string::npos);
}

TEST(SensingScenario, MistakesSayWhereAndWhat) {
  EXPECT_NE(part_error("{builtin: block, identity: [block, cube], pose: {at: [0, 0]}}")
                .find("give either 'builtin' or 'identity', not both"),
            std::string::npos);
  EXPECT_NE(part_error("{identity: [block], pose: {at: [0, 0]}}")
                .find("expected a list of at least two candidate shapes"),
            std::string::npos);
  EXPECT_NE(part_error("{identity: [block, block], pose: {at: [0, 0]}}").find("listed twice"),
            std::string::npos);
  const std::string unknown = part_error("{builtin: block, pose: {stable: [P1, P9], at: [0, 0]}}");
  EXPECT_EQ(unknown.rfind("test.yaml:3:46: objects.part.pose.stable: object 'part' has no stable "
                          "pose 'P9'",
                          0),
            0U)
      << unknown;
  const std::string cameras = "sensors:\n  cameras:\n    - ";
  EXPECT_NE(part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                       cameras + "{name: c, pose: {xyz: [0, 0, 1]}, intrinsics: {fx: 1, fy: 1, "
                                 "cx: 0, cy: 0, width: 0, height: 1}}\n")
                .find("sensors.cameras[0].intrinsics.width: must be a whole number >= 1 and <= "
                      "16384 (an image side in pixels), got 0"),
            std::string::npos);
  EXPECT_NE(
      part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                 cameras + "{name: c, pose: {xyz: [0, 0, 1]}, intrinsics: {fx: 1, fy: 1, "
                           "cx: 0, cy: 0, width: 1, height: 1}, detection_probability: 1.5}\n")
          .find("detection_probability: must be a number > 0 and <= 1 (a probability), got 1.5"),
      std::string::npos);
  EXPECT_NE(
      part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                 cameras + "{name: c, mount: belt, pose: {xyz: [0, 0, 1]}, intrinsics: {fx: 1, "
                           "fy: 1, cx: 0, cy: 0, width: 1, height: 1}}\n")
          .find("unknown mount 'belt'"),
      std::string::npos);
  EXPECT_NE(part_error("{builtin: cube, pose: {stable: P1, at: [0, 0]}}",
                       "sensing: {max_operations: 0}\n")
                .find("sensing.max_operations: must be a whole number >= 1 and <= 10"),
            std::string::npos);
}

// The example: only a look from the side tells P1 from P2 (the face on top is a plain square
// either way); the overhead camera leaves the ambiguity above the threshold, and the chosen
// operation, a wrist scan from a reachable side viewpoint, brings it below.
TEST(SensePlanning, TheExampleScansFromTheSide) {
  const Scenario scenario = load_scenario(kExamples / "sensing_block_pose.yaml");
  const SensePlan plan = plan_sensing(scenario, WorldModel(scenario));
  ASSERT_EQ(plan.objects.size(), 1U);
  const ObjectSensePlan& block = plan.objects[0];
  EXPECT_EQ(block.hypotheses, (std::vector<std::string>{"P1", "P2"}));
  EXPECT_NEAR(block.selection.ambiguity_before, 1.0, 1e-12);
  bool overhead = false;
  for (const sensing::CandidateOperation& candidate : block.selection.candidates)
    if (candidate.viewpoint.label == "overhead") {
      overhead = true;
      EXPECT_GT(candidate.max_ambiguity, scenario.sensing.ambiguity_threshold);
    }
  EXPECT_TRUE(overhead);
  ASSERT_FALSE(block.selection.sequence.empty());
  EXPECT_TRUE(block.selection.resolved);
  const sensing::Viewpoint& chosen =
      block.selection.candidates[static_cast<std::size_t>(block.selection.sequence[0].candidate)]
          .viewpoint;
  EXPECT_TRUE(chosen.reachable);
  EXPECT_GT(std::abs(chosen.direction.x()), 0.3);  // from a side, not from above
  EXPECT_LT(chosen.direction.z(), 0.9);
}

TEST(SensePlanning, AnUncertainObjectNeedsASensor) {
  const Scenario scenario = with_part("{builtin: block, pose: {stable: [P1, P2], at: [20, 0]}}");
  try {
    (void)plan_sensing(scenario, WorldModel(scenario));
    ADD_FAILURE() << "expected a ScenarioError";
  } catch (const ScenarioError& error) {
    EXPECT_NE(std::string(error.what()).find("but the scenario has no sensor to look at it"),
              std::string::npos)
        << error.what();
  }
}

PlanOptions without_probability() {
  PlanOptions options;
  options.probability.reset();
  return options;
}

std::string example_text() {
  std::ifstream in(kExamples / "sensing_block_pose.yaml");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// spar plan on an uncertain object: the sensing operations first, then one branch per hypothesis,
// each the scenario with the block as the hypothesis has it, planned like any scenario.
TEST(SensePlanning, PlanSensesFirstThenPlansEachOutcome) {
  const Scenario scenario = load_scenario(kExamples / "sensing_block_pose.yaml");
  const PlanResult result = plan(scenario, builtin_domain(), without_probability());
  ASSERT_TRUE(result.sensing);
  EXPECT_EQ(result.sensing->object, "block");
  EXPECT_TRUE(result.sensing->selection.resolved);
  EXPECT_FALSE(result.sensing->selection.sequence.empty());
  ASSERT_EQ(result.branches.size(), 2U);
  for (std::size_t h = 0; h < 2; ++h) {
    const PlanBranch& branch = *std::next(result.branches.begin(), static_cast<std::ptrdiff_t>(h));
    EXPECT_EQ(branch.object, "block");
    EXPECT_EQ(branch.outcome, h == 0 ? "P1" : "P2");
    EXPECT_FALSE(branch.result.sensing);
    const ObjectSpec& block = branch.result.world.scenario().object("block");
    EXPECT_FALSE(block.uncertain());
    EXPECT_EQ(block.initial_stable_pose, static_cast<int>(h));
    EXPECT_TRUE(branch.result.planned()) << branch.outcome << ": " << branch.result.family.reason;
  }
  EXPECT_TRUE(result.planned());
  EXPECT_TRUE(result.instances.instances.empty());  // the plans are the branches'
}

TEST(SensePlanning, SensingThatCannotResolveIsNoPlan) {
  std::string text = example_text();
  text.replace(text.find("ambiguity_threshold: 0.3"), 24, "ambiguity_threshold: 0");
  const PlanResult result = plan(parse_scenario(text, "threshold0.yaml", kExamples),
                                 builtin_domain(), without_probability());
  ASSERT_TRUE(result.sensing);
  EXPECT_FALSE(result.sensing->selection.resolved);
  EXPECT_TRUE(result.branches.empty());
  EXPECT_FALSE(result.planned());
  EXPECT_EQ(result.family.reason.rfind("sensing cannot tell the hypotheses of 'block' apart", 0),
            0U)
      << result.family.reason;
}

TEST(SensePlanning, PlanRefusesTwoUncertainObjects) {
  std::string text = example_text();
  text.replace(text.find("stable: P7"), 10, "stable: [P7, P8]");
  const Scenario scenario = parse_scenario(text, "two.yaml", kExamples);
  try {
    (void)plan(scenario, builtin_domain());
    ADD_FAILURE() << "expected a ScenarioError";
  } catch (const ScenarioError& error) {
    EXPECT_NE(std::string(error.what())
                  .find("objects 'block' and 'peg' are both uncertain: spar plan branches on one "
                        "uncertain object"),
              std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace spar::planner
