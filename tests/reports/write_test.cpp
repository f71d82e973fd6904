// write_reports under hostile folders and signals (issue 22): a report set is replaced whole or
// not at all, nothing is written through a symbolic link, and no other report's formats are left
// beside a new one.
#include "spar/reports/write.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "spar/reports/error.hpp"
#include "spar/reports/json.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::reports {
namespace {

namespace fs = std::filesystem;

const std::vector<Format> kAll = {Format::kJson, Format::kMarkdown, Format::kHtml};

fs::path fresh_folder(const std::string& name) {
  const fs::path folder = fs::temp_directory_path() / ("spar_write_test_" + name);
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The folder's file names but the cell views (cell-<k>.svg, written with the Markdown).
std::vector<std::string> names_in(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder))
    if (!entry.path().filename().string().starts_with("cell-"))
      names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// Two reports from the golden files (planning them would take seconds per test process).
Report golden(const std::string& name) {
  return report_from_json(nlohmann::ordered_json::parse(
      read(fs::path(SPAR_SOURCE_DIR) / "tests/reports/golden" / (name + ".json"))));
}
const Report& face_up() {
  static const Report report = golden("peg_block_face_up");
  return report;
}
const Report& on_back() {
  static const Report report = golden("peg_block_on_back");
  return report;
}

// The temporary names of the old writer, planted as links to a file outside: spar overwrote it.
TEST(WriteReportSet, NeverWritesThroughALink) {
  const fs::path folder = fresh_folder("links");
  const fs::path outside = folder / "outside.txt";
  std::ofstream(outside) << "precious";
  fs::create_directory(folder / "report");
  for (const char* name : {".report.md.tmp", ".report.json.tmp", "report.html"})
    fs::create_symlink(outside, folder / "report" / name);
  (void)write_reports(face_up(), folder / "report", kAll);
  EXPECT_EQ(read(outside), "precious");
  EXPECT_FALSE(fs::is_symlink(folder / "report" / "report.html"));
  EXPECT_EQ(read(folder / "report" / "report.html"), render(face_up(), Format::kHtml));
  EXPECT_EQ(names_in(folder / "report"),
            (std::vector<std::string>{".report.json.tmp", ".report.md.tmp", "report.html",
                                      "report.json", "report.md"}));
  fs::remove_all(folder);
}

// `--format json` over an older report left that report's report.md and report.html beside it.
TEST(WriteReportSet, RemovesTheOlderReportsOtherFormats) {
  const fs::path folder = fresh_folder("stale");
  (void)write_reports(face_up(), folder, kAll);
  (void)write_reports(on_back(), folder, {Format::kJson});
  EXPECT_EQ(names_in(folder), (std::vector<std::string>{"report.json"}));
  EXPECT_FALSE(fs::exists(folder / "cell-0.svg"));  // the Markdown's drawings went with it
  EXPECT_EQ(read(folder / "report.json"), render(on_back(), Format::kJson));
  fs::remove_all(folder);
}

// A file that cannot be replaced: the old set stays whole and the message says why (it said
// "...: Success", errno read after it was reset, and left a mixed set).
TEST(WriteReportSet, AFailureKeepsTheOldSetAndSaysWhy) {
  const fs::path folder = fresh_folder("blocked");
  (void)write_reports(face_up(), folder, {Format::kJson, Format::kMarkdown});
  fs::create_directories(folder / "report.html" / "inside");
  EXPECT_THROW_MESSAGE(write_reports(on_back(), folder, kAll),
                       "report.html is a directory, not a report file (the old report is kept)");
  EXPECT_EQ(read(folder / "report.json"), render(face_up(), Format::kJson));
  EXPECT_EQ(read(folder / "report.md"), render(face_up(), Format::kMarkdown));
  EXPECT_EQ(names_in(folder),
            (std::vector<std::string>{"report.html", "report.json", "report.md"}));
  fs::remove_all(folder);
}

TEST(WriteReportSet, AnEmptyFolderNameIsAnError) {
  EXPECT_THROW_MESSAGE(write_reports(face_up(), "", kAll), "the report folder is empty");
}

// A child process rewrites the folder with two reports in turn until SIGTERM or SIGINT arrives at
// some moment; the folder then holds one whole set (every file of the same report) and no
// temporary.
TEST(WriteReportSet, ASignalLeavesOneWholeSet) {
  const fs::path folder = fresh_folder("signals");
  const std::vector<std::string> first = {render(face_up(), Format::kJson),
                                          render(face_up(), Format::kMarkdown),
                                          render(face_up(), Format::kHtml)};
  const std::vector<std::string> second = {render(on_back(), Format::kJson),
                                           render(on_back(), Format::kMarkdown),
                                           render(on_back(), Format::kHtml)};
  (void)write_reports(face_up(), folder, kAll);
  for (int round = 0; round < 8; ++round) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      for (int i = 0;; ++i) {
        try {
          (void)write_reports(i % 2 ? face_up() : on_back(), folder, kAll);
        } catch (const ReportError&) {  // "interrupted": the held signal acts on the way out
        }
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5 + 7 * round));
    const int signal_number = round % 2 ? SIGINT : SIGTERM;
    ASSERT_EQ(kill(child, signal_number), 0);
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << "round " << round;
    ASSERT_EQ(names_in(folder),
              (std::vector<std::string>{"report.html", "report.json", "report.md"}))
        << "round " << round;
    const std::vector<std::string> now = {read(folder / "report.json"), read(folder / "report.md"),
                                          read(folder / "report.html")};
    EXPECT_TRUE(now == first || now == second) << "a mixed set after round " << round;
  }
  fs::remove_all(folder);
}

}  // namespace
}  // namespace spar::reports
