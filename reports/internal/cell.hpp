// The work cell of a report (model.hpp's Cell), built from the planner's result (reports/ only).
//
// It walks the plan's steps in execution order keeping every object's ideal pose (initial, then
// where each putdown or assembly leaves it) and which one the gripper holds, and makes a view of
// the initial state and after every pickup, putdown and assembly: each object's silhouette from
// above and from the front (its mesh's triangles projected and united, internal/silhouette.hpp),
// the gripper's (geometry::gripper_body, open or closed on the grasp), and the box of positions
// the handled object may occupy. That box is sound: phase 2's propagation is replayed over the
// same steps and the object's pose error (held: as if released where it is, with that motion's
// arm error) is bounded over the instance's uncertainty variables. Views get no box when phase 2
// did not run. The outlines are made after the walk, as tasks on the threads the plan ran on
// (PlanResult::analysis.threads, common/parallel.hpp); the cell does not depend on them.
//
// Example:
//   const Cell cell = build_cell(result, chosen, result.chosen(), result.chosen_analysis());
//   cell.views.front().title;   // "initial state"
#pragma once

#include "spar/planner/plan.hpp"
#include "spar/reports/model.hpp"

namespace spar::reports::internal {

// `chosen` is the report's record of `instance` (its steps name the views); `analysis` is that
// instance's phase 2 analysis or nullptr.
[[nodiscard]] Cell build_cell(const planner::PlanResult& result, const Chosen& chosen,
                              const planner::PlanInstance& instance,
                              const planner::InstanceAnalysis* analysis);

}  // namespace spar::reports::internal
