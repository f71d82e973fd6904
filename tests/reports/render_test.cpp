// The Markdown and HTML renderers (from the JSON only), the report writer, the graph layouts and
// the planner's thread safety that `spar plan --batch` relies on.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <regex>

#include "spar/reports/error.hpp"
#include "spar/reports/html.hpp"
#include "spar/reports/internal/layout.hpp"
#include "spar/reports/internal/text.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/markdown.hpp"
#include "spar/reports/write.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/reports/example_reports.hpp"

namespace spar::reports::testing {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::size_t precondition_count(const Json& report) {
  std::size_t n = 0;
  for (const Json& step : report["chosen"]["steps"]) n += step["preconditions"].size();
  return n;
}

TEST(Rounded, KeepsSignificantDigitsAndDropsTrailingZeros) {
  EXPECT_EQ(internal::rounded(0.0023999), "0.0024");
  EXPECT_EQ(internal::rounded(2.0), "2");
  EXPECT_EQ(internal::rounded(-0.30479999999999990), "-0.305");
  EXPECT_EQ(internal::rounded(1234.56), "1235");
  EXPECT_EQ(internal::rounded(-1e-30), "0");           // below the 15 decimals shown
  EXPECT_EQ(internal::rounded(9999999.0), "9999999");  // below 1e7: fixed
  EXPECT_EQ(internal::rounded(12345678.0), "1.23e+07");
  EXPECT_EQ(internal::rounded(-2.54e306), "-2.54e+306");  // all of it, not 63 truncated digits
  EXPECT_EQ(internal::rounded(HUGE_VAL), "inf");
}

TEST(Markdown, HasOneTableRowPerPreconditionInTheScenarioUnit) {
  const Json& report = example_report("peg_block_face_down");
  const std::string markdown = render_markdown(report);
  const std::string preconditions =
      markdown.substr(markdown.find("## Preconditions"),
                      markdown.find("## Inserted") - markdown.find("## Preconditions"));
  EXPECT_EQ(count(preconditions, "\n| ") - 1, precondition_count(report));  // minus the header
  EXPECT_NE(preconditions.find("] in |"), std::string::npos);
  EXPECT_NE(markdown.find("range-scan block *(inserted)*"), std::string::npos);
}

TEST(Markdown, FailedStepShowsVerificationAndRecovery) {
  const Json& report = example_report("peg_block_on_back");
  ASSERT_GT(report["chosen"]["errors"].get<int>(), 0);
  const std::string markdown = render_markdown(report);
  const std::string section = markdown.substr(markdown.find("## Verification and recovery"));
  EXPECT_NE(section.find("- verify: "), std::string::npos);
  EXPECT_NE(section.find("recovery `"), std::string::npos);
  EXPECT_NE(summary(report_from_json(report)).find("errors: 1"), std::string::npos);
}

TEST(Markdown, NoPlanGivesTheReason) {
  const std::string markdown = render_markdown(no_plan_report());
  EXPECT_NE(markdown.find("no_plan ("), std::string::npos);
  EXPECT_EQ(markdown.find("## Preconditions"), std::string::npos);
}

TEST(Html, IsSelfContained) {
  const std::string html = render_html(example_report("peg_block_face_down"));
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  EXPECT_EQ(html.find("url(http"), std::string::npos);
  // The only address is the SVG namespace, which is a name, not a request.
  const std::regex address("https?://[^\"]*");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), address);
       it != std::sregex_iterator(); ++it)
    EXPECT_EQ(it->str(), "http://www.w3.org/2000/svg");
}

TEST(Html, OneRowAndOneBarPerPrecondition) {
  for (const std::string& name : example_names()) {
    const Json& report = example_report(name);
    const std::string html = render_html(report);
    EXPECT_EQ(count(html, "<tr class=\"precondition\""), precondition_count(report)) << name;
    EXPECT_EQ(count(html, "class=\"bound-bar\""), precondition_count(report)) << name;
  }
}

TEST(Html, TimelineMarksInsertedStepsAndVerification) {
  const std::string face_down = render_html(example_report("peg_block_face_down"));
  EXPECT_EQ(count(face_down, "<g class=\"step inserted\">"), 2u);  // the two range-scans
  EXPECT_EQ(count(face_down, ">verify</text>"), 0u);
  const std::string on_back = render_html(example_report("peg_block_on_back"));
  EXPECT_EQ(count(on_back, ">verify</text>"), 1u);
  for (const char* section : {"id=\"timeline\"", "id=\"preconditions\"", "id=\"ordering\"",
                              "id=\"network\"", "id=\"instances\"", "id=\"uncertainty\""})
    EXPECT_NE(face_down.find(section), std::string::npos) << section;
}

