// The report's JSON against docs/report-schema.md, both ways: every report the examples produce
// validates against the document's JSON Schema (so every field produced is documented: the schema
// refuses undocumented members), the document's field table lists exactly the schema's fields,
// and every field the schema declares is produced by some example.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "tests/reports/example_reports.hpp"
#include "tests/reports/json_schema.hpp"

namespace spar::reports::testing {
namespace {

std::string schema_document() {
  std::ifstream in(std::string(SPAR_SOURCE_DIR) + "/docs/report-schema.md");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

JsonSchema document_schema() {
  const std::string document = schema_document();
  const std::size_t heading = document.find("## JSON Schema");
  const std::size_t start = document.find("```json\n", heading);
  const std::size_t end = document.find("\n```", start + 8);
  if (heading == std::string::npos || start == std::string::npos || end == std::string::npos)
    throw std::runtime_error("docs/report-schema.md has no ```json block under ## JSON Schema");
  return JsonSchema(nlohmann::json::parse(document.substr(start + 8, end - start - 8)));
}

// The first column of the "## Fields" table: `path` cells.
std::set<std::string> documented_fields() {
  const std::string document = schema_document();
  const std::size_t begin = document.find("## Fields");
  const std::size_t end = document.find("## JSON Schema");
  std::set<std::string> fields;
  const std::regex row(R"(^\| `([^`]+)` \|)");
  std::istringstream lines(document.substr(begin, end - begin));
  for (std::string line; std::getline(lines, line);) {
    std::smatch match;
    if (std::regex_search(line, match, row)) fields.insert(match[1]);
  }
  return fields;
}

// Every example's preconditions have an attained range, so none writes no_inner_range: the writer's
// form of a face-up report whose first precondition has none (what build_report makes when the
// bounds give no witness enclosure), so the schema's field is checked as written.
const nlohmann::ordered_json& no_inner_range_report() {
  static const nlohmann::ordered_json document = [] {
    Report report = golden_report("peg_block_face_up");
    const auto step = std::ranges::find_if(report.chosen->steps, [](const Step& s) {
      return s.preconditions && !s.preconditions->empty();
    });
    Precondition& precondition = step->preconditions->front();
    precondition.inner_lo.reset();
    precondition.inner_hi.reset();
    precondition.no_inner_range = "no witness";
    return to_json(report);
  }();
  return document;
}

std::vector<const nlohmann::ordered_json*> all_reports() {
  std::vector<const nlohmann::ordered_json*> reports;
  // The on-back task with a camera (issue 27: the verification's vision) stands for the plain one:
  // the same report plus that member, for one planning less.
  for (const std::string& name : example_names())
    reports.push_back(name == "peg_block_on_back" ? &camera_report() : &example_report(name));
  reports.push_back(&no_plan_report());
  reports.push_back(&sensing_report());
  // A robot read from a URDF file (issue 23): robot.urdf, base_link, tip and joint_names.
  reports.push_back(&example_report("panda_peg_block"));
  // Camera verification spliced in by phase 2 (issue 27): the step's vision.
  reports.push_back(&example_report("peg_block_camera_verify"));
  reports.push_back(&no_inner_range_report());
  return reports;
}

// One test for both directions: the reports are planned once per test process, and planning them
// is nearly all of its time (a minute under the sanitizers).
TEST(ReportSchema, EveryReportValidatesAndEveryDocumentedFieldIsProduced) {
  const JsonSchema schema = document_schema();
  std::set<std::string> produced;
  for (const nlohmann::ordered_json* report : all_reports()) {
    const std::vector<std::string> errors = schema.validate(*report, produced);
    EXPECT_TRUE(errors.empty()) << (*report)["scenario"] << ": " << errors.size()
                                << " violations, first: " << errors.front();
  }
  for (const std::string& field : schema.paths())
    EXPECT_TRUE(produced.contains(field)) << field << " is documented but no example produces it";
}

TEST(ReportSchema, FieldTableListsExactlyTheSchemaFields) {
  const std::set<std::string> table = documented_fields(), schema = document_schema().paths();
  for (const std::string& field : schema)
    EXPECT_TRUE(table.contains(field)) << field << " is in the JSON Schema but not in the table";
  for (const std::string& field : table)
    EXPECT_TRUE(schema.contains(field)) << field << " is in the table but not in the JSON Schema";
  EXPECT_GT(table.size(), 100u);
}

TEST(ReportSchema, AnUndocumentedFieldIsRefused) {
  nlohmann::ordered_json report = example_report("peg_block_face_up");
  report["chosen"]["steps"][0]["colour"] = "red";
  std::set<std::string> seen;
  const std::vector<std::string> errors = document_schema().validate(report, seen);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0], "chosen.steps[]: undocumented member colour");
}

TEST(ReportSchema, AMistypedFieldIsRefused) {
  nlohmann::ordered_json report = example_report("peg_block_face_up");
  report["chosen"]["steps"][0]["preconditions"] = nlohmann::ordered_json::array({{{"lo", 1}}});
  std::set<std::string> seen;
  const std::vector<std::string> errors = document_schema().validate(report, seen);
  EXPECT_FALSE(errors.empty());
}

TEST(ReportSchema, SchemaVersionIsFirst) {
  const nlohmann::ordered_json& report = example_report("peg_block_face_down");
  EXPECT_EQ(report.begin().key(), "schema");
  EXPECT_EQ(report["schema"], kReportSchema);
}

}  // namespace
}  // namespace spar::reports::testing
