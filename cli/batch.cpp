#include "cli/batch.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <new>
#include <system_error>

#include "cli/options.hpp"
#include "spar/common/deadline.hpp"
#include "spar/common/input_file.hpp"
#include "spar/common/text.hpp"

namespace spar::cli {
namespace {

namespace fs = std::filesystem;

bool is_scenario_name(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".yaml" || extension == ".yml";
}

BatchItem item_at(std::string path) {
  BatchItem item{.path = std::move(path), .file = {}, .problem = {}};
  item.file = printable(item.path);
  return item;
}

std::vector<BatchItem> folder_items(const std::string& folder) {
  std::vector<std::string> paths;
  std::error_code error;
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error))
    if (is_scenario_name(it->path())) paths.push_back(it->path().string());
  if (error)
    throw UsageError("--batch: cannot list the folder " + single_quoted(folder, 4096) + ": " +
                     error.message());
  std::sort(paths.begin(), paths.end());
  if (paths.empty())
    throw UsageError("--batch: no *.yaml or *.yml scenario in the folder " +
                     single_quoted(folder, 4096));
  std::vector<BatchItem> items;
  for (std::string& path : paths) items.push_back(item_at(std::move(path)));
  return items;
}

std::vector<BatchItem> list_items(const std::string& list) {
  std::string text;
  try {
    text = normalize_newlines(read_input_file(list, "batch list", kMaxTextFileBytes));
  } catch (const InputError& error) {
    throw UsageError(std::string("--batch: ") + error.what() + " (give a folder or a list file)");
  }
  const fs::path base = fs::path(list).parent_path();
  const std::string source = printable(list);
  std::vector<BatchItem> items;
  std::size_t start = 0;
  for (int number = 1; start < text.size(); ++number) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    std::string line = text.substr(start, end - start);
    const std::size_t line_start = start;
    start = end + 1;
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    line = line.substr(first, line.find_last_not_of(" \t") + 1 - first);
    BatchItem item = item_at(fs::path(line).is_absolute() ? line : (base / line).string());
    const std::size_t column_base = line_start + first;
    if (const auto bad = find_invalid_utf8(line)) {
      item.problem = source + ":" + line_column(text, column_base + *bad) +
                     ": the path is not UTF-8 (the list must be UTF-8 text)";
    } else if (const auto control = find_control_character(line)) {
      item.problem = source + ":" + line_column(text, column_base + *control) +
                     ": the path holds a control character";
    }
    items.push_back(std::move(item));
  }
  if (items.empty())
    throw UsageError("--batch: " + single_quoted(list, 4096) + " lists no scenario");
  return items;
}

nlohmann::ordered_json error_record(const BatchItem& item, const std::string& message) {
  return {{"file", item.file}, {"error", printable(message)}};
}

}  // namespace

std::vector<BatchItem> batch_items(const std::string& source) {
  std::error_code error;
  if (fs::is_directory(source, error)) return folder_items(source);
  return list_items(source);
}

BatchLine batch_line(const BatchItem& item, const PlanOne& plan,
                     std::optional<double> time_limit) noexcept {
  // Every dump may meet a string that breaks the text policy by mistake: it is replaced (U+FFFD),
  // never thrown, so the line is written whatever the record holds.
  const auto dump = [](const nlohmann::ordered_json& record) {
    return record.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  };
  try {
    try {
      if (!item.problem.empty()) return {dump(error_record(item, item.problem)), true};
      std::optional<ScopedDeadline> deadline;
      if (time_limit) deadline.emplace(std::chrono::duration<double>(*time_limit));
      nlohmann::ordered_json record = {{"file", item.file}};
      const planner::Scenario scenario = planner::load_scenario(item.path);
      if (!scenario.warnings.empty()) record["warnings"] = scenario.warnings;
      plan(scenario, record);
      return {dump(record), false};
    } catch (const TimeLimitError& error) {
      return {dump({{"file", item.file}, {"status", "time_limit"}, {"error", error.what()}}), true};
    } catch (const std::bad_alloc&) {
      return {dump(error_record(item, "out of memory while planning this scenario")), true};
    } catch (const std::exception& error) {
      return {dump(error_record(item, error.what())), true};
    } catch (...) {
      return {dump(error_record(item, "unexpected error while planning this scenario")), true};
    }
  } catch (...) {  // even building the error record failed (no memory left): a fixed line
    return {"{\"error\": \"out of memory\"}", true};
  }
}

}  // namespace spar::cli
