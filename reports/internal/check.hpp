// The renderers' guard (reports/ only): a document is read into the model first (a JSON document
// must say it is a spar-report/1 and have every required member), and a model whose parts do not
// fit together (an index past its array) becomes a ReportError naming the format, never a crash.
//
// Example:
//   return guarded("Markdown", [&] { return markdown(report); });
#pragma once

#include <exception>
#include <string>

#include "spar/reports/error.hpp"

namespace spar::reports::internal {

template <typename Render>
[[nodiscard]] std::string guarded(const char* format, Render render) {
  try {
    return render();
  } catch (const ReportError& error) {
    throw ReportError(std::string("cannot render ") + format + ": " + error.what());
  } catch (const std::exception& error) {
    throw ReportError(std::string("cannot render ") + format +
                      ": malformed report: " + error.what());
  }
}

}  // namespace spar::reports::internal
