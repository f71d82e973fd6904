// Scenario and domain files under hostile input (issue 22): values that would exhaust memory or
// are not physical, text that is not UTF-8 or holds control characters, files that hold two
// documents or end lines with CR, paths that are not regular files. Each is refused with one
// error at `file:line:col` that says what is wrong; what loads stays inside the table of limits
// (common/limits.hpp), which a property checks over random values.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "spar/common/limits.hpp"
#include "spar/common/number.hpp"
#include "spar/common/text.hpp"
#include "spar/common/units.hpp"
#include "spar/planner/domain.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/scenario.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/common/replaced.hpp"

namespace spar::planner {
namespace {

namespace fs = std::filesystem;

// One cube on the table in inches and degrees; each case replaces one piece of it.
const std::string kCell = R"(name: cell
units: {length: in, angle: deg}
robot: {gripper: {max_opening: 4}, max_tilt: 60}
grasping: {approach_step: 45, positions_per_axis: 1}
objects:
  cube:
    builtin: cube
    pose: {stable: P1, at: [20, 0], yaw: 0}
    uncertainty: {dx: 0.1, dy: 0.1, dz: 0.1, dtheta: 2}
places: [{name: left, at: [14, -8]}]
)";

// kCell with the first `from` replaced by `to`.
std::string cell_with(const std::string& from, const std::string& to) {
  return test_support::replaced(kCell, from, to);
}

std::string scenario_error(const std::string& text) {
  try {
    (void)parse_scenario(text, "cell.yaml", ".");
  } catch (const ScenarioError& error) {
    return error.what();
  }
  return "";
}

struct Hostile {
  std::string name;
  std::string text;
  std::string message;  // the expected start: "cell.yaml:L:C: what"
};

TEST(HostileScenario, EachIsRefusedAtFileLineColumn) {
  const std::vector<Hostile> cases = {
      {"approach step that makes billions of grasps",
       cell_with("approach_step: 45", "approach_step: 1e-9"),
       "cell.yaml:4:27: grasping.approach_step: must be an angle >= 1 and <= 360 deg"},
      {"a million positions per axis",
       cell_with("positions_per_axis: 1", "positions_per_axis: 1000000"),
       "cell.yaml:4:51: grasping.positions_per_axis: must be a whole number >= 1 and <= 20"},
      {"fractional positions", cell_with("positions_per_axis: 1", "positions_per_axis: 2.5"),
       "cell.yaml:4:51: grasping.positions_per_axis: must be a whole number"},
      {"gripper opening of 1e308", cell_with("max_opening: 4", "max_opening: 1e308"),
       "cell.yaml:3:32: robot.gripper.max_opening: must be a length > 0 and <= 78.7402 in"},
      {"a tilt past straight up", cell_with("max_tilt: 60", "max_tilt: 270"),
       "cell.yaml:3:46: robot.max_tilt: must be an angle > 0 and <= 180 deg"},
      {"a place a light year away", cell_with("at: [14, -8]", "at: [1e300, -8]"),
       "cell.yaml:10:28: places[0].at[0]: must be a length from -3937.01 in to 3937.01 in"},
      {"a yaw of 1e20 degrees", cell_with("yaw: 0", "yaw: 1e20"),
       "cell.yaml:8:42: objects.cube.pose.yaw: must be an angle from -360 deg to 360 deg"},
      {"an angular uncertainty of many turns", cell_with("dtheta: 2", "dtheta: 1e9"),
       "cell.yaml:9:54: objects.cube.uncertainty.dtheta: must be an angle >= 0 and <= 180 deg"},
      {"a negative half-width", cell_with("dx: 0.1", "dx: -0.1"),
       "cell.yaml:9:23: objects.cube.uncertainty.dx: must be a length >= 0"},
      {"too many places",
       cell_with("places: [{name: left, at: [14, -8]}]",
                 [] {
                   std::string places = "places: [";
                   for (int i = 0; i < 1001; ++i)
                     places += "{name: p" + std::to_string(i) + ", at: [14, -8]}, ";
                   return places + "]";
                 }()),
       "cell.yaml:10:9: places: holds 1001 entries; their number must be a whole number >= 0 and "
       "<= 1000"},
      {"a name that is not UTF-8", cell_with("name: cell", "name: ce\xffll"),
       "cell.yaml:1:9: invalid UTF-8 (byte 0xff); cell.yaml must be UTF-8 text"},
      {"a NUL escape in the name", cell_with("name: cell", "name: \"peg\\0block\""),
       "cell.yaml:1:7: name: 'peg\\0block' holds a control character"},
      {"a backspace escape in the name", cell_with("name: cell", "name: \"peg\\block\""),
       "cell.yaml:1:7: name: 'peg\\x08lock' holds a control character"},
      {"a raw control character", cell_with("name: cell", "name: ce\x01ll"),
       "cell.yaml:1:9: control character '\\x01' in the file"},
      {"two documents", kCell + "---\nname: second\n",
       "cell.yaml:11:1: a second YAML document (after '---')"},
      {"an empty second document", kCell + "---\n", "cell.yaml:11:1: a second YAML document"},
      // yaml-cpp 0.7's LoadAll looped forever, growing, on a ',' no node can start with (found
      // by scenario_fuzz in CI: a comment line, then a line starting with ',').
      {"a stray comma", "# a comment\n,he peg lies on its side\n",
       "cell.yaml:2:1: YAML syntax error: ',' cannot start a value"},
      {"a stray comma after a document start", "---\n,\n",
       "cell.yaml:2:1: YAML syntax error: ',' cannot start a value"},
      {"a stray comma after the document", kCell + ",\n",
       "cell.yaml:11:1: YAML syntax error: end of map not found"},
      {"an escape sequence in an unknown key", cell_with("name: cell", "\"\\e[31mred\": 1"),
       "cell.yaml:1:1: unknown key '\\x1b[31mred'"},
      {"a file over the YAML limit", kCell + "# " + std::string(1 << 20, 'x') + "\n",
       "cell.yaml: is larger than 1 MB, the limit for a YAML file"},
  };
  for (const Hostile& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string message = scenario_error(c.text);
    EXPECT_EQ(message.substr(0, c.message.size()), c.message) << message;
    EXPECT_TRUE(is_valid_utf8(message)) << printable(message);
    EXPECT_FALSE(find_control_character(message).has_value()) << printable(message);
  }
}

TEST(HostileScenario, GarbageEchoedInAMessageIsShortAndEscaped) {
  const std::string garbage = std::string(5000, 'z') + "\\e";
  const std::string message =
      scenario_error(cell_with("robot: {gripper", "robot: {model: \"" + garbage + "\", gripper"));
  EXPECT_EQ(message.rfind("cell.yaml:3:16: robot.model: 'zzzz", 0), 0u) << message;
  EXPECT_NE(message.find("... (5001 bytes)' holds a control character"), std::string::npos)
      << message;
  EXPECT_LT(message.size(), 400u) << message;
}

TEST(HostileScenario, CrOnlyAndCrLfFilesLoadLikeLf) {
  std::string cr = kCell, crlf;
  for (char& c : cr)
    if (c == '\n') c = '\r';
  for (const char c : kCell) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const Scenario lf = parse_scenario(kCell, "cell.yaml", ".");
  for (const std::string& text : {cr, crlf}) {
    const Scenario other = parse_scenario(text, "cell.yaml", ".");
    EXPECT_EQ(other.name, lf.name);
    EXPECT_EQ(other.places.size(), 1u);
    EXPECT_TRUE(other.objects[0].initial_pose.isApprox(lf.objects[0].initial_pose));
  }
  // Line numbers count CR line ends too.
  std::string bad = cell_with("yaw: 0", "yaw: 1e20");
  for (char& c : bad)
    if (c == '\n') c = '\r';
  EXPECT_EQ(scenario_error(bad).rfind("cell.yaml:8:42: objects.cube.pose.yaw:", 0), 0u)
      << scenario_error(bad);
}

// A scratch folder with a FIFO, a dangling link and a folder named like a scenario.
const fs::path& scratch() {
  static const fs::path dir = [] {
    // A fresh folder per process (ctest runs each test case as its own process, in parallel).
    std::string pattern = (fs::temp_directory_path() / "spar_hostile_input_test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    const fs::path root(pattern);
    fs::create_directories(root / "folder.yaml");
    fs::create_symlink(root / "nowhere.yaml", root / "dangling.yaml");
    if (mkfifo((root / "fifo.yaml").c_str(), 0600) != 0) throw std::runtime_error("mkfifo");
    return root;
  }();
  return dir;
}

TEST(HostileScenario, PathsThatAreNotRegularFilesAreRefusedWithoutReading) {
  const std::vector<std::pair<fs::path, std::string>> cases = {
      {scratch() / "folder.yaml", "folder.yaml: is a directory, not a scenario file"},
      {scratch() / "fifo.yaml", "fifo.yaml: is not a regular file (a FIFO)"},
      {scratch() / "dangling.yaml", "dangling.yaml: is a symbolic link to '"},
      {"/dev/zero", "/dev/zero: is not a regular file (a character device)"},
  };
  for (const auto& [path, message] : cases) {
    EXPECT_THROW_MESSAGE(load_scenario(path), message);
    EXPECT_THROW_MESSAGE(load_domain(path), "");  // the same reader: refused too
  }
  EXPECT_THROW_MESSAGE(load_domain("/dev/zero"),
                       "/dev/zero: is not a regular file (a character device): give a domain file");
  EXPECT_THROW_MESSAGE(load_domain(scratch() / "fifo.yaml"),
                       "fifo.yaml: is not a regular file (a FIFO): give a domain file");
}

TEST(HostileScenario, AMeshOfImplausibleSizeForTheUnitLoadsWithAWarning) {
  const fs::path folder = scratch() / "units";
  fs::create_directories(folder);
  // A 0.1 m cube written in metres, read by an inch scenario: 2.54 mm across.
  std::ofstream(folder / "cube.off") << "OFF\n8 6 0\n0 0 0\n0.1 0 0\n0.1 0.1 0\n0 0.1 0\n"
                                        "0 0 0.1\n0.1 0 0.1\n0.1 0.1 0.1\n0 0.1 0.1\n"
                                        "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n"
                                        "4 2 3 7 6\n4 3 0 4 7\n";
  const std::string text =
      "units: {length: in}\nobjects:\n  cube: {mesh: cube.off, pose: {xyz: "
      "[20, 0, 0]}}\n";
  const Scenario scenario = parse_scenario(text, "cell.yaml", folder);
  ASSERT_EQ(scenario.warnings.size(), 1u);
  EXPECT_EQ(scenario.warnings[0].rfind("cell.yaml:3:16: objects.cube.mesh: the mesh is 0.1 in "
                                       "across (0.00254 m), implausibly small",
                                       0),
            0u)
      << scenario.warnings[0];
  EXPECT_NE(scenario.warnings[0].find("is the mesh in m?"), std::string::npos);
  // The same mesh in a metre scenario is plausible: no warning.
  const Scenario metres = parse_scenario(
      "objects:\n  cube: {mesh: cube.off, pose: {xyz: [0.5, 0, 0]}}\n", "cell.yaml", folder);
  EXPECT_TRUE(metres.warnings.empty());
}

// Property: a random number in any numeric key of the cell either loads, and then the value the
// scenario holds lies inside that key's limit, or is refused at that key's line and column.
struct NumericKey {
  std::string from, to_prefix;  // `from` is replaced by to_prefix + the number
  std::string limit;
  std::function<double(const Scenario&)> read;  // the loaded value, SI
};

RC_GTEST_PROP(HostileScenario, LoadedNumbersStayInsideTheTable, ()) {
  static const std::vector<NumericKey> keys = {
      {"max_opening: 4", "max_opening: ", "robot.gripper.max_opening",
       [](const Scenario& s) { return s.robot.gripper.max_opening; }},
      {"max_tilt: 60", "max_tilt: ", "robot.max_tilt",
       [](const Scenario& s) { return s.robot.max_tool_tilt; }},
      {"approach_step: 45", "approach_step: ", "grasping.approach_step",
       [](const Scenario& s) { return s.grasping.approach_step; }},
      {"positions_per_axis: 1", "positions_per_axis: ", "grasping.positions_per_axis",
       [](const Scenario& s) { return double(s.grasping.positions_per_axis); }},
      {"yaw: 0", "yaw: ", "pose.angle",
       [](const Scenario& s) {
         const auto& r = s.objects[0].initial_pose.linear();
         return std::atan2(r(1, 0), r(0, 0));  // within one turn: wrapped, checked below
       }},
      {"dx: 0.1", "dx: ", "uncertainty.length",
       [](const Scenario& s) { return s.objects[0].uncertainty.dx; }},
      {"dtheta: 2", "dtheta: ", "uncertainty.angle",
       [](const Scenario& s) { return s.objects[0].uncertainty.dtheta; }},
      {"at: [14, -8]", "at: [14, ", "pose.position",
       [](const Scenario& s) { return s.places[0].y; }},
  };
  const NumericKey& key = *rc::gen::elementOf(keys);
  const int exponent = *rc::gen::inRange(-320, 309);
  const double mantissa = *rc::gen::inRange(-9999, 9999) / 1000.0;
  const double value = mantissa * std::pow(10.0, exponent);
  std::string number = format_number(value);
  if (key.to_prefix.starts_with("at: [")) number += "]";
  const std::string text = cell_with(key.from, key.to_prefix + number);
  const std::string message = scenario_error(text);
  if (message.empty()) {
    const Scenario scenario = parse_scenario(text, "cell.yaml", ".");
    const NumericLimit& limit = numeric_limit(key.limit);
    if (key.limit != "pose.angle") RC_ASSERT(limit.contains(key.read(scenario)));
  } else {
    RC_ASSERT(message.rfind("cell.yaml:", 0) == 0u);
    RC_ASSERT(message.find(": must be ") != std::string::npos ||
              message.find("min_opening must be below max_opening") != std::string::npos);
  }
}

// ---- domain files ----

std::string domain_with(const std::string& operational) {
  return "actions:\n"
         "  - name: poke\n"
         "    parameters: {object: object, position: position(object)}\n"
         "    operational: [" +
         operational +
         "]\n"
         "    add: []\n"
         "    delete: []\n"
         "    effect: none\n";
}

TEST(HostileDomain, EachIsRefusedAtFileLineColumn) {
  const std::vector<Hostile> cases = {
      {"at() with one argument", domain_with("\"at(object)\""),
       "d.yaml:4:19: 'at(object)' has 1 argument(s), but at takes 2 (the planner's at(...))"},
      {"gripper() with two", domain_with("\"gripper(object, position)\""),
       "d.yaml:4:19: 'gripper(object, position)' has 2 argument(s), but gripper takes 1"},
      {"a predicate of the file's own used with two arities",
       domain_with("\"near(object)\", \"near(object, position)\""),
       "d.yaml:4:35: 'near(object, position)' has 2 argument(s), but near takes 1 (its first use "
       "at d.yaml:4:19)"},
      {"not UTF-8", domain_with("\"at(object, position)\"") + "# \xc3\x28\n",
       "d.yaml:8:3: invalid UTF-8 (byte 0xc3)"},
      {"a control character from an escape", domain_with("\"at(object,\\0position)\""),
       "d.yaml:4:19: operational atom 'at(object,\\0position)' holds a control character"},
      {"two documents", domain_with("") + "---\nactions: []\n",
       "d.yaml:8:1: a second YAML document (after '---')"},
      {"a stray comma", ",", "d.yaml:1:1: YAML syntax error: ',' cannot start a value"},
      {"a key that is not a name", "actions:\n  - {[a]: 1}\n",
       "d.yaml:2:6: a key of action must be a text"},
  };
  for (const Hostile& c : cases) {
    SCOPED_TRACE(c.name);
    std::string message;
    try {
      (void)parse_domain(c.text, "d.yaml");
    } catch (const DomainError& error) {
      message = error.what();
    }
    EXPECT_EQ(message.substr(0, c.message.size()), c.message) << message;
  }
  EXPECT_NO_THROW((void)parse_domain(domain_with("\"at(object, position)\""), "d.yaml"));
}

}  // namespace
}  // namespace spar::planner
