// Writing a report folder: report.json (the source of truth), report.md and report.html, each
// written from the same report model (reports/model.hpp); with the Markdown, the drawings of the
// work cell it links to (cell-0.svg, cell-1.svg, ...: one per view, internal/cell_svg.hpp). A call
// replaces the folder's report as a set, or leaves the old set as it was:
//   - every file is rendered first, then written to a temporary file of a unique hidden name
//     (".report.md.<pid>-<random>-<n>.tmp", created with O_EXCL | O_NOFOLLOW, so no existing file
//     or symbolic link is ever written through), and renamed over its final name only once all
//     are complete;
//   - an old file is kept as a hard link until every rename has succeeded: a rename that fails
//     half-way puts the old set back, and the error names the system's reason;
//   - files of an older report that this call does not write (report.md after --format json,
//     cell views past this report's) are removed, so the folder never mixes two reports;
//   - SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGPIPE (when at their default action) are held while a
//     set is written: before the renames the temporaries are discarded (the old set stays), during
//     them the renames finish; then the signal acts. Only SIGKILL or a crash can leave a hidden
//     temporary behind, never a partial report file.
//
// Example:
//   const std::vector<Format> formats = parse_formats("json,html");
//   for (const auto& file : write_reports(build_report(result), "report", formats))
//     std::cout << "wrote " << file.string() << '\n';
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "spar/reports/model.hpp"

namespace spar::reports {

enum class Format { kJson, kMarkdown, kHtml };

// "json,md,html" (any order, no repeats; "markdown" is accepted for "md"). Throws ReportError
// naming an unknown or repeated format.
[[nodiscard]] std::vector<Format> parse_formats(std::string_view list);
// "report.json", "report.md", "report.html".
[[nodiscard]] std::string file_name(Format format);
// The file's text: the JSON indented by 2 (with a final newline), or the rendered Markdown/HTML.
[[nodiscard]] std::string render(const Report& report, Format format);

// Creates `folder` if needed and writes the formats (and the Markdown's drawings) as one set (see
// above); returns the report files written, in `formats` order. Throws ReportError (an empty
// folder name; the path and the system's reason) having removed its temporaries and kept the old
// set.
std::vector<std::filesystem::path> write_reports(const Report& report,
                                                 const std::filesystem::path& folder,
                                                 const std::vector<Format>& formats);

}  // namespace spar::reports
