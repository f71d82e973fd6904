// The HTML report: one self-contained file (no network, no scripts, no external fonts or styles)
// with inline SVG, written from the report model (reports/model.hpp).
//
// Sections, each an element with a stable id that tests and readers can find:
//   #summary        scenario, status, verdict counts, errors, instances
//   #timeline       the chosen plan in execution order; inserted steps dashed and tagged,
//                   failed steps red, steps with verification carry a "verify" badge
//   #preconditions  one <tr class="precondition"> per precondition: verdict, a bar of the sound
//                   bound [lo, hi] against the threshold with the inner bound inside it, exact
//                   values on hover, the witness in a table, per-variable blame bars and the
//                   reverse-analysis margin ("holds up to x2.3: +-0.25 in, +-13 deg")
//   #repairs, #verification, #uncertainty (the variables with provenance and ranges),
//   #ordering       the ordering graph, layered by longest path (internal/layout.hpp)
//   #network        the geometric constraint network, nodes on a circle
//   #instances      the instances examined with their error counts
// Units are shown on every value; numbers are rounded for reading (the JSON keeps exact values).
//
// Example:
//   const Report report = build_report(planner::plan(scenario, domain));
//   std::ofstream("report.html") << render_html(report);
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "spar/reports/model.hpp"

namespace spar::reports {

// Throws ReportError when the model's parts do not fit together (an index past its array).
[[nodiscard]] std::string render_html(const Report& report);
// A report read back from its JSON; throws ReportError when it is not a spar-report/1 document.
[[nodiscard]] std::string render_html(const nlohmann::ordered_json& report);

}  // namespace spar::reports
