// Writing a report folder: report.json (the source of truth), report.md and report.html, each
// written from the same report model (reports/model.hpp); with the Markdown, the drawings of the
// work cell it links to (cell-0.svg, cell-1.svg, ...: one per view, internal/cell_svg.hpp). Atomic
// per file and all-or-nothing per call: every format is rendered first, each is written to a
// temporary name in the folder
// (".report.<ext>.tmp") and renamed over its final name only once all are written, so a failure (a
// report that cannot be rendered, a full disk) leaves no half-written report behind, and a reader
// never sees one.
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

// Creates `folder` if needed and writes the formats (and the Markdown's drawings); returns the
// report files written, in `formats`
// order. Throws ReportError (with the path and the system's reason) and removes its temporaries.
std::vector<std::filesystem::path> write_reports(const Report& report,
                                                 const std::filesystem::path& folder,
                                                 const std::vector<Format>& formats);

}  // namespace spar::reports