TEST(Html, ShowsBlameAndReverseMargin) {
  const std::string html = render_html(example_report("peg_block_face_down"));
  EXPECT_NE(html.find("class=\"blame\""), std::string::npos);
  EXPECT_TRUE(
      std::regex_search(html, std::regex(R"(<td>x[0-9.]+ \(±[0-9.]+ in, ±[0-9.]+ deg\)</td>)")));
}

TEST(SensingReport, ShowsTheSensePlanAndEveryBranch) {
  const Json& report = sensing_report();
  EXPECT_EQ(report["status"], "planned");
  const Json& first = report["chosen"]["steps"][0];
  EXPECT_EQ(first["action"], "sense");
  EXPECT_EQ(first["object"], "block");
  EXPECT_EQ(first["sensing"]["sensor"], "range_scan");
  EXPECT_LT(first["sensing"]["predicted_max_ambiguity"].get<double>(), 0.3);
  ASSERT_EQ(report["branches"].size(), 2U);
  EXPECT_EQ(report["branches"][1]["outcome"], "P2");
  EXPECT_EQ(report["branches"][1]["status"], "planned");
  EXPECT_FALSE(report["branches"][1]["steps"].empty());
  const std::string markdown = render_markdown(report);
  for (const char* part : {"## Sensing", "### block: 2 hypotheses", "| range_scan at V",
                           "### Branch P1 (block is P1): planned",
                           "### Branch P2 (block is P2): planned", "branch P2: planned"})
    EXPECT_NE(markdown.find(part), std::string::npos) << part;
  const std::string html = render_html(report);
  EXPECT_NE(html.find("class=\"view-sphere\""), std::string::npos);
  EXPECT_EQ(count(html, "<h3>Branch P"), 2U);
}

TEST(Renderers, RefuseADocumentThatIsNotAReport) {
  EXPECT_THROW_MESSAGE(render_html(Json::parse(R"({"status": "planned"})")),
                       "cannot render HTML: not a spar-report/1 report");
  Json broken = example_report("peg_block_face_up");
  broken.erase("units");
  EXPECT_THROW_MESSAGE(render_markdown(broken), "cannot render Markdown: malformed report");
}

TEST(ReportJson, AMissingOrMistypedMemberIsNamedByItsPath) {
  Json broken = example_report("peg_block_on_back");
  broken["chosen"]["steps"][2].erase("action");
  EXPECT_THROW_MESSAGE(report_from_json(broken),
                       "malformed report: chosen.steps[2].action: missing");
  broken = example_report("peg_block_on_back");
  broken["chosen"]["steps"][0]["preconditions"][1]["lo"] = "low";
  EXPECT_THROW_MESSAGE(report_from_json(broken),
                       "malformed report: chosen.steps[0].preconditions[1].lo: expected a number");
  EXPECT_THROW_MESSAGE(report_from_json(Json::parse(R"({"schema": "spar-report/0"})")),
                       "not a spar-report/1 report");
}

TEST(ReportJson, OptionalMembersStayAbsentAndNullablesNull) {
  const Report report = report_from_json(no_plan_report());
  EXPECT_FALSE(report.chosen.has_value());
  const Json again = to_json(report);
  EXPECT_TRUE(again.at("chosen").is_null());
  EXPECT_TRUE(again.contains("reason"));
  const Report planned = report_from_json(example_report("peg_block_face_up"));
  EXPECT_FALSE(to_json(planned).contains("reason"));
  EXPECT_EQ(step_label(*planned.chosen, 0), "#1 range-scan block");  // phase 2 inserted it
}

TEST(Formats, ParseListsAndRefuseUnknownOrRepeated) {
  EXPECT_EQ(parse_formats("html,json"), (std::vector<Format>{Format::kHtml, Format::kJson}));
  EXPECT_THROW_MESSAGE(parse_formats("json,pdf"), "unknown report format 'pdf'");
  EXPECT_THROW_MESSAGE(parse_formats("md,markdown"), "given twice");
  EXPECT_THROW_MESSAGE(parse_formats(""), "unknown report format ''");
}

fs::path fresh_folder(const std::string& name) {
  const fs::path folder = fs::temp_directory_path() / ("spar_reports_test_" + name);
  fs::remove_all(folder);
  return folder;
}

