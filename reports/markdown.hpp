// The Markdown report: what a person reads in a terminal or a pull request. Rendered from the
// report's JSON only (reports/plan_json.hpp), so the same JSON always gives the same bytes.
//
// Sections: title and summary (status, steps, verdict counts, errors, instances), the chosen plan
// in execution order, the per-precondition verdict table (bounds rounded to 3 significant digits,
// in the scenario's length unit where they are lengths), inserted sensing and squeeze with the
// bounds before and after, verification and recovery, and the instances considered. summary()
// gives the few lines `spar plan` prints.
//
// Example:
//   const nlohmann::ordered_json report = plan_json(planner::plan(scenario, domain));
//   std::ofstream("report.md") << render_markdown(report);
//   std::cout << summary(report);
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace spar::reports {

// Throws ReportError when `report` is not a spar-report/1 document.
[[nodiscard]] std::string render_markdown(const nlohmann::ordered_json& report);
// A few lines: status, steps with inserted ones, verdict counts, errors, instances.
[[nodiscard]] std::string summary(const nlohmann::ordered_json& report);

}  // namespace spar::reports
