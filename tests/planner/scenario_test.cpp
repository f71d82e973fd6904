// The scenario loader (planner/scenario.hpp): the four seed experiments load with their units
// converted, their objects and places are within the robot's reach, and every class of mistake
// gives one ScenarioError whose message starts with `file:line:col:` and says what is wrong.
#include "spar/planner/scenario.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>

#include "spar/common/limits.hpp"
#include "spar/common/units.hpp"
#include "spar/geometry/stable_poses.hpp"
#include "spar/kinematics/robot.hpp"
#include "spar/planner/error.hpp"
#include "spar/sensing/camera.hpp"
#include "tests/common/replaced.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

constexpr double in = units::kInch;
constexpr double deg = units::kDegree;

using testing::kExamples;

// A folder of its own for the files a test writes (meshes), emptied first.
std::filesystem::path scratch_folder(const std::string& name) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / ("spar_scenario_test_" + name);
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  return folder;
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// The message of the ScenarioError that parsing `yaml` (as "test.yaml") throws, or "" if none.
std::string error_of(const std::string& yaml, const std::filesystem::path& base_dir = ".") {
  try {
    (void)parse_scenario(yaml, "test.yaml", base_dir);
  } catch (const ScenarioError& error) {
    return error.what();
  }
  return "";
}

// Parsing `yaml` fails at `line:column` with a message containing `fragment`.
void expect_error(const std::string& yaml, int line, int column, const std::string& fragment,
                  const std::filesystem::path& base_dir = ".") {
  const std::string message = error_of(yaml, base_dir);
  const std::string where =
      "test.yaml:" + std::to_string(line) + ":" + std::to_string(column) + ": ";
  EXPECT_EQ(message.substr(0, where.size()), where) << message;
  EXPECT_NE(message.find(fragment), std::string::npos)
      << "message: " << message << "\nexpected to contain: " << fragment;
}

// A small valid scenario the error tests break one line at a time (line numbers matter).
const std::string kValid = R"(units: {length: in, angle: deg}
objects:
  peg:
    builtin: peg
    pose: {stable: P1, at: [14, 12]}
  block:
    builtin: block
    features: {hole: [2, 6, 10, 12, 16]}
    pose: {stable: P5, at: [20, 0], yaw: 90}
    uncertainty: {dx: 0.11, dy: 0.11, dz: 0.11, dtheta: 5.5}
places: [{name: left, at: [14, -8]}]
goals:
  - assembled: {held: peg, fixed: block, fixed_faces: hole, relative: {xyz: [0, 0, 6]}}
)";

using test_support::replaced;

std::string with(const std::string& from, const std::string& to) {
  return replaced(kValid, from, to);
}

