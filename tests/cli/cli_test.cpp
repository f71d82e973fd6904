// The `spar` command as a user meets it (issue 12): one table of command lines, each run as the
// built binary with its exit status, standard output and standard error checked. Every row is its
// own ctest case (CliCase/<name>).
//
// Rules every row obeys on top of its own patterns:
//   - the process exits by itself (no signal, no hang: a row has a time limit);
//   - exit status 1 comes with exactly one "spar: error: ..." line on stderr (a usage mistake, a
//     bad file, lost output), exit status 0 with an empty stderr.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "tests/cli/process.hpp"

namespace {

namespace fs = std::filesystem;

struct Case {
  std::string name;
  std::vector<std::string> args;  // after "spar"; @DIR@ is the scratch folder, @SRC@ the source
  int exit_status{0};
  std::string stdout_pattern;  // ECMAScript regex searched in stdout ("" = not checked)
  std::string stderr_pattern;  // searched in stderr ("" = not checked beyond the rules above)
  std::string stdout_to{};     // a file to send stdout to instead of capturing it ("/dev/full")
  int seconds{30};             // time limit
};

using spar::cli_test::Outcome;
using spar::cli_test::read_file;
using spar::cli_test::write_text;

// The scratch folder with the input files the rows use; made once per test binary.
const fs::path& scratch() {
  static const fs::path dir = [] {
    std::string pattern = (fs::temp_directory_path() / "spar-cli-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    const fs::path root(pattern);
    // JSONL batch: good, invalid UTF-8, wrong type, missing key, not an object, good.
    write_text(
        root / "batch.jsonl",
        "{\"name\":\"a\",\"expr\":\"x+1\",\"vars\":{\"x\":[0,1]}}\n"
        "{\"name\":\"b\xff\",\"expr\":\"x\",\"vars\":{\"x\":[0,1]}}\n"
        "{\"name\":\"c\",\"expr\":5,\"vars\":{\"x\":[0,1]}}\n"
        "{\"name\":\"d\",\"vars\":{\"x\":[0,1]}}\n"
        "[1,2]\n"
        "{\"name\":\"last\",\"expr\":\"x*y\",\"vars\":{\"x\":[0,1],\"y\":[\"1e-310\",2]}}\n");
    write_text(root / "good.jsonl", "{\"name\":\"a\",\"expr\":\"x+1\",\"vars\":{\"x\":[0,1]}}\n");
    // A variable-free expression that does not converge, then an ordinary record: the batch must
    // survive the first (it crashed the whole run).
    write_text(root / "constant.jsonl",
               "{\"name\":\"big\",\"expr\":\"exp(1000)\",\"vars\":{}}\n"
               "{\"name\":\"after\",\"expr\":\"x\",\"vars\":{\"x\":[0,1]}}\n");
    // One record summing 2000 variables (took > 300 s and 3.5 GB).
    std::string sum, vars;
    for (int i = 0; i < 2000; ++i) {
      sum += (i ? "+" : "") + std::string("x") + std::to_string(i);
      vars += (i ? "," : "") + std::string("\"x") + std::to_string(i) + "\":[0,1]";
    }
    write_text(root / "wide.jsonl",
               "{\"name\":\"wide\",\"expr\":\"" + sum + "\",\"vars\":{" + vars + "}}\n");
    // Two unit cubes overlapping in a 0.5 cube: volume 2 was reported for a solid of 1.875.
    std::string cubes = "OFF\n16 12 0\n";
    for (const double offset : {0.0, 0.5})
      for (int corner = 0; corner < 8; ++corner)
        cubes += std::to_string(offset + (corner & 1)) + ' ' +
                 std::to_string(offset + ((corner >> 1) & 1)) + ' ' +
                 std::to_string(offset + ((corner >> 2) & 1)) + '\n';
    for (const int base : {0, 8})
      for (const char* quad : {"0 2 3 1", "4 5 7 6", "0 1 5 4", "2 6 7 3", "0 4 6 2", "1 3 7 5"}) {
        std::istringstream corners(quad);
        cubes += "4";
        for (int c; corners >> c;) cubes += ' ' + std::to_string(base + c);
        cubes += '\n';
      }
    write_text(root / "overlap.off", cubes);
    write_text(root / "huge.off",
               "OFF\n4 4 0\n0 0 0\n1e300 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
    // A cube to be put at a place 5 m out, beyond the robot's reach: no plan (issue 21).
    write_text(root / "no_plan.yaml",
               "objects:\n  cube: {builtin: cube, pose: {stable: P1, at: [0.5, 0]}}\n"
               "places: [{name: far, at: [5, 0]}]\n"
               "goals: [{at: {object: cube, place: far}}]\n");
    fs::create_directory(root / "folder.off");
    write_text(root / "tetrahedron.off",
               "OFF\n4 4 0\n1 1 1\n1 -1 -1\n-1 1 -1\n-1 -1 1\n3 0 1 2\n3 0 3 1\n3 0 2 3\n"
               "3 1 3 2\n");
    // Image files for `spar vision match`: three edges that are nothing the sidewalk camera
    // expects, and an edge without its end.
    write_text(root / "clutter_only.json",
               R"({"edges": [{"id": 1, "p0": [10, 10], "p1": [200, 30]},
                             {"id": 2, "p0": [600, 400], "p1": [420, 300]},
                             {"id": 3, "p0": [100, 450], "p1": [110, 300]}]})");
    write_text(root / "bad_image.json", R"({"edges": [{"id": "a", "p0": [1, 2]}]})");
    write_text(root / "bad_mass.json",
               "{\"frame\": [\"a\", \"b\"],\n \"sources\": [[{\"set\": [\"a\"], \"mass\": 1.5}]]}");
    write_text(root / "conflict.json",
               "{\"frame\": [\"a\", \"b\"], \"sources\": [[{\"set\": [\"a\"], \"mass\": 1}],"
               " [{\"set\": [\"b\"], \"mass\": 1}]]}");
    // A scenario for the time limits (issue 22).
    fs::create_directory(root / "batch");
    write_text(root / "batch" / "a_good.yaml",
               read_file(fs::path(SPAR_SOURCE_DIR) / "examples" / "peg_block_face_up.yaml"));
    write_text(root / "one.txt", "batch/a_good.yaml\n");
    return root;
  }();
  return dir;
}

// Removes the scratch folder when the test binary ends.
class RemoveScratch : public testing::Environment {
 public:
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(scratch(), ignored);
  }
};
[[maybe_unused]] testing::Environment* const kRemoveScratch =
    testing::AddGlobalTestEnvironment(new RemoveScratch);

