// plan(): the planner's one entry point. From a scenario and a domain to a plan family (phase 1:
// constraint posting, planner/posting.hpp) and its plan instances (planner/instances.hpp); phase 2
// (planner/uncertainty/analysis.hpp) examines the instances in order and chooses the first without
// errors, else the one with the fewest. The chosen instance then gets its margins
// (planner/uncertainty/margins.hpp) and, unless PlanOptions::probability is nullopt, the
// probabilistic analysis (planner/uncertainty/probability.hpp: σ, P(violation) first-order and
// Monte Carlo per precondition) and the tolerance allocation, all three as one set of tasks.
//
// A scenario with an uncertain object (docs/scenario.md: `identity: [...]`, `pose: {stable:
// [...]}`) is not planned as such: sense planning (planner/sense_planning.hpp) chooses the
// operations that tell its hypotheses apart, and each hypothesis is then planned as the truth, one
// branch per outcome (the survey's section 3 before SPAR's phases). One uncertain object per
// scenario: a second one is refused (spar sense-plan handles several).
//
// Example:
//   const PlanResult result = plan(load_scenario("examples/peg_block_face_down.yaml"),
//                                  builtin_domain());
//   if (result.planned())
//     for (const InstanceStep& step : result.chosen().steps) std::cout << step.action_name << '\n';
#pragma once

#include <cstddef>
#include <functional>
#include <list>
#include <optional>
#include <string_view>
#include <vector>

#include "spar/planner/domain.hpp"
#include "spar/planner/instances.hpp"
#include "spar/planner/posting.hpp"
#include "spar/planner/scenario.hpp"
#include "spar/planner/sense_planning.hpp"
#include "spar/planner/uncertainty/analysis.hpp"
#include "spar/planner/uncertainty/margins.hpp"
#include "spar/planner/uncertainty/probability.hpp"
#include "spar/planner/world.hpp"

namespace spar::planner {

struct PlanOptions {
  PostingOptions posting{};
  std::size_t max_instances{16};  // plan instances enumerated (labelings x linearizations)
  bool uncertainty{true};         // run phase 2 (else the first instance is chosen)
  AnalysisOptions analysis{};
  // The chosen instance's probabilistic analysis and tolerance allocation
  // (planner/uncertainty/probability.hpp); nullopt: off.
  std::optional<ProbabilityOptions> probability{ProbabilityOptions{}};
  // Threads for the parts of one plan that split into independent tasks (common/parallel.hpp):
  // the world model's grasp searches, the instances after a first with errors, and the chosen
  // instance's margins, Monte Carlo and tolerance allocation (plan() sets analysis.threads from
  // it). The result does not depend on it.
  unsigned threads{1};
  // Called as each stage starts, with a short text for a progress display ("phase 1: constraint
  // posting", "phase 2: plan instance 2 of 16", ...); from the calling thread. Empty: none.
  std::function<void(std::string_view stage)> progress{};
};

struct PlanBranch;

struct PlanResult {
  WorldModel world;
  Domain domain;
  PlanFamily family;
  InstanceList instances;  // empty unless the family is planned
  // Phase 2: the instances examined, in order (it stops at the first without errors). Only the
  // chosen one has its failed steps' sensor margins and its margins (AnalysedStep::
  // sensor_scale_needed, PreconditionResult's tight bound, blame, reverse, Monte Carlo).
  std::vector<InstanceAnalysis> examined;
  std::size_t chosen_index{0};  // into instances.instances
  // PlanOptions::probability on the chosen instance, when phase 2 ran (else nullopt).
  std::optional<ProbabilityAnalysis> probability;
  std::optional<ToleranceAllocation> tolerances;
  // The chosen plan's steps in phase 2's order (inserted ones included), each step's collision
  // check and what it carries: an instance step's own, a squeeze's where phase 2 put it. Empty
  // unless phase 2 ran.
  std::vector<std::pair<StepCheck, std::vector<int>>> chosen_checks;
  // The options phase 2 ran with (a report says when a margin is its search's cap, max_scale).
  AnalysisOptions analysis{};
  // The chosen instance's analysis, or nullptr when phase 2 did not run.
  [[nodiscard]] const InstanceAnalysis* chosen_analysis() const;

  // With an uncertain object: the operations chosen for it, and one branch per hypothesis (in
  // hypothesis order), each planned like any scenario; `family`, `instances` and `examined` are
  // then empty. Without branches (the operations cannot tell the hypotheses apart),
  // `family.reason` says why.
  std::optional<ObjectSensePlan> sensing{};
  // A list: PlanResult does not move without the chance of throwing, so a growing vector would
  // copy it, and the phase 2 analyses it holds do not copy.
  std::list<PlanBranch> branches{};

  // Phase 1 found a plan; with an uncertain object: there are branches and every one is planned.
  [[nodiscard]] bool planned() const;
  // Throws PlanError when there is no instance.
  [[nodiscard]] const PlanInstance& chosen() const;
};

// One outcome of sensing: the scenario with the uncertain object as hypothesis `outcome` has it.
struct PlanBranch {
  std::string object;
  std::string outcome;  // the hypothesis' label: "P1", "cube", "cube:P3"
  PlanResult result;
};

// Throws ScenarioError/PlanError for a scenario that cannot be planned at all (no goals, an object
// without grasps); a search that finds no plan is a result with family.status != kPlanned.
[[nodiscard]] PlanResult plan(Scenario scenario, const Domain& domain,
                              const PlanOptions& options = {});

}  // namespace spar::planner
