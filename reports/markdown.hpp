// The Markdown report: what a person reads in a terminal or a pull request, written from the
// report model (reports/model.hpp); the same model always gives the same bytes.
//
// Sections: title and summary (status, steps, verdict counts, errors, instances), the chosen plan
// in execution order, the work cell (links to cell-<k>.svg, written beside report.md by
// write_reports), the per-precondition verdict table (bounds rounded to 3 significant digits, in
// the scenario's length unit where they are lengths), inserted sensing and squeeze with the
// bounds before and after (the dropped ones in one line), verification and recovery, failure
// probability and tolerances, and the instances considered. A step is always "#k action object",
// k its place in the plan. summary() gives the few lines `spar plan` prints.
//
// Example:
//   const Report report = build_report(planner::plan(scenario, domain));
//   std::ofstream("report.md") << render_markdown(report);
//   std::cout << summary(report);
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "spar/reports/model.hpp"

namespace spar::reports {

// Throws ReportError when the model's parts do not fit together (an index past its array).
[[nodiscard]] std::string render_markdown(const Report& report);
// A report read back from its JSON; throws ReportError when it is not a spar-report/1 document.
[[nodiscard]] std::string render_markdown(const nlohmann::ordered_json& report);
// A few lines: status, steps with inserted ones, verdict counts, errors, instances.
[[nodiscard]] std::string summary(const Report& report);

}  // namespace spar::reports
