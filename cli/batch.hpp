// The scenarios of `spar plan --batch` and how each becomes exactly one JSON line, whatever
// happens while it is planned. A batch survives any one bad scenario: no exception leaves a
// worker (not a scenario that is not UTF-8, not std::bad_alloc, not a time limit), and every
// listed item gets its record, in input order.
//
// Listing (batch_items):
//   - a folder: every entry whose name ends in .yaml or .yml in any case (*.YAML too), sorted by
//     name, whatever it is: a dangling link, a FIFO or a folder named x.yaml gets an error record
//     saying what it is, never a silent skip;
//   - a list file (read by the one input-file reader): one path per line, relative to the list's
//     folder; blank lines and lines starting with # are skipped; CR and CRLF end lines; a line
//     that is not UTF-8 or holds a control character (a NUL would cut the path) is an item whose
//     record says so at list:line:col.
// Records (batch_line), one JSON object per line:
//   {"file", "report"[, "warnings"]}   planned (warnings: the scenario's, common to its load)
//   {"file", "error"}                  refused or failed, with the message
//   {"file", "status": "time_limit", "error"}   the --time-limit ran out (common/deadline.hpp)
// "file" is the path as listed, through printable() (common/text.hpp), so a file name that is
// not UTF-8 still makes a valid JSON line.
//
// Example:
//   for (const BatchItem& item : batch_items("cells/"))
//     std::cout << batch_line(item, plan_one, 30.0).json << '\n';
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "spar/planner/scenario.hpp"

namespace spar::cli {

struct BatchItem {
  std::string path;     // as listed: the bytes the file system has
  std::string file;     // the record's "file": printable(path)
  std::string problem;  // why it cannot be planned, found while listing ("" if none)
};

// The items of a folder or a list file; throws UsageError when `source` is neither, or lists
// nothing.
[[nodiscard]] std::vector<BatchItem> batch_items(const std::string& source);

// Fills record["report"] (and writes any files) for a loaded scenario.
using PlanOne = std::function<void(const planner::Scenario&, nlohmann::ordered_json& record)>;

struct BatchLine {
  std::string json;  // one line, valid UTF-8, no newline
  bool failed{false};
};

// Loads and plans one item under `time_limit` seconds (none: no limit). Never throws.
[[nodiscard]] BatchLine batch_line(const BatchItem& item, const PlanOne& plan,
                                   std::optional<double> time_limit) noexcept;

}  // namespace spar::cli
