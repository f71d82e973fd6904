// The JSON report of a planning run in one call: to_json(build_report(result)) (reports/model.hpp
// describes the records, reports/json.hpp the JSON, docs/report-schema.md every field).
//
// Example:
//   const planner::PlanResult result = planner::plan(scenario, planner::builtin_domain());
//   std::cout << plan_json(result).dump(2) << '\n';   // what `spar plan --json` prints
#pragma once

#include <nlohmann/json.hpp>

#include "spar/planner/plan.hpp"
#include "spar/reports/build.hpp"
#include "spar/reports/json.hpp"

namespace spar::reports {

[[nodiscard]] inline nlohmann::ordered_json plan_json(const planner::PlanResult& result) {
  return to_json(build_report(result));
}

}  // namespace spar::reports