std::string expand(std::string text) {
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"@DIR@", scratch().string()},
                                   std::pair<std::string, std::string>{"@SRC@", SPAR_SOURCE_DIR}}) {
    for (auto at = text.find(key); at != std::string::npos; at = text.find(key, at)) {
      text.replace(at, key.size(), value);
    }
  }
  return text;
}

// Runs spar with `args`, stdin from /dev/null, stdout and stderr to files (or stdout to
// `stdout_to`); kills it after `seconds`.
Outcome run_spar(const Case& row, const std::string& label) {
  const fs::path out_path = scratch() / (label + ".out"), err_path = scratch() / (label + ".err");
  const std::string stdout_file = row.stdout_to.empty() ? out_path.string() : row.stdout_to;
  std::vector<std::string> arguments{SPAR_BINARY};
  for (const std::string& arg : row.args) arguments.push_back(expand(arg));
  Outcome outcome =
      spar::cli_test::run_process(arguments, stdout_file, err_path.string(), row.seconds);
  if (row.stdout_to.empty()) outcome.out = read_file(out_path);
  outcome.err = read_file(err_path);
  return outcome;
}

// Everything wrong with `outcome` for `row`, one line each ("" when the row holds).
std::string problems(const Case& row, const Outcome& outcome) {
  std::ostringstream wrong;
  if (outcome.exit_status != row.exit_status) {
    wrong << "exit status " << outcome.exit_status << " (" << outcome.what << "), expected "
          << row.exit_status << '\n';
  }
  static const std::regex one_error_line("spar: error: [^\n]*\n");
  if (row.exit_status == 1 && !std::regex_match(outcome.err, one_error_line)) {
    wrong << "stderr is not one 'spar: error: ...' line\n";
  }
  if (row.exit_status == 0 && !outcome.err.empty()) wrong << "stderr is not empty\n";
  if (!row.stdout_pattern.empty() &&
      !std::regex_search(outcome.out, std::regex(row.stdout_pattern))) {
    wrong << "stdout does not match /" << row.stdout_pattern << "/\n";
  }
  if (!row.stderr_pattern.empty() &&
      !std::regex_search(outcome.err, std::regex(row.stderr_pattern))) {
    wrong << "stderr does not match /" << row.stderr_pattern << "/\n";
  }
  return wrong.str();
}

