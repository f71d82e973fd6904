// The HTML report: one self-contained file (no network, no scripts, no external fonts or styles)
// with inline SVG, written from the report model (reports/model.hpp).
//
// Every step is named by its place in the chosen plan, "#3 pickup block" (model.hpp's
// step_label), in every section. It reads on a phone: a viewport meta, drawings that scale to
// their box (viewBox), tables that scroll inside their own box, and below 700 px the
// precondition table as one card per precondition (tests/reports/browser_check.py checks it at
// 390 px and 1280 px in Chromium).
//
// Sections, each an element with a stable id that tests and readers can find:
//   #summary        scenario, status, verdict counts, errors, instances
//   #timeline       the chosen plan in execution order (<ol class="timeline">, one
//                   <li class="step"> each): inserted steps dashed and tagged, failed steps red
//                   (.failed), steps with verification carry a "verify" badge
//   #cell           the work cell, one <svg class="cell-view"> per state: the initial one and
//                   after every pickup, putdown and assembly (internal/cell_svg.hpp names the
//                   parts)
//   #preconditions  one <tr class="precondition"> per precondition: verdict, a bar of the sound
//                   bound [lo, hi] against the threshold with the inner bound inside it, exact
//                   values on hover, the witness in a table, per-variable blame bars and the
//                   reverse-analysis margin ("holds up to x2.3: +-0.25 in, +-13 deg")
//                   ("≥ x8, search cap" where the search stopped at its cap)
//   #repairs        the kept sensing and squeezes with the bounds they changed; the dropped ones
//                   in one line
//   #verification, #probability (tolerances: a zero one "must be exact"), #uncertainty (the
//                   variables with provenance and ranges),
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
