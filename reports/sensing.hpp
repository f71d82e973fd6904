// The "Sensing" part of reports: the records of sense planning (reports/model.hpp's
// ObjectSensing) built from planner/sense_planning.hpp's result, and their Markdown and HTML:
// the reachable candidate operations' table (least predicted worst-case ambiguity first; the
// unreachable viewpoints only named, folded in HTML), the chosen operations, the hypotheses'
// beliefs before and after (the worst case of the chosen sequence), and each identity's view sphere
// drawn as two hemispheres (seen from above and from below, orthographically), every sample
// direction coloured by the aspect the object shows along it.
//
// Example:
//   const SensePlanRecord record = build_sense_plan(scenario, planner::plan_sensing(scenario,
//   world)); std::cout << to_json(record).dump(2);                // `spar sense-plan --json`
//   std::cout << sensing_markdown(record.objects);       // `spar sense-plan`
#pragma once

#include <string>
#include <vector>

#include "spar/planner/scenario.hpp"
#include "spar/planner/sense_planning.hpp"
#include "spar/reports/model.hpp"

namespace spar::reports {

[[nodiscard]] ObjectSensing build_object_sensing(const planner::ObjectSensePlan& plan);
[[nodiscard]] SensePlanRecord build_sense_plan(const planner::Scenario& scenario,
                                               const planner::SensePlan& plan);

// "## Sensing" with one subsection per object (empty string for no object).
[[nodiscard]] std::string sensing_markdown(const std::vector<ObjectSensing>& objects);
// The same as an HTML <section> with the view-sphere drawings (empty for no object).
[[nodiscard]] std::string sensing_html(const std::vector<ObjectSensing>& objects);
// One identity's view sphere as an inline SVG.
[[nodiscard]] std::string view_sphere_svg(const ViewSphere& sphere);

}  // namespace spar::reports