TEST(WriteReports, WritesEveryFormatAndNoTemporaries) {
  const fs::path folder = fresh_folder("write");
  const Json& report = example_report("peg_block_face_up");
  const auto files = write_reports(report_from_json(report), folder / "nested",
                                   {Format::kJson, Format::kMarkdown, Format::kHtml});
  ASSERT_EQ(files.size(), 3u);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder / "nested"))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"report.html", "report.json", "report.md"}));
  std::ifstream in(files[0]);
  EXPECT_EQ(Json::parse(in), report);
  fs::remove_all(folder);
}

TEST(WriteReports, AReportThatCannotBeRenderedWritesNothing) {
  const fs::path folder = fresh_folder("bad");
  Report broken = report_from_json(example_report("peg_block_face_up"));
  broken.chosen->probability->preconditions[0].step = 99;  // past the steps: cannot be rendered
  EXPECT_THROW((void)write_reports(broken, folder, {Format::kJson, Format::kHtml}), ReportError);
  EXPECT_FALSE(fs::exists(folder / "report.json"));
  EXPECT_FALSE(fs::exists(folder / "report.html"));
  fs::remove_all(folder);
}

TEST(WriteReports, AnUnwritableFolderIsAnErrorNamingIt) {
  const fs::path folder = fresh_folder("file");
  std::ofstream(folder.string()) << "a file, not a folder";
  EXPECT_THROW_MESSAGE(write_reports(report_from_json(example_report("peg_block_face_up")),
                                     folder / "sub", {Format::kJson}),
                       "cannot create the report folder");
  fs::remove(folder);
}

TEST(LayeredLayout, EdgesPointToLaterLayersAndPositionsAreDistinct) {
  // A plan-like graph: start -> a chain with a diamond -> finish, listed out of order.
  const std::vector<std::pair<int, int>> edges = {{0, 2}, {2, 3}, {2, 4}, {3, 5}, {4, 5}, {5, 1}};
  const internal::LayeredLayout layout = internal::layered_layout(6, edges);
  for (const auto& [from, to] : edges) EXPECT_LT(layout.layer[from], layout.layer[to]);
  EXPECT_EQ(layout.layers, 5);
  EXPECT_EQ(layout.widest, 2);
  EXPECT_NE(layout.position[3], layout.position[4]);
  EXPECT_EQ(layout.layer[1], 4);  // finish: the longest path
}

TEST(LayeredLayout, ACycleDoesNotHang) {
  const internal::LayeredLayout layout = internal::layered_layout(3, {{0, 1}, {1, 2}, {2, 1}});
  EXPECT_EQ(layout.layer[0], 0);
  EXPECT_EQ(layout.layer[1], layout.layer[2]);
}

TEST(CircularLayout, PointsAreOnTheUnitCircleStartingAtTheTop) {
  const std::vector<internal::Point> ring = internal::circular_layout(4);
  ASSERT_EQ(ring.size(), 4u);
  EXPECT_NEAR(ring[0].x, 0.0, 1e-12);
  EXPECT_NEAR(ring[0].y, -1.0, 1e-12);
  EXPECT_NEAR(ring[1].x, 1.0, 1e-12);
}

TEST(CircleOrder, NeighboursSitSideBySide) {
  // A chain listed out of order: 0-3-1-4-2 must come out as consecutive slots.
  const std::vector<std::pair<int, int>> chain = {{1, 4}, {0, 3}, {4, 2}, {3, 1}};
  const std::vector<int> slot = internal::circle_order(5, chain);
  for (const auto& [a, b] : chain) EXPECT_EQ(std::abs(slot[a] - slot[b]), 1) << a << "-" << b;
  std::vector<int> sorted = slot;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(internal::circle_order(3, {}), (std::vector<int>{0, 1, 2}));  // isolated: as given
}

// `spar plan --batch` runs plan() on several threads: two concurrent plans must give exactly what
// they give one after the other.
TEST(Planner, TwoConcurrentPlansGiveTheSequentialReports) {
  planner::PlanOptions options;
  options.analysis.reverse = false;
  options.analysis.blame = false;
  options.analysis.samples = 0;
  const auto run = [&](const std::string& name) {
    Json report = plan_json(planner::plan(planner::load_scenario(example_path(name)),
                                          planner::builtin_domain(), options));
    report["family"]["search"].erase("seconds");
    return report;
  };
  const Json first = run("peg_block_face_down"), second = run("peg_block_on_sides");
  auto a = std::async(std::launch::async, run, "peg_block_face_down");
  auto b = std::async(std::launch::async, run, "peg_block_on_sides");
  EXPECT_EQ(a.get(), first);
  EXPECT_EQ(b.get(), second);
}

}  // namespace
}  // namespace spar::reports::testing
