// Golden reports of the seed's four experiments (tests/reports/golden/<name>.{json,md,html}).
// The JSON is compared structurally: the same members and array lengths, strings equal except
// for the numbers inside them, numbers equal within a relative 1e-6 (harmless float noise between
// machines does not break them); family.search (the search's effort and wall-clock time) is not
// compared. Markdown and HTML must regenerate byte-identically from the golden JSON.
// SPAR_UPDATE_GOLDEN=1 rewrites the golden files from the current planner (review the diff);
// SPAR_UPDATE_GOLDEN=render only re-renders the Markdown and HTML from the golden JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "spar/reports/json.hpp"
#include "spar/reports/write.hpp"
#include "tests/reports/example_reports.hpp"

namespace spar::reports::testing {
namespace {

using Json = nlohmann::ordered_json;

std::string golden_path(const std::string& name, const std::string& extension) {
  return std::string(SPAR_SOURCE_DIR) + "/tests/reports/golden/" + name + "." + extension;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

bool close(double a, double b) {
  if (a == b) return true;
  return std::fabs(a - b) <= 1e-6 * std::max({1e-3, std::fabs(a), std::fabs(b)});
}

// Splits text into its numbers and the text between them.
void split_numbers(const std::string& text, std::vector<double>& numbers, std::string& rest) {
  static const std::regex number(R"([-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)");
  rest = std::regex_replace(text, number, "#");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), number);
       it != std::sregex_iterator(); ++it)
    numbers.push_back(std::strtod(it->str().c_str(), nullptr));  // 1e-400 is 0, not an error
}

// Differences between `expected` and `actual`, as "path: what" lines (at most 20).
void compare(const Json& expected, const Json& actual, const std::string& path,
             std::vector<std::string>& differences) {
  if (differences.size() >= 20) return;
  if (path == "family.search") return;  // effort, not the plan: changes with every search tweak
  if (expected.is_number() && actual.is_number()) {
    if (!close(expected.get<double>(), actual.get<double>()))
      differences.push_back(path + ": " + expected.dump() + " != " + actual.dump());
    return;
  }
  if (expected.type() != actual.type()) {
    differences.push_back(path + ": " + expected.dump().substr(0, 80) +
                          " != " + actual.dump().substr(0, 80));
    return;
  }
  if (expected.is_string()) {
    std::vector<double> a, b;
    std::string text_a, text_b;
    split_numbers(expected.get<std::string>(), a, text_a);
    split_numbers(actual.get<std::string>(), b, text_b);
    bool same = text_a == text_b && a.size() == b.size();
    for (std::size_t i = 0; same && i < a.size(); ++i) same = close(a[i], b[i]);
    if (!same)
      differences.push_back(path + ": " + expected.dump().substr(0, 80) +
                            " != " + actual.dump().substr(0, 80));
    return;
  }
  if (expected.is_array()) {
    if (expected.size() != actual.size()) {
      differences.push_back(path + ": " + std::to_string(expected.size()) +
                            " items != " + std::to_string(actual.size()));
      return;
    }
    for (std::size_t i = 0; i < expected.size(); ++i)
      compare(expected[i], actual[i], path + "[" + std::to_string(i) + "]", differences);
    return;
  }
  if (expected.is_object()) {
    for (const auto& [key, value] : expected.items()) {
      const std::string member = path.empty() ? key : path + "." + key;
      if (!actual.contains(key))
        differences.push_back(member + ": missing");
      else
        compare(value, actual[key], member, differences);
    }
    for (const auto& [key, value] : actual.items())
      if (!expected.contains(key)) differences.push_back(path + "." + key + ": not in the golden");
    return;
  }
  if (expected != actual)
    differences.push_back(path + ": " + expected.dump() + " != " + actual.dump());
}

std::string update_mode() {
  const char* update = std::getenv("SPAR_UPDATE_GOLDEN");
  return update == nullptr ? "" : update;
}
bool updating() { return update_mode() == "1"; }
// A renderer changed, the planner did not: re-render from the golden JSON, keep the JSON.
bool rendering_only() { return update_mode() == "render"; }

class GoldenReport : public ::testing::TestWithParam<std::string> {};

TEST_P(GoldenReport, JsonMatchesStructurally) {
  const Json& report = example_report(GetParam());
  if (updating()) {
    // The wall-clock time is not compared; written as 0 so that it does not churn the goldens.
    Report golden = report_from_json(report);
    golden.family.search.seconds = 0.0;
    std::ofstream(golden_path(GetParam(), "json"), std::ios::binary)
        << render(golden, Format::kJson);
    std::ofstream(golden_path(GetParam(), "md"), std::ios::binary)
        << render(golden, Format::kMarkdown);
    std::ofstream(golden_path(GetParam(), "html"), std::ios::binary)
        << render(golden, Format::kHtml);
    GTEST_SKIP() << "golden files rewritten";
  }
  const Json golden = Json::parse(read_file(golden_path(GetParam(), "json")));
  std::vector<std::string> differences;
  compare(golden, report, "", differences);
  std::string listing;
  for (const std::string& difference : differences) listing += "\n  " + difference;
  EXPECT_TRUE(differences.empty()) << "the report differs from tests/reports/golden/" << GetParam()
                                   << ".json (SPAR_UPDATE_GOLDEN=1 rewrites it):" << listing;
}

TEST_P(GoldenReport, MarkdownAndHtmlRegenerateByteIdenticallyFromTheJson) {
  const Report golden = report_from_json(Json::parse(read_file(golden_path(GetParam(), "json"))));
  if (rendering_only()) {
    std::ofstream(golden_path(GetParam(), "md"), std::ios::binary)
        << render(golden, Format::kMarkdown);
    std::ofstream(golden_path(GetParam(), "html"), std::ios::binary)
        << render(golden, Format::kHtml);
    GTEST_SKIP() << "Markdown and HTML re-rendered from the golden JSON";
  }
  EXPECT_EQ(render(golden, Format::kMarkdown), read_file(golden_path(GetParam(), "md")));
  EXPECT_EQ(render(golden, Format::kHtml), read_file(golden_path(GetParam(), "html")));
  // And the JSON itself round-trips through the model and the writer unchanged.
  EXPECT_EQ(render(golden, Format::kJson), read_file(golden_path(GetParam(), "json")));
}

TEST(GoldenCompare, FloatNoiseIsToleratedAndRealChangesAreNot) {
  const Json a = Json::parse(R"({"x": 1.0, "e": "0.30000000000000004*dx + 2", "v": "satisfied"})");
  std::vector<std::string> differences;
  compare(a, Json::parse(R"({"x": 1.0000000001, "e": "0.3*dx + 2", "v": "satisfied"})"), "",
          differences);
  EXPECT_TRUE(differences.empty());
  compare(a, Json::parse(R"({"x": 1.001, "e": "0.3*dy + 2", "v": "violated"})"), "", differences);
  EXPECT_EQ(differences.size(), 3u);
}

INSTANTIATE_TEST_SUITE_P(SeedExperiments, GoldenReport, ::testing::ValuesIn(example_names()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace spar::reports::testing