// gtest prints a failing row by its name, not its bytes.
void PrintTo(const Case& row, std::ostream* out) { *out << row.name; }

class CliCase : public testing::TestWithParam<Case> {};

TEST_P(CliCase, ExitStatusAndMessages) {
  const Case& row = GetParam();
  const Outcome outcome = run_spar(row, row.name);
  const std::string wrong = problems(row, outcome);
  if (wrong.empty()) return;
  std::string command = "spar";
  for (const std::string& arg : row.args) command += " '" + expand(arg) + "'";
  const std::string report = command + "\n" + wrong + "--- stdout (first 600 bytes)\n" +
                             outcome.out.substr(0, 600) + "\n--- stderr\n" +
                             outcome.err.substr(0, 600);
  ADD_FAILURE() << report;
}

constexpr int kError = 1;
const std::string kFull = "/dev/full";
const std::string kLost = "cannot write the output to standard output: No space left on device";
const std::string kSidewalk = "@SRC@/examples/vision/pseiki_sidewalk.yaml";
const std::string kSidewalkImage = "@SRC@/examples/vision/pseiki_sidewalk_image.json";
const std::string kPose =
    "1 0 0 0.5 0 -1 0 0.1 0 0 -1 0.2 0 0 0 1";  // a flange pose spar ik solves

