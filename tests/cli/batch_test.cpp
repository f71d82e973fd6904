// `spar plan --batch` under hostile input (issue 22): every listed item gets exactly one JSON
// record, in order, whatever it is (not UTF-8, a dangling link, a FIFO, *.YAML, a list line that
// is not UTF-8 or holds a NUL), and one bad item never costs the others their reports. Each
// stdout line is parsed as JSON: a line that is not valid JSON (or not UTF-8) fails the test.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/cli/process.hpp"

namespace spar::cli_test {
namespace {

namespace fs = std::filesystem;

const fs::path& scratch() {
  static const fs::path root = [] {
    // A fresh folder per process (ctest runs each test case as its own process, in parallel).
    std::string pattern = (fs::temp_directory_path() / "spar-batch-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    const fs::path dir(pattern);
    fs::create_directories(dir / "cells");
    const std::string good =
        read_file(fs::path(SPAR_SOURCE_DIR) / "examples" / "peg_block_face_up.yaml");
    write_text(dir / "cells" / "a_good.yaml", good);
    write_text(dir / "cells" / "b_not_utf8.yaml",
               "name: peg\xff"
               "block\nobjects: {}\n");
    write_text(dir / "cells" / "c_upper.YAML", good);
    fs::create_symlink(dir / "nowhere.yaml", dir / "cells" / "d_dangling.yaml");
    if (mkfifo((dir / "cells" / "e_fifo.yaml").c_str(), 0600) != 0)
      throw std::runtime_error("mkfifo failed");
    write_text(dir / "cells" / "f_name_\xfe.yaml", good);  // a file name that is not UTF-8
    write_text(dir / "cells" / "g_nul_name.yaml",
               "name: \"peg\\0block\"\nobjects: {c: {builtin: cube, pose: {stable: P1, at: [0.5, "
               "0]}}}\n");
    write_text(dir / "cells" / "notes.txt", "not a scenario: not listed\n");
    std::string list = "cells/a_good.yaml\n\xfe\xff.yaml\n# a comment\n\n   \n";
    list += std::string("x\0y.yaml\n", 9);
    list += "cells/missing.yaml\r\ncells/c_upper.YAML";  // CRLF, and no final line end
    write_text(dir / "list.txt", list);
    return dir;
  }();
  return root;
}

struct BatchRun {
  Outcome outcome;
  std::vector<nlohmann::json> records;
};

BatchRun run_batch(const std::vector<std::string>& extra) {
  std::vector<std::string> arguments{SPAR_BINARY, "plan", "--samples", "0", "--instances", "1"};
  arguments.insert(arguments.end(), extra.begin(), extra.end());
  const fs::path out = scratch() / "out.jsonl", err = scratch() / "err.txt";
  BatchRun run{run_process(arguments, out.string(), err.string(), 120), {}};
  run.outcome.out = read_file(out);
  run.outcome.err = read_file(err);
  std::size_t start = 0;
  while (start < run.outcome.out.size()) {
    const std::size_t end = run.outcome.out.find('\n', start);
    EXPECT_NE(end, std::string::npos) << "the last line has no line end";
    const std::string line = run.outcome.out.substr(start, end - start);
    try {
      run.records.push_back(nlohmann::json::parse(line));  // throws on invalid UTF-8 too
    } catch (const nlohmann::json::exception& error) {
      ADD_FAILURE() << "not a JSON line: " << error.what();
    }
    start = end == std::string::npos ? run.outcome.out.size() : end + 1;
  }
  return run;
}

// (file suffix, "report" or the start of the error)
struct Expected {
  std::string file;
  std::string outcome;
};

void expect_records(const BatchRun& run, const std::vector<Expected>& expected) {
  ASSERT_EQ(run.records.size(), expected.size()) << run.outcome.out << run.outcome.err;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const nlohmann::json& record = run.records[i];
    SCOPED_TRACE(record.dump().substr(0, 300));
    const std::string file = record.at("file");
    EXPECT_TRUE(file.ends_with(expected[i].file)) << file;
    if (expected[i].outcome == "report") {
      EXPECT_TRUE(record.contains("report"));
      EXPECT_EQ(record["report"]["schema"], "spar-report/1");
    } else {
      ASSERT_TRUE(record.contains("error"));
      EXPECT_NE(record["error"].get<std::string>().find(expected[i].outcome), std::string::npos);
    }
  }
}

TEST(PlanBatch, AFolderGivesEveryScenarioNamedEntryARecord) {
  const BatchRun run = run_batch({"--batch", (scratch() / "cells").string(), "--jobs", "0"});
  EXPECT_EQ(run.outcome.exit_status, 1) << run.outcome.what;
  EXPECT_EQ(run.outcome.err, "spar: error: 4 of 7 scenarios failed (their records say why)\n");
  expect_records(run, {
                          {"a_good.yaml", "report"},
                          {"b_not_utf8.yaml", "b_not_utf8.yaml:1:10: invalid UTF-8 (byte 0xff)"},
                          {"c_upper.YAML", "report"},
                          {"d_dangling.yaml", "nowhere.yaml', which does not exist"},
                          {"e_fifo.yaml", "is not a regular file (a FIFO): give a scenario file"},
                          {"f_name_\\xfe.yaml", "report"},
                          {"g_nul_name.yaml", "name: 'peg\\0block' holds a control character"},
                      });
  // The scenario named after a file name that is not UTF-8 has a printable name.
  EXPECT_EQ(run.records[5]["report"]["scenario"], "peg_block_face_up");
}

TEST(PlanBatch, AListGivesEveryLineARecord) {
  const BatchRun run = run_batch({"--batch", (scratch() / "list.txt").string()});
  EXPECT_EQ(run.outcome.exit_status, 1) << run.outcome.what;
  expect_records(run, {
                          {"cells/a_good.yaml", "report"},
                          {"\\xfe\\xff.yaml", "list.txt:2:1: the path is not UTF-8"},
                          {"x\\0y.yaml", "list.txt:6:2: the path holds a control character"},
                          {"cells/missing.yaml", "missing.yaml: no such scenario file"},
                          {"cells/c_upper.YAML", "report"},
                      });
}

TEST(PlanBatch, ReportsGoToOneFolderPerScenario) {
  const fs::path reports = scratch() / "reports";
  const BatchRun run =
      run_batch({"--batch", (scratch() / "list.txt").string(), "--report", reports.string()});
  EXPECT_EQ(run.records.size(), 5u);
  EXPECT_TRUE(fs::is_regular_file(reports / "a_good" / "report.json"));
  EXPECT_TRUE(fs::is_regular_file(reports / "c_upper" / "report.html"));
}

}  // namespace
}  // namespace spar::cli_test
