// Building the report model (reports/model.hpp) from the planner's result, once: every value a
// report shows is computed here (unit conversions, names for indices, the inserted steps' poses),
// so the back ends (JSON, Markdown, HTML) only write what the records hold.
//
// Example:
//   const planner::PlanResult result = planner::plan(scenario, planner::builtin_domain());
//   const Report report = build_report(result);
//   report.chosen->steps[0].action;                          // "pickup"
//   const Chosen other = build_chosen(result, 3, analysis);  // instance 3 analysed on its own
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "spar/bounds/bound.hpp"
#include "spar/planner/plan.hpp"
#include "spar/reports/model.hpp"

namespace spar::reports {

// On the threads the plan ran on (the work cell's outlines, internal/cell.hpp); the report does not
// depend on them.
[[nodiscard]] Report build_report(const planner::PlanResult& result);

// The `chosen` record of plan instance `instance` (an index into result.instances) with its phase
// 2 analysis (nullptr: the instance's steps only). The probabilistic analysis is the chosen
// instance's: it is added only when `instance` is result.chosen_index and `analysis` is
// result.chosen_analysis().
[[nodiscard]] Chosen build_chosen(const planner::PlanResult& result, std::size_t instance,
                                  const planner::InstanceAnalysis* analysis);

// A bound result with its witnesses named by the box's variables; `seconds` is the wall-clock
// time it took.
[[nodiscard]] BoundRecord bound_record(const bounds::Box& box, const bounds::BoundResult& result,
                                       double seconds, std::optional<std::string> name = {});

}  // namespace spar::reports
