#include "spar/reports/write.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "spar/reports/error.hpp"
#include "spar/reports/html.hpp"
#include "spar/reports/internal/cell_svg.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/markdown.hpp"

namespace spar::reports {
namespace fs = std::filesystem;

std::vector<Format> parse_formats(std::string_view list) {
  std::vector<Format> formats;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string_view word = list.substr(start, comma - start);
    Format format;
    if (word == "json")
      format = Format::kJson;
    else if (word == "md" || word == "markdown")
      format = Format::kMarkdown;
    else if (word == "html")
      format = Format::kHtml;
    else
      throw ReportError("unknown report format '" + std::string(word) +
                        "' (expected a comma-separated list of json, md, html)");
    if (std::find(formats.begin(), formats.end(), format) != formats.end())
      throw ReportError("report format '" + std::string(word) + "' given twice");
    formats.push_back(format);
    start = comma + 1;
  }
  return formats;
}

std::string file_name(Format format) {
  switch (format) {
    case Format::kJson:
      return "report.json";
    case Format::kMarkdown:
      return "report.md";
    case Format::kHtml:
      return "report.html";
  }
  return "report";
}

std::string render(const Report& report, Format format) {
  switch (format) {
    case Format::kJson:
      return to_json(report).dump(2) + "\n";
    case Format::kMarkdown:
      return render_markdown(report);
    case Format::kHtml:
      return render_html(report);
  }
  return {};
}

std::vector<fs::path> write_reports(const Report& report, const fs::path& folder,
                                    const std::vector<Format>& formats) {
  // Every file: the formats' (returned), then the cell's views the Markdown links to.
  std::vector<std::pair<std::string, std::string>> files;
  for (const Format format : formats) files.emplace_back(file_name(format), render(report, format));
  const std::size_t reports = files.size();
  if (report.cell && std::find(formats.begin(), formats.end(), Format::kMarkdown) != formats.end())
    for (std::size_t v = 0; v < report.cell->views.size(); ++v)
      files.emplace_back(internal::cell_view_file(v), internal::cell_view_svg(report, v, true));
  std::error_code error;
  fs::create_directories(folder, error);
  if (error)
    throw ReportError("cannot create the report folder " + folder.string() + ": " +
                      error.message());
  std::vector<fs::path> temporaries, finals;
  const auto remove_temporaries = [&] {
    for (const fs::path& temporary : temporaries) fs::remove(temporary, error);
  };
  for (const auto& [name, text] : files) {
    finals.push_back(folder / name);
    temporaries.push_back(folder / ("." + name + ".tmp"));
    std::ofstream out(temporaries.back(), std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      const std::string reason = std::strerror(errno);
      remove_temporaries();
      throw ReportError("cannot write " + temporaries.back().string() + ": " + reason);
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    fs::rename(temporaries[i], finals[i], error);
    if (error) {
      remove_temporaries();
      throw ReportError("cannot rename " + temporaries[i].string() + " to " + finals[i].string() +
                        ": " + error.message());
    }
  }
  finals.resize(reports);
  return finals;
}

}  // namespace spar::reports
