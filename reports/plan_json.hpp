// The report of a planning run as JSON: the source of truth of every report spar writes (Markdown
// and HTML are rendered from it, never from planner internals). Schema "spar-report/1", documented
// field by field in docs/report-schema.md together with the JSON Schema tests validate against.
//
// Keys named normative in the planner issues are kept exactly: status (planned | no_plan) and
// reason, units, robot {base, tool}, family {steps, ordering, variables, arcs}, instances {count,
// limit_reached, examined [{errors}]}, chosen {steps, errors} whose steps carry id, action, object,
// grasp {label, faces, width, gripper_in_object}, object_pose, stable_pose, gripper_pose, joints
// (radians), configuration, for assemblies fixed_object, fixed_pose, held_pose, and per step
// preconditions [{name, kind, relation, expression, lo, hi, inner_lo, inner_hi, verdict, witness,
// box}], finger_opening, verification and recovery.
//
// Units: poses, widths and finger openings are in the scenario's length unit. Precondition
// expressions, their bounds, witnesses and boxes are in SI (metres, radians), because the
// expression must be re-boundable by `spar bound`; each precondition's `display` repeats its bounds
// in the scenario's unit. JSON has no inf or NaN: they are the strings "inf", "-inf", "nan".
//
// Example:
//   const planner::PlanResult result = planner::plan(scenario, planner::builtin_domain());
//   const nlohmann::ordered_json report = plan_json(result);
//   std::cout << report.dump(2) << '\n';                    // report["schema"] == kReportSchema
#pragma once

#include <nlohmann/json.hpp>

#include "spar/planner/plan.hpp"

namespace spar::reports {

// The version of the report's layout; a reader checks it before anything else.
inline constexpr const char* kReportSchema = "spar-report/1";

[[nodiscard]] nlohmann::ordered_json plan_json(const planner::PlanResult& result);

}  // namespace spar::reports