TEST(Scenario, ValidTextLoadsWithDefaultsAndConvertedUnits) {
  const Scenario scenario = parse_scenario(kValid, "dir/my_cell.yaml", ".");
  EXPECT_EQ(scenario.name, "my_cell");  // the source's stem without `name:`
  EXPECT_EQ(scenario.units.length_name(), "in");
  EXPECT_EQ(scenario.robot.model, "puma560");
  ASSERT_EQ(scenario.objects.size(), 2u);
  const ObjectSpec& block = scenario.object("block");
  EXPECT_EQ(block.shape, "builtin: block");
  EXPECT_EQ(block.stable_poses[*block.initial_stable_pose].label, "P5");
  // Resting in P5 at (20, 0) in, turned 90 deg: its frame's x axis is the world's y axis.
  EXPECT_NEAR(block.initial_pose.translation().x(), 20 * in, 1e-12);
  EXPECT_NEAR(block.initial_pose.translation().z(), 0, 1e-12);
  EXPECT_TRUE(block.initial_pose.linear().col(0).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_NEAR(block.uncertainty.dx, 0.11 * in, 1e-15);
  EXPECT_NEAR(block.uncertainty.dtheta, 5.5 * deg, 1e-15);
  EXPECT_EQ(block.features.at("hole"), (std::vector<int>{2, 6, 10, 12, 16}));
  EXPECT_EQ(block.location.str(), "dir/my_cell.yaml:6:3");
  ASSERT_EQ(scenario.places.size(), 1u);
  EXPECT_NEAR(scenario.places[0].y, -8 * in, 1e-15);
  ASSERT_EQ(scenario.goals.size(), 1u);
  const auto& goal = std::get<AssembledGoal>(scenario.goals[0]);
  EXPECT_EQ(goal.fixed_faces, block.features.at("hole"));
  EXPECT_TRUE(goal.held_faces.empty());
  EXPECT_NEAR(goal.relative.translation().z(), 6 * in, 1e-15);
  EXPECT_TRUE(goal.mating_vector.isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_FALSE(scenario.range_scan.has_value());
}

// sensors.cameras (normative): intrinsics in pixels, the pose in the file's units; the lookup by
// name lists the known cameras.
TEST(Scenario, CamerasLoadWithIntrinsicsInPixelsAndThePoseInTheFilesUnits) {
  const Scenario scenario = parse_scenario(kValid + R"(sensors:
  cameras:
    - name: overhead
      pose: {xyz: [20, 0, 30], rpy: [180, 0, 0]}
      intrinsics: {fx: 800, fy: 810, cx: 320, cy: 240, width: 640, height: 480}
      noise_px: 0.5
      detection_probability: 0.9
      uncertainty: {dx: 0.5, dtheta: 2}
    - {name: side, pose: {xyz: [0, 0, 10]}, projection: orthographic,
       intrinsics: {fx: 100, fy: 100, cx: 64, cy: 64, width: 128, height: 128}}
)",
                                           "cell.yaml", ".");
  ASSERT_EQ(scenario.cameras.size(), 2u);
  const CameraSensor& overhead = scenario.camera("overhead");
  EXPECT_EQ(overhead.projection, sensing::Projection::kPinhole);
  EXPECT_EQ(overhead.intrinsics.fy, 810);
  EXPECT_EQ(overhead.intrinsics.height, 480);
  EXPECT_NEAR(overhead.pose.translation().z(), 30 * in, 1e-15);
  EXPECT_TRUE(overhead.pose.linear().col(2).isApprox(Eigen::Vector3d(0, 0, -1), 1e-12));
  EXPECT_EQ(overhead.noise_px, 0.5);
  EXPECT_EQ(overhead.detection_probability, 0.9);
  EXPECT_NEAR(overhead.uncertainty.dx, 0.5 * in, 1e-15);
  EXPECT_NEAR(overhead.uncertainty.dtheta, 2 * deg, 1e-15);
  EXPECT_EQ(overhead.location.str(), "cell.yaml:16:7");
  const CameraSensor& side = scenario.camera("side");
  EXPECT_EQ(side.projection, sensing::Projection::kOrthographic);
  EXPECT_EQ(side.noise_px, 0.0);
  EXPECT_EQ(side.detection_probability, 1.0);
  try {
    (void)scenario.camera("wrist");
    ADD_FAILURE() << "no error";
  } catch (const ScenarioError& error) {
    EXPECT_STREQ(error.what(), "scenario 'cell' has no camera 'wrist' (cameras: overhead, side)");
  }
}

TEST(ScenarioErrors, CameraMistakesNameTheKey) {
  const std::string camera =
      "sensors:\n  cameras:\n    - {name: c, pose: {xyz: [0, 0, 30]}, intrinsics: {fx: 800, fy: "
      "800, cx: 320, cy: 240, width: 640, height: 480}}\n";
  const auto broken = [&](const std::string& from, const std::string& to) {
    return kValid + replaced(camera, from, to);
  };
  expect_error(
      broken("fx: 800", "fx: 0"), 16, 59,
      "sensors.cameras[0].intrinsics.fx: must be a number > 0 and <= 1e+06 (a focal length "
      "in pixels), got 0");
  expect_error(broken("width: 640", "width: 64.5"), 16, 98,
               "sensors.cameras[0].intrinsics.width: must be a whole number >= 1 and <= 16384 (an "
               "image side in pixels), got 64.5");
  expect_error(broken("height: 480", "height: 0"), 16, 111,
               "sensors.cameras[0].intrinsics.height: must be a whole number >= 1 and <= 16384 (an "
               "image side in pixels), got 0");
  expect_error(broken("}}", "}, detection_probability: 1.5}"), 16, 140,
               "sensors.cameras[0].detection_probability: must be a number > 0 and <= 1 (a "
               "probability), got 1.5");
  expect_error(broken("}}", "}, noise_px: -1}"), 16, 127,
               "sensors.cameras[0].noise_px: must be a number >= 0 and <= 100 (an edge detector's "
               "noise in pixels), got -1");
  expect_error(broken("}}", "}, projection: pinhol}"), 16, 129,
               "unknown projection 'pinhol' (did you mean 'pinhole'?)");
  expect_error(broken("}}", "}, noise: 1}"), 16, 117, "sensors.cameras[0]: unknown key 'noise'");
  expect_error(kValid + camera +
                   "    - {name: c, pose: {}, intrinsics: {fx: 1, fy: 1, cx: 0, cy: 0, "
                   "width: 1, height: 1}}\n",
               17, 7, "sensors.cameras[1].name: duplicate camera name 'c'");
}

// common/limits.cpp cannot include sensing/, so its image side must be checked against it here.
TEST(ScenarioLimits, TheImageSideIsTheRenderersLimit) {
  EXPECT_EQ(numeric_limit("camera.image_side").high, sensing::kMaxImageSide);
}

TEST(Scenario, UnitsConvertBothWays) {
  Units units;
  units.length = LengthUnit::kMillimetre;
  units.angle = AngleUnit::kDegree;
  EXPECT_DOUBLE_EQ(units.to_file_length(0.0254), 25.4);
  EXPECT_DOUBLE_EQ(units.to_file_angle(std::numbers::pi), 180);
  EXPECT_EQ(units.angle_name(), "deg");
  units.length = LengthUnit::kInch;
  EXPECT_EQ(units.to_file_length(0.0254), 1.0);
}

TEST(Scenario, PosesAsXyzRpyOrMatrixAndRestingPosesAreClassified) {
  // The peg standing on its base at (1, 2) m, turned 90 deg about z, given three ways; lifted
  // 1 m it rests on nothing and has no stable pose.
  for (const std::string pose :
       {"{xyz: [1, 2, 0], rpy: [0, 0, 1.5707963267948966]}",
        "{matrix: [[0, -1, 0, 1], [1, 0, 0, 2], [0, 0, 1, 0], [0, 0, 0, 1]]}",
        "{stable: P1, at: [1, 2], yaw: 1.5707963267948966}"}) {
    const Scenario scenario =
        parse_scenario("objects: {peg: {builtin: peg, pose: " + pose + "}}", "t.yaml", ".");
    const ObjectSpec& peg = scenario.object("peg");
    EXPECT_TRUE(peg.initial_pose.translation().isApprox(Eigen::Vector3d(1, 2, 0), 1e-9)) << pose;
    EXPECT_TRUE(peg.initial_pose.linear().col(0).isApprox(Eigen::Vector3d::UnitY(), 1e-9)) << pose;
    ASSERT_TRUE(peg.initial_stable_pose.has_value()) << pose;
    EXPECT_EQ(peg.stable_poses[*peg.initial_stable_pose].label, "P1") << pose;
  }
  const Scenario lifted =
      parse_scenario("objects: {peg: {builtin: peg, pose: {xyz: [1, 2, 1]}}}", "t.yaml", ".");
  EXPECT_FALSE(lifted.object("peg").initial_stable_pose.has_value());
}

TEST(Scenario, FeaturesAndGoalFacesTakeIdsFaceNamesOrFeatureNames) {
  const Scenario scenario = parse_scenario(
      replaced(with("features: {hole: [2, 6, 10, 12, 16]}",
                    "features: {hole: [peg hole floor, 2, 6, 10, 12], outside: top}"),
               "fixed_faces: hole", "fixed_faces: [hole, 1]"),
      "t.yaml", ".");
  const ObjectSpec& block = scenario.object("block");
  EXPECT_EQ(block.features.at("hole"), (std::vector<int>{2, 6, 10, 12, 16}));
  EXPECT_EQ(block.features.at("outside"), std::vector<int>{19});
  EXPECT_EQ(std::get<AssembledGoal>(scenario.goals[0]).fixed_faces,
            (std::vector<int>{1, 2, 6, 10, 12, 16}));
}

TEST(Scenario, MeshCoordinatesAreInTheFilesLengthUnit) {
  const std::filesystem::path folder = scratch_folder("mesh_units");
  std::filesystem::create_directories(folder / "meshes");
  // A 10 mm cube as an OFF file.
  write_file(folder / "meshes" / "cube.off",
             "OFF\n8 6 0\n0 0 0\n10 0 0\n10 10 0\n0 10 0\n0 0 10\n10 0 10\n10 10 10\n0 10 10\n"
             "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n");
  write_file(folder / "cell.yaml",
             "units: {length: mm}\n"
             "objects: {cube: {mesh: meshes/cube.off, pose: {stable: P1, at: [100, 0]}}}\n");
  const Scenario scenario = load_scenario(folder / "cell.yaml");
  const ObjectSpec& cube = scenario.object("cube");
  EXPECT_EQ(cube.shape, "mesh: meshes/cube.off");
  EXPECT_NEAR(cube.model.volume(), 1e-6, 1e-18);  // (0.01 m)^3
  // `at` puts the centre of mass (the cube's centre) above (100, 0) mm.
  EXPECT_TRUE((cube.initial_pose * cube.model.center_of_mass())
                  .isApprox(Eigen::Vector3d(0.1, 0, 0.005), 1e-12));
  EXPECT_EQ(scenario.path, folder / "cell.yaml");
  EXPECT_EQ(scenario.name, "cell");
}

TEST(Scenario, ObjectLookupNamesTheKnownObjects) {
  const Scenario scenario = parse_scenario(kValid, "t.yaml", ".");
  try {
    (void)scenario.object("bolt");
    ADD_FAILURE() << "no error";
  } catch (const ScenarioError& error) {
    EXPECT_NE(std::string(error.what()).find("no object 'bolt' (objects: peg, block)"),
              std::string::npos)
        << error.what();
  }
}

// ---- one test per class of mistake ----

TEST(ScenarioErrors, YamlSyntax) {
  expect_error(with("  peg:\n", "  peg: [\n"), 5, 9, "YAML syntax error");
}

// yaml-cpp's own message for this is "bad file".
TEST(ScenarioErrors, NestingBeyondYamlCppsLimitIsNamed) {
  const std::string deep = "objects: " + std::string(1000, '[') + std::string(1000, ']') + "\n";
  expect_error(deep, 1, 2010, "YAML syntax error: nested too deeply");
}

TEST(ScenarioErrors, UnknownKeySuggestsTheNearestKnownOne) {
  expect_error(with("    builtin: peg\n", "    bultin: peg\n"), 4, 5,
               "objects.peg: unknown key 'bultin' (did you mean 'builtin'?)");
  expect_error("robot: {modle: puma560}\nobjects: {}\n", 1, 9,
               "robot: unknown key 'modle' (did you mean 'model'?)");
}

TEST(ScenarioErrors, WrongType) {
  expect_error(with("places: [{name: left, at: [14, -8]}]", "places: 3"), 11, 9,
               "places: expected a list, got '3'");
  expect_error(with("at: [14, 12]", "at: [14, north]"), 5, 33,
               "objects.peg.pose.at[1]: expected a number, got 'north'");
  expect_error(with("at: [14, 12]", "at: [14]"), 5, 28,
               "objects.peg.pose.at: expected a list of 2 numbers, got a list of 1");
}

TEST(ScenarioErrors, MissingKey) {
  expect_error("units: {length: in}\n", 1, 1, "missing key 'objects'");
  expect_error(with("    pose: {stable: P1, at: [14, 12]}\n", ""), 4, 5,
               "objects.peg: missing key 'pose'");
  expect_error(with("    builtin: peg\n", ""), 4, 5,
               "objects.peg: needs exactly one of 'builtin: <name>', 'mesh: <file>' and "
               "'identity: [<candidates>]'");
}

TEST(ScenarioErrors, UnknownObjectInAGoal) {
  expect_error(with("held: peg", "held: pge"), 13, 23,
               "goals[0].assembled.held: unknown object 'pge' (did you mean 'peg'?); objects: "
               "peg, block");
}

TEST(ScenarioErrors, UnknownFaceOrFeature) {
  expect_error(with("[2, 6, 10, 12, 16]", "[2, 6, 10, 12, 20]"), 8, 37,
               "object 'block' has no face 20 (faces 1..19)");
  expect_error(with("fixed_faces: hole", "fixed_faces: hose"), 13, 55,
               "object 'block' has no face or feature named 'hose' (did you mean 'hole'?)");
}

TEST(ScenarioErrors, PoseThatIsNotRigid) {
  expect_error(with("{stable: P1, at: [14, 12]}",
                    "{matrix: [[2, 0, 0, 1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}"),
               5, 20, "objects.peg.pose.matrix: not a rigid transform");
  expect_error(with("{stable: P1, at: [14, 12]}", "{stable: P1, at: [14, 12], xyz: [0, 0, 1]}"), 5,
               43, "give either {stable, at, yaw} or {xyz, rpy}");
}

TEST(ScenarioErrors, NegativeOrNanUncertainty) {
  expect_error(with("dy: 0.11", "dy: -0.11"), 10, 33,
               "objects.block.uncertainty.dy: must be a length >= 0 and <= 393.701 in (an error in "
               "a robot cell), got -0.11 in");
  expect_error(with("dtheta: 5.5", "dtheta: .nan"), 10, 57,
               "objects.block.uncertainty.dtheta: expected a finite number, got '.nan'");
}

TEST(ScenarioErrors, UnknownRobotModel) {
  expect_error("robot: {model: puma561}\nobjects: {}\n", 1, 16,
               "unknown robot model 'puma561' (did you mean 'puma560'?); known: puma560, "
               "puma762, ur5, panda, dh (or urdf: <file>)");
}

TEST(ScenarioErrors, DhTableMistakes) {
  expect_error(
      "robot:\n  model: dh\n  dh: [{d: 1, limits: [1, -1]}, {a: 1, limits: [-1, 1]}]\n"
      "objects: {}\n",
      3, 23, "robot.dh[0].limits: the lower limit is above the upper one");
  expect_error("robot: {model: puma560, dh: []}\nobjects: {}\n", 1, 29,
               "a DH table goes with model: dh");
}

TEST(ScenarioErrors, UrdfRobotMistakes) {
  expect_error("robot: {model: ur5, urdf: arm.urdf}\nobjects: {}\n", 1, 27,
               "robot.urdf: give either model: <name> or urdf: <file>, not both");
  expect_error("robot: {model: puma560, tip: flange}\nobjects: {}\n", 1, 30,
               "robot.tip: a tip link goes with urdf: <file> or a URDF built-in (ur5, panda)");
  expect_error("robot: {model: ur5, tip: gripper}\nobjects: {}\n", 1, 16,
               "robot: " + std::string(SPAR_CORPUS_DIR) +
                   "/robots/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf:6: no "
                   "link 'gripper' for the tip");
  expect_error("robot: {urdf: absent.urdf}\nobjects: {}\n", 1, 15,
               "robot.urdf: absent.urdf: cannot read the URDF file");
}

TEST(Scenario, RobotsByNameUrdfFileOrAnyDhTable) {
  const auto robot_of = [](const std::string& robot, const std::filesystem::path& folder) {
    return parse_scenario(
               "robot: " + robot + "\nobjects: {cube: {builtin: cube, pose: {xyz: [0.5, 0, 0]}}}\n",
               "test.yaml", folder)
        .robot;
  };
  const RobotSpec ur5 = robot_of("{model: ur5}", ".");
  EXPECT_EQ(ur5.arm.tip_link(), "tool0");
  EXPECT_EQ(ur5.arm.ik_method(), kinematics::IkMethod::kUrClosedForm);
  const std::filesystem::path data = std::string(SPAR_CORPUS_DIR) + "/robots";
  const RobotSpec file = robot_of(
      "{urdf: example-robot-data/robots/panda_description/urdf/panda.urdf, tip: panda_link8, "
      "package_path: [.]}",
      data);
  EXPECT_EQ(file.model, "urdf");
  EXPECT_EQ(file.urdf, "example-robot-data/robots/panda_description/urdf/panda.urdf");
  EXPECT_EQ(file.arm.dof(), 7u);
  EXPECT_EQ(file.arm.ik_method(), kinematics::IkMethod::kRedundantClosedForm);
  // A UR5 as a DH table (Hawkins 2013): no longer refused, its geometry picks the UR closed form.
  const RobotSpec dh = robot_of(
      "{model: dh, dh: [{d: 0.089159, alpha: 1.5707963267948966, limits: [-6, 6]}, "
      "{a: -0.425, limits: [-6, 6]}, {a: -0.39225, limits: [-6, 6]}, "
      "{d: 0.10915, alpha: 1.5707963267948966, limits: [-6, 6]}, "
      "{d: 0.09465, alpha: -1.5707963267948966, limits: [-6, 6]}, {d: 0.0823, limits: [-6, 6]}]}",
      ".");
  EXPECT_EQ(dh.arm.ik_method(), kinematics::IkMethod::kUrClosedForm);
}

TEST(ScenarioErrors, MissingMeshNamesTheResolvedPath) {
  const std::filesystem::path folder = scratch_folder("missing_mesh");
  const std::string message =
      error_of("objects: {part: {mesh: meshes/part.off, pose: {xyz: [0, 0, 0]}}}", folder);
  EXPECT_EQ(message.rfind("test.yaml:1:24: objects.part.mesh: ", 0), 0u) << message;
  EXPECT_NE(message.find((folder / "meshes" / "part.off").string() + ": no such mesh file"),
            std::string::npos)
      << message;
}

TEST(ScenarioErrors, MalformedMeshIncludesTheGeometryMessage) {
  const std::filesystem::path folder = scratch_folder("bad_mesh");
  // A tetrahedron with one face missing: not closed.
  write_file(folder / "open.off",
             "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n"
             "3 0 3 2\n");
  const std::string message =
      error_of("objects: {part: {mesh: open.off, pose: {xyz: [0, 0, 0]}}}", folder);
  EXPECT_EQ(message.rfind("test.yaml:1:24: objects.part.mesh: bad mesh ", 0), 0u) << message;
  EXPECT_NE(message.find("at least 4 triangles"), std::string::npos) << message;
}

TEST(ScenarioErrors, DuplicateNames) {
  expect_error(with("  block:\n", "  peg:\n"), 6, 3, "objects: duplicate object name 'peg'");
  expect_error(with("places: [{name: left, at: [14, -8]}]",
                    "places: [{name: left, at: [14, -8]}, {name: left, at: [0, 9]}]"),
               11, 45, "places[1].name: duplicate place name 'left'");
  expect_error(with("units: {length: in, angle: deg}", "units: {length: in, length: mm}"), 1, 21,
               "units: duplicate key 'length'");
}

TEST(ScenarioErrors, UnknownStablePoseListsTheKnownOnes) {
  expect_error(with("stable: P5", "stable: P7"), 9, 20,
               "object 'block' has no stable pose 'P7'; its stable poses: P1, P2, P3, P4, P5, "
               "P6");
}

TEST(ScenarioErrors, UnknownUnit) {
  expect_error(with("length: in", "length: ft"), 1, 17,
               "units.length: unknown length unit 'ft'; known: m, mm, in");
}

TEST(ScenarioErrors, UnreadableFile) {
  try {
    (void)load_scenario(kExamples / "no_such_scenario.yaml");
    ADD_FAILURE() << "no error";
  } catch (const ScenarioError& error) {
    EXPECT_NE(std::string(error.what()).find("no_such_scenario.yaml: no such scenario file"),
              std::string::npos)
        << error.what();
  }
}

// ---- the seed's four experiments ----

// The seed's situations, by what rests on the table (not by pose label, which the examples may
// pick among equivalent poses): the block on its top (19, face down), on a side (1, 5, 9 or 11)
// or on its bottom (13, hole up); the peg standing on its base (7) or lying on its side.
enum class BlockRests { kFaceDown, kOnASide, kHoleUp };
enum class PegRests { kOnItsSide, kOnItsBase };
struct Experiment {
  const char* file;
  BlockRests block;
  PegRests peg;
};
constexpr Experiment kExperiments[] = {
    {"peg_block_face_down.yaml", BlockRests::kFaceDown, PegRests::kOnItsSide},
    {"peg_block_on_sides.yaml", BlockRests::kOnASide, PegRests::kOnItsSide},
    {"peg_block_face_up.yaml", BlockRests::kHoleUp, PegRests::kOnItsSide},
    {"peg_block_on_back.yaml", BlockRests::kHoleUp, PegRests::kOnItsBase}};

TEST(SeedExperiments, LoadInInchesAndDegreesWithTable2Uncertainties) {
  for (const Experiment& experiment : kExperiments) {
    SCOPED_TRACE(experiment.file);
    const Scenario scenario = load_scenario(kExamples / experiment.file);
    EXPECT_EQ(scenario.units.length_name(), "in");
    EXPECT_EQ(scenario.units.angle_name(), "deg");
    const ObjectSpec& block = scenario.object("block");
    const ObjectSpec& peg = scenario.object("peg");
    EXPECT_EQ(block.shape, "builtin: block");
    EXPECT_EQ(peg.shape, "builtin: peg");
    ASSERT_TRUE(block.initial_stable_pose && peg.initial_stable_pose);
    const std::vector<int>& block_on = block.stable_poses[*block.initial_stable_pose].table_faces;
    switch (experiment.block) {
      case BlockRests::kFaceDown:
        EXPECT_EQ(block_on, std::vector<int>{19});
        break;
      case BlockRests::kOnASide:
        ASSERT_EQ(block_on.size(), 1u);
        EXPECT_TRUE(block_on[0] == 1 || block_on[0] == 5 || block_on[0] == 9 || block_on[0] == 11)
            << block_on[0];
        break;
      case BlockRests::kHoleUp:
        EXPECT_EQ(block_on, std::vector<int>{13});
        break;
    }
    // The peg's axis (its frame's z) in the world: up when standing, nearly level when lying.
    const double axis_up = peg.initial_pose.linear().col(2).z();
    if (experiment.peg == PegRests::kOnItsBase) {
      EXPECT_EQ(peg.stable_poses[*peg.initial_stable_pose].table_faces, std::vector<int>{7});
      EXPECT_NEAR(axis_up, 1, 1e-12);
    } else {
      EXPECT_LT(std::abs(axis_up), 0.5);
    }
    for (const ObjectSpec* object : {&block, &peg}) {
      EXPECT_NEAR(object->uncertainty.dx, 0.11 * in, 1e-15);
      EXPECT_NEAR(object->uncertainty.dtheta, 5.5 * deg, 1e-15);
    }
    EXPECT_NEAR(scenario.robot.uncertainty.dz, 0.001 * in, 1e-15);
    EXPECT_NEAR(scenario.robot.uncertainty.dtheta, 0.001, 1e-6);  // 0.0573 deg
    EXPECT_NEAR(scenario.robot.gripper.max_opening, 4 * in, 1e-15);
    EXPECT_NEAR(scenario.grasping.approach_step, 45 * deg, 1e-15);
    ASSERT_TRUE(scenario.range_scan.has_value());
    EXPECT_LT(scenario.range_scan->residual.dx, 0.05 * in);  // below the insertion clearance
    ASSERT_EQ(scenario.goals.size(), 1u);
    const auto& goal = std::get<AssembledGoal>(scenario.goals[0]);
    EXPECT_EQ(goal.held, "peg");
    EXPECT_EQ(goal.fixed, "block");
    EXPECT_EQ(goal.fixed_faces, (std::vector<int>{2, 6, 10, 12, 16}));
    EXPECT_EQ(goal.held_faces, (std::vector<int>{11, 12, 13, 14, 15, 16, 17, 18, 19}));
    EXPECT_NEAR(goal.clearance, 0.05 * in, 1e-15);
    // Ta: the peg upside down with its shaft end (z = 5 in, peg frame) on the hole floor (1 in).
    EXPECT_TRUE((goal.relative * Eigen::Vector3d(0, 0, 5 * in))
                    .isApprox(Eigen::Vector3d(0, 0, 1 * in), 1e-12));
  }
}

// What the planner's reachable(grasp, position) asks, with the robot's IK: the object at `pose`
// (resting in `stable`) has a grasp usable in that pose that the arm reaches pointing down.
// The arm reaches the gripper pose (world) pointing down, with joints within limits.
bool arm_reaches(const Scenario& scenario, const kinematics::Transform& gripper_pose) {
  const double tilt = std::acos(std::clamp(-gripper_pose.linear()(2, 2), -1.0, 1.0));
  if (tilt > scenario.robot.max_tool_tilt) return false;
  const kinematics::Transform tip_in_base = scenario.robot.base.inverse(Eigen::Isometry) *
                                            gripper_pose *
                                            scenario.robot.tool.inverse(Eigen::Isometry);
  for (const kinematics::JointSolution& solution : scenario.robot.arm.inverse(tip_in_base))
    if (solution.within_limits) return true;
  return false;
}

bool some_grasp_reachable(const Scenario& scenario, const geometry::StablePose& stable,
                          const kinematics::Transform& pose,
                          const std::vector<geometry::Grasp>& grasps,
                          const geometry::GripperSpec& gripper) {
  for (const geometry::Grasp& grasp : grasps)
    if (geometry::grasp_usable(grasp, stable, gripper) &&
        arm_reaches(scenario, pose * grasp.gripper_in_object))
      return true;
  return false;
}

TEST(SeedExperiments, EveryInitialPoseAndEveryPlaceIsWithinReach) {
  // The planner rejects positions the arm cannot reach with the gripper pointing down; the
  // examples' layout (robot base, tool, places) must leave every one reachable: each object's
  // initial pose, and each place in each of the object's stable poses. Also the assembly: with the
  // block hole up (P5) at any place, the peg at T_block Ta has a reachable grasp leaving the shaft
  // free.
  for (const Experiment& experiment : kExperiments) {
    SCOPED_TRACE(experiment.file);
    const Scenario scenario = load_scenario(kExamples / experiment.file);
    geometry::GripperSpec gripper = scenario.robot.gripper;
    gripper.max_approach_tilt = scenario.robot.max_tool_tilt;
    for (const ObjectSpec& object : scenario.objects) {
      const auto grasps = geometry::compute_grasps(object.model, gripper, scenario.grasping);
      const geometry::StablePose& initial = object.stable_poses[*object.initial_stable_pose];
      EXPECT_TRUE(some_grasp_reachable(scenario, initial, object.initial_pose, grasps, gripper))
          << object.name << " initial";
      for (const Place& place : scenario.places)
        for (const geometry::StablePose& stable : object.stable_poses) {
          const kinematics::Transform pose =
              Eigen::Translation3d(place.x, place.y, 0) *
              Eigen::AngleAxisd(place.yaws.front(), Eigen::Vector3d::UnitZ()) *
              stable.object_to_world;
          EXPECT_TRUE(some_grasp_reachable(scenario, stable, pose, grasps, gripper))
              << object.name << " " << stable.label << " at " << place.name;
        }
    }
    const auto& goal = std::get<AssembledGoal>(scenario.goals[0]);
    const ObjectSpec& block = scenario.object("block");
    const ObjectSpec& peg = scenario.object("peg");
    const auto peg_grasps = geometry::compute_grasps(peg.model, gripper, scenario.grasping);
    const geometry::StablePose& hole_up = block.stable_poses[4];
    ASSERT_EQ(hole_up.label, "P5");
    for (const Place& place : scenario.places) {
      const kinematics::Transform block_pose =
          Eigen::Translation3d(place.x, place.y, 0) *
          Eigen::AngleAxisd(place.yaws.front(), Eigen::Vector3d::UnitZ()) * hole_up.object_to_world;
      bool mate_reachable = false;
      for (const geometry::Grasp& grasp : peg_grasps)
        mate_reachable |=
            geometry::grasp_leaves_free(grasp, goal.held_faces) &&
            arm_reaches(scenario, block_pose * goal.relative * grasp.gripper_in_object);
      EXPECT_TRUE(mate_reachable) << "assembly at " << place.name;
    }
  }
}

}  // namespace
}  // namespace spar::planner