// Columns: name, arguments, exit status, stdout pattern, stderr pattern[, stdout file[,
// seconds]]. One row per line where it fits, so the table reads as a table.
// clang-format off
const std::vector<Case> kCases = {
  // A leading unary minus is an expression, not an option.
  {"SimplifyLeadingMinus", {"simplify", "-x"}, 0, "^-x\n$", ""},
  {"SimplifyLeadingMinusCall", {"simplify", "-sin(x)*2"}, 0, "^-2\\*sin\\(x\\)\n$", ""},
  {"BoundLeadingMinus", {"bound", "-x", "--var", "x=0:1"}, 0, "range +\\[-1, -?0\\]", ""},
  {"BoundConstraintLeadingMinus", {"bound", "x", "--var", "x=0:1", "--constraint", "-x<=-0.5"},
   0, "range +\\[0.5, 1\\]", ""},
  // CLI11 reads "-(" and "-." as short options too; a report's expressions start with "-(".
  {"SimplifyLeadingMinusGroup", {"simplify", "-(x)"}, 0, "^-x\n$", ""},
  {"BoundLeadingMinusGroup", {"bound", "-(x+1)", "--var", "x=0:1"}, 0, "range +\\[-2, -1\\]", ""},
  {"BoundConstraintLeadingMinusGroup",
   {"bound", "x", "--var", "x=0:1", "--constraint", "-(x)<=-0.5"}, 0, "range +\\[0.5, 1\\]", ""},
  {"SimplifyLeadingMinusNumber", {"simplify", "-2*x"}, 0, "^-2\\*x\n$", ""},
  // Far out, sin is evaluated at its true phase (issue 22: "attained [0, 0]" for 0.858...).
  {"BoundHugeSinAttained", {"bound", "sin(x)", "--var", "x=1e15:1e15"}, 0,
   "attained \\[0.85827279317", ""},
  // No attained range: null and why (was inner_lo "inf" > inner_hi "-inf").
  {"BoundInfeasibleInnerIsNull",
   {"bound", "x", "--var", "x=0:1", "--constraint", "x>=2", "--json"}, 0,
   "\"inner_lo\": null,\n  \"inner_hi\": null,\n  \"no_inner_range\": \"no point of the box "
   "satisfies the constraints", ""},
  {"BoundAfterDoubleDash", {"bound", "--var", "x=0:1", "--", "-x"}, 0, "range +\\[-1, -?0\\]", ""},
  // --var: one value per occurrence, repeatable, in any order.
  {"VarBeforeExpression", {"bound", "--var", "x=0:1", "x"}, 0, "range +\\[0, 1\\]", ""},
  {"VarsAroundExpression", {"bound", "--var", "y=0:1", "x+y", "--var", "x=0:2"}, 0,
   "range +\\[0, 3\\]", ""},
  // Numbers: what spar prints is read back; messages print enough digits.
  {"SubnormalBound", {"bound", "x", "--var", "x=1e-310:1"}, 0, "range +\\[[0-9.e-]+, 1\\]", ""},
  {"EmptyRangeDigits", {"bound", "x", "--var", "x=2e-9:1e-9"}, kError, "",
   "lower bound 2e-09 > upper bound 1e-09"},
  {"OverflowBound", {"bound", "x", "--var", "x=0:1e400"}, kError, "",
   "--var x: upper bound: '1e400' is outside the range of double precision numbers"},
  {"RealExponent", {"bound", "x^pi", "--var", "x=1:2"}, 0, "range +\\[(1|0.9999[0-9]*), 8.82", ""},
  {"SeventeenDigitExponent", {"bound", "x^3.1415926535897931", "--var", "x=1:2"}, 0,
   "range +\\[(1|0.9999[0-9]*), 8.82", ""},
  // NaN, negative, zero and overflow are refused for every numeric option, in words.
  {"TolNaN", {"bound", "x", "--var", "x=0:1", "--tol", "nan"}, kError, "",
   "--tol: must be a number >= 0, got 'nan'"},
  {"MaxEvalsNegative", {"bound", "x", "--var", "x=0:1", "--max-evals", "-1"}, kError, "",
   "--max-evals: must be a whole number from 1 to"},
  {"MaxTiltNaN", {"ik", "--pose", kPose, "--max-tilt-deg", "nan"}, kError, "",
   "--max-tilt-deg: must be a number from 0 to 180, got 'nan'"},
  {"JointAngleInfinite", {"fk", "--q", "0 0 0 0 0 inf"}, kError, "",
   "--q: must be a finite number, got 'inf'"},
  {"MaxOpeningNaN", {"object", "cube", "--max-opening", "nan"}, kError, "",
   "--max-opening: must be a positive number, got 'nan'"},
  {"DemoFormatWritesThatFormat", {"demo", "--format", "md", "--report", "@DIR@/demo"}, 0,
   "\nreport: [^\n]*/demo/report.md\n$", ""},
  {"PlanFormatWithoutReport",
   {"plan", "@SRC@/examples/peg_block_face_up.yaml", "--format", "md"}, kError, "",
   "^spar: error: --format needs --report DIR\n$"},
  // Issue 21's examples plan and render their reports.
  {"PlanFixtureExampleReports", {"plan", "@SRC@/examples/fixture_two_pins.yaml", "--samples", "0",
   "--report", "@DIR@/fixture"}, 0, "planned", ""},
  {"PlanStackExampleReports", {"plan", "@SRC@/examples/stack_in_tray.yaml", "--samples", "0",
   "--report", "@DIR@/stack"}, 0, "planned", ""},
  {"PlanCrowdedExampleReports", {"plan", "@SRC@/examples/crowded_table.yaml", "--samples", "0",
   "--instances", "2", "--report", "@DIR@/crowded"}, 0, "planned", ""},
  // Issue 27's camera example: the verification names what PSEIKI must see.
  {"PlanCameraExampleNamesWhatPseikiMustSee",
   {"plan", "@SRC@/examples/peg_block_on_back_camera.yaml", "--samples", "0"}, 3,
   "camera overhead must see peg/e[0-9]+(, peg/e[0-9]+)* \\(PSEIKI accepts", ""},
  // A camera with a residual verifies where a range scanner would scan (docs/vision.md).
  {"PlanCameraVerifyExampleProvesTheInsertion",
   {"plan", "@SRC@/examples/peg_block_camera_verify.yaml", "--samples", "0", "--report",
    "@DIR@/camera-verify", "--format", "html"},
   0, "camera-verify block.*camera-verify peg", ""},
  // No plan is a result, not a success: the report says why, the exit status is 2.
  {"PlanUnreachablePlaceNoPlan", {"plan", "@DIR@/no_plan.yaml", "--json", "--samples", "0"}, 2,
   "\"status\": \"no_plan\",\\s*\"reason\": \"no_plan: .*goal at\\(cube, far\\)", ""},
  // spar plan's exit status says its verdict: 0 proved, 2 no plan, 3 errors left to verify.
  {"PlanProvedExitsZero",
   {"plan", "@SRC@/examples/peg_block_face_up.yaml", "--samples", "0", "--report", "@DIR@/up"}, 0,
   "errors: 0 \\(nothing to verify at execution\\)", ""},
  {"PlanNoPlanExitsTwo",
   {"plan", "@SRC@/examples/peg_block_face_down.yaml", "--max-nodes", "3", "--report",
    "@DIR@/np"},
   2, "^plan peg_block_face_down: no_plan \\(", "^$"},
  {"PlanWithErrorsExitsThree",
   {"plan", "@SRC@/examples/peg_block_on_back.yaml", "--samples", "0", "--report", "@DIR@/ob"}, 3,
   "errors: 1 \\(verification and recovery posted\\)", "^$"},
  {"Version", {"--version"}, 0, "^[0-9]+\\.[0-9]+\\.[0-9]+\n$", ""},
  {"HelpNamesTheExitStatuses", {"plan", "--help"}, 0,
   "Exit status: 0 planned, every precondition proved; 1 bad input or usage; 2 no plan; 3", ""},
  {"PlanInstancesZero", {"plan", "@SRC@/examples/peg_block_face_up.yaml", "--instances", "0"},
   kError, "", "--instances: must be a whole number from 1 to 100000, got '0'"},
  {"PlanSamplesNegative", {"plan", "@SRC@/examples/peg_block_face_up.yaml", "--samples", "-1"},
   kError, "", "--samples: must be a whole number from 0 to 100000000, got '-1'"},
  {"PlanSamplesReachTheReport",
   {"plan", "@SRC@/examples/peg_block_on_back.yaml", "--json", "--samples", "1000"}, 3,
   "\"probability\": \\{[^}]*\\}[^}]*\"samples\": 1000", ""},
  // Every precondition proved: the plan's P is 0 exactly and a tenth of the points check that.
  {"PlanSamplesATenthWhenEveryPreconditionIsProved",
   {"plan", "@SRC@/examples/peg_block_face_up.yaml", "--json", "--samples", "1000"}, 0,
   "\"probability\": \\{[^}]*\\}[^}]*\"samples\": 100,", ""},
  {"QrBudgetZero", {"qr", "match-strike", "--budget", "0"}, kError, "",
   "^spar: error: --budget: must be a whole number from 1 to 10000, got '0'\n$"},
  {"QrSeedNegative", {"qr", "match-strike", "--seed", "-1"}, kError, "",
   "--seed: must be a whole number from 0 to 18446744073709551615, got '-1'"},
  {"QrSeedTwoToThe64", {"qr", "match-strike", "--seed", "18446744073709551616"}, kError, "",
   "--seed: must be a whole number from 0 to 18446744073709551615"},
  {"QrSeedLargest", {"qr", "match-strike", "--seed", "18446744073709551615"}, 0, "status: ", ""},
  // Options that would make the work unbounded are capped with a clear error.
  {"ApproachStepTiny", {"object", "cube", "--approach-step", "1e-9"}, kError, "",
   "--approach-step: must be an angle >= 1 and <= 360 deg \\(each step is one more grasp per "
   "contact position\\), got 1e-09 deg"},
  {"PositionsHuge", {"object", "cube", "--positions", "100000"}, kError, "",
   "--positions: must be a whole number >= 1 and <= 20 \\(a face pair gets the square of it as "
   "contact positions\\), got 100000"},
  {"MaxOpeningHuge", {"object", "cube", "--max-opening", "1e308", "--units", "in"}, kError, "",
   "--max-opening: must be a length > 0 and <= 78.7402 in \\(the widest parallel gripper spar "
   "models\\), got 1e\\+308 in"},
  {"PlanUnknownFormat",
   {"plan", "@SRC@/examples/peg_block_face_up.yaml", "--report", "@DIR@/r", "--format", "pdf"},
   kError, "", "unknown report format 'pdf'"},
  // JSONL batches: a bad line is an error record with its line number; the batch goes on.
  {"JsonlBadLinesAreRecords", {"bound", "--jsonl", "@DIR@/batch.jsonl"}, kError,
   "\\{\"line\":2,\"name\":\"[^\n]*\"error\":\"\\[json.exception.parse_error.101\\][^\n]*\n"
   "\\{\"line\":3,\"name\":\"c\",\"error\":\"\\\\\"expr\\\\\" must be a string\"\\}\n"
   "\\{\"line\":4,\"name\":\"d\",\"error\":\"missing \\\\\"expr\\\\\" string\"\\}\n"
   "\\{\"line\":5,\"name\":\"\",\"error\":\"a record must be a JSON object\"\\}\n"
   "\\{\"name\":\"last\",\"lo\"",
   "4 line\\(s\\) of '[^']*batch.jsonl' could not be bounded"},
  {"JsonlDirectory", {"bound", "--jsonl", "@DIR@"}, kError, "", "is a directory"},
  // Scenario batches (issue 22; tests/cli/batch_test.cpp has the rest).
  {"BatchTimeLimitIsARecord", {"plan", "--batch", "@DIR@/one.txt", "--time-limit", "0.001"},
   kError,
   "^\\{\"file\":\"[^\"]*a_good.yaml\",\"status\":\"time_limit\",\"error\":\"time limit of "
   "0.001 s reached\"\\}\n$",
   "1 of 1 scenarios failed"},
  {"PlanTimeLimit", {"plan", "@DIR@/batch/a_good.yaml", "--time-limit", "0.001"}, kError, "",
   "^spar: error: time limit of 0.001 s reached\n$"},
  {"BatchNotAListNorAFolder", {"plan", "--batch", "/dev/zero"}, kError, "",
   "--batch: /dev/zero: is not a regular file \\(a character device\\): give a batch list"},
  {"JsonlWithExpression", {"bound", "x+1", "--var", "x=0:1", "--jsonl", "@DIR@/good.jsonl"},
   kError, "", "cannot be combined with an expression"},
  {"JsonlConstantDoesNotKillTheBatch", {"bound", "--jsonl", "@DIR@/constant.jsonl"}, 0,
   "\"name\":\"big\"[^\n]*\n[^\n]*\"name\":\"after\"", ""},
  {"JsonlTwoThousandVariables", {"bound", "--jsonl", "@DIR@/wide.jsonl"}, 0, "\"name\":\"wide\"",
   "", "", 60},
  // Crashes and hangs of the issue: each exits by itself with an answer.
  {"ExpThousand", {"bound", "exp(1000)"}, 0, "range +\\[1.79769[0-9.e+]*, inf\\]", ""},
  {"UnderflowingConstant", {"bound", "1e-400"}, 0, "range", ""},
  {"TanOfHalfPi", {"bound", "tan(pi/2)"}, 0, "range +\\[-inf, inf\\][^\n]*\nattained none", ""},
  {"TripleExp", {"bound", "exp(exp(exp(10)))", "--json"}, 0, "\"hi\": \"inf\"", ""},
  {"HugeIntegerPowerKeepsParity", {"bound", "x^2000000000", "--var", "x=-1.0000001:-1"}, 0,
   "range +\\[1, ", ""},
  {"LogTimesZeroStaysUndefined", {"bound", "0*log(x)", "--var", "x=-2:-1"}, 0, "infeasible", ""},
  {"XOverXPossiblyUndefined", {"bound", "x/x", "--var", "x=-1:1"}, 0, "possibly undefined", ""},
  {"AttainedInOrder", {"bound", "exp(1)"}, 0, "attained \\[2.718281828459045[0-9]*, 2.71828", ""},
  {"NonAsciiIdentifier", {"bound", "x\u00b2", "--var", "x=0:1"}, kError, "", "non-ASCII"},
  {"DeepParentheses", {"simplify", std::string(10000, '(') + "x" + std::string(10000, ')')}, 0,
   "^x\n$", ""},
  // Meshes.
  {"MeshDirectory", {"object", "@DIR@/folder.off"}, kError, "", "is a directory"},
  {"MeshHugeCoordinate", {"object", "@DIR@/huge.off"}, kError, "",
   "huge.off:4: coordinate '1e300' is too large"},
  {"MeshSelfIntersecting", {"object", "@DIR@/overlap.off"}, kError, "",
   "overlap.off:[0-9]+: the mesh intersects itself"},
  {"MeshFromExamples", {"object", "@SRC@/examples/objects/block.off", "--json"}, 0,
   "\"stable_poses\"", ""},
  // Dempster-Shafer evidence.
  {"Evidence", {"evidence", "@SRC@/examples/evidence_identity.json"}, 0,
   "conflict K = 0.322\n[^]*cube +0.728614 +0.825959 +0.775811", ""},
  {"EvidenceJson", {"evidence", "@SRC@/examples/evidence_identity.json", "--json"}, 0,
   "\"pignistic\": \\{[^]*\"ambiguity\": 0.9694551", ""},
  {"EvidenceMissing", {"evidence", "@DIR@/none.json"}, kError, "",
   "none.json: cannot read the evidence file: no such file"},
  {"EvidenceBadMass", {"evidence", "@DIR@/bad_mass.json"}, kError, "",
   "bad_mass.json: sources\\[0\\]\\[0\\].mass: must be a number in \\[0, 1\\], got 1.5"},
  {"EvidenceTotalConflict", {"evidence", "@DIR@/conflict.json"}, kError, "", "total conflict"},
  // Aspects.
  {"AspectsCube", {"aspects", "cube"}, 0, "^object cube: 26 aspects \\(exact arrangement\\)", ""},
  {"AspectsTetrahedronJson", {"aspects", "@DIR@/tetrahedron.off", "--json"}, 0,
   "\"method\": \"exact arrangement\"[^]*\"label\": \"A14\"", ""},
  {"AspectsBlock", {"aspects", "@SRC@/examples/objects/block.off", "--units", "in"}, 0,
   "aspects \\(view sphere, 1280 view directions", ""},
  {"AspectsMaxAngleZero", {"aspects", "cube", "--max-angle", "0"}, kError, "",
   "--max-angle: must be a number > 0 and <= 90, got '0'"},
  {"AspectsUnknown", {"aspects", "teapot"}, kError, "", "teapot: no such file, nor a built-in"},
  // Sense planning.
  {"SensePlan", {"sense-plan", "@SRC@/examples/sensing_block_pose.yaml"}, 0,
   "\n1\\. range_scan at V[0-9]+ \\(aspect A[0-9]+\\): at most [0-9.e-]+ bits \\(worst case P[12]\\)",
   ""},
  {"SensePlanJson", {"sense-plan", "@SRC@/examples/sensing_block_pose.yaml", "--json"}, 0,
   "\"sequence\": \\[\n +\\{\n +\"sensor\": \"range_scan\",\n +\"viewpoint\": \"V[0-9]+\"",
   ""},
  {"SensePlanNothingUncertain", {"sense-plan", "@SRC@/examples/peg_block_face_up.yaml"}, 0,
   "nothing to sense", ""},
  // PSEIKI verification vision (issue 27) on the survey's sidewalk example.
  {"VisionRender", {"vision", "render", kSidewalk, "--camera", "front", "--json"}, 0,
   "\"edges\": \\[\n *\\{\n *\"id\": \"walk/e1\",\n *\"object\": \"walk\",\n *\"faces\": "
   "\\[\n *\"walk/f1\"\n *\\],\n *\"p0\": \\[", ""},
  {"VisionMatch", {"vision", "match", kSidewalk, "--camera", "front", "--image", kSidewalkImage,
                   "--json"}, 0,
   "\"scene\": \\{\n *\"belief\": 0.809[0-9]*,\n *\"disbelief\": [0-9.e-]+,\n *\"accepted\": "
   "true[^]*\"pose_correction\": \\{\n *\"object\": \"front\"", ""},
  {"VisionMatchText", {"vision", "match", kSidewalk, "--camera", "front", "--image",
                       kSidewalkImage}, 0,
   "^scene belief 0.81 \\(threshold 0.50\\): accepted\n", ""},
  {"VisionMatchRejects", {"vision", "match", kSidewalk, "--camera", "front", "--image",
                          "@DIR@/clutter_only.json"}, 0,
   "^scene belief 0.00 \\(threshold 0.50\\): rejected\n", ""},
  {"VisionSimulate", {"vision", "simulate", kSidewalk, "--camera", "front", "--seed", "3",
                      "--perturb", "split=0.1,clutter=5"}, 0,
   // No [^]* across the whole output: libstdc++'s regex recurses once per character and
   // overflows the stack under AddressSanitizer on these ~100 KB.
   "\n *\"truth\": \"walk/e[0-9]+\"\n", ""},
  // One camera description for both: the sense-planning example's overhead camera in PSEIKI.
  {"VisionRenderSensingCamera", {"vision", "render", "@SRC@/examples/sensing_block_pose.yaml",
                                 "--camera", "overhead"}, 0,
   "^expected scene of camera overhead: [1-9][0-9]* edges", ""},
  {"VisionUnknownCamera", {"vision", "render", kSidewalk, "--camera", "back"}, kError, "",
   "scenario 'pseiki_sidewalk' has no camera 'back' \\(cameras: front\\)"},
  {"VisionImageMissing", {"vision", "match", kSidewalk, "--camera", "front", "--image",
                          "@DIR@/none.json"}, kError, "",
   "none.json: cannot read the image file: no such file"},
  {"VisionImageBadEdge", {"vision", "match", kSidewalk, "--camera", "front", "--image",
                          "@DIR@/bad_image.json"}, kError, "",
   "bad_image.json: edges\\[0\\]: missing key 'p1'"},
  {"VisionPerturbUnknownKey", {"vision", "simulate", kSidewalk, "--camera", "front", "--perturb",
                               "shade=1"}, kError, "", "--perturb: unknown key 'shade'"},
  {"VisionRenderFull", {"vision", "render", kSidewalk, "--camera", "front"}, kError, "", kLost,
   kFull},
  // Output that cannot be written fails the command.
  {"SimplifyFull", {"simplify", "x+x"}, kError, "", kLost, kFull},
  {"BoundFull", {"bound", "x", "--var", "x=0:1"}, kError, "", kLost, kFull},
  {"BoundJsonlFull", {"bound", "--jsonl", "@DIR@/good.jsonl"}, kError, "", kLost, kFull},
  {"FkFull", {"fk", "--q", "0 0 0 0 0 0"}, kError, "", kLost, kFull},
  {"IkFull", {"ik", "--pose", kPose}, kError, "", kLost, kFull},
  {"QrFull", {"qr", "match-strike"}, kError, "", kLost, kFull},
  {"ObjectFull", {"object", "cube"}, kError, "", kLost, kFull},
  {"DemoFull", {"demo"}, kError, "", kLost, kFull},
  {"WriteOffFull", {"object", "cube", "--write-off", "/dev/full"}, kError, "",
   "cannot write the mesh to '/dev/full': No space left on device"},
  {"SvgFull", {"qr", "match-strike", "--svg", "/dev/full"}, kError, "",
   "cannot write the SVG to '/dev/full': No space left on device"},
  // Usage mistakes are one line.
  {"UnknownOption", {"bound", "x", "--vars", "x=0:1"}, kError, "", "^spar: error: "},
  {"MissingExpression", {"bound"}, kError, "", "give an expression or --jsonl FILE"},
  {"UnknownObject", {"object", "sphere"}, kError, "", "no such file, nor a built-in object"},
  {"UnknownRobot", {"fk", "--robot", "puma999", "--q", "0 0 0 0 0 0"}, kError, "",
   "--robot: unknown robot 'puma999' \\(built-in: puma560, puma762, ur5, panda; or a URDF "
   "file\\)"},
  {"PlanReportEmpty", {"plan", "@SRC@/examples/peg_block_face_up.yaml", "--report", ""}, kError,
   "", "--report: give a folder name, not ''"},
  {"UnknownVariable", {"bound", "x+y", "--var", "x=0:1"}, kError, "",
   "unknown variable 'y' in the expression: give it a range"},
};
// clang-format on

// Every expression spar prints is accepted back as a positional argument (issue 22: the
// pickup/assembly expressions of a report all start with "-(" and were refused as options).
TEST(CliReadsBack, ReportExpressionsStartingWithMinus) {
  const std::string report =
      read_file(fs::path(SPAR_SOURCE_DIR) / "tests/reports/golden" / "peg_block_face_up.json");
  static const std::regex expression("\"expression\": \"(-[^\"]*)\"");
  std::smatch found;
  ASSERT_TRUE(std::regex_search(report, found, expression)) << "no expression starting with -";
  const Case row{"ReportExpression", {"simplify", found[1].str()}, 0, "dtheta", ""};
  const std::string wrong = problems(row, run_spar(row, row.name));
  EXPECT_EQ(wrong, "") << found[1].str();
}

INSTANTIATE_TEST_SUITE_P(Spar, CliCase, testing::ValuesIn(kCases),
                         [](const testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
