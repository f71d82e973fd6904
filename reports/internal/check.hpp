// Guards of the renderers (reports/ only): a document must say it is a spar-report/1 before it is
// read, and a missing or mistyped member becomes a ReportError naming what is wrong.
//
// Example:
//   return guarded("Markdown", report, [&] { return render(report); });
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "spar/reports/error.hpp"
#include "spar/reports/plan_json.hpp"

namespace spar::reports::internal {

template <typename Render>
[[nodiscard]] std::string guarded(const char* format, const nlohmann::ordered_json& report,
                                  Render render) {
  if (!report.is_object() || !report.contains("schema") || report["schema"] != kReportSchema)
    throw ReportError(std::string("cannot render ") + format + ": not a " + kReportSchema +
                      " report (its \"schema\" member must say so)");
  try {
    return render();
  } catch (const nlohmann::json::exception& error) {
    throw ReportError(std::string("cannot render ") + format +
                      ": malformed report: " + error.what());
  }
}

}  // namespace spar::reports::internal
