// Phase 2 of SPAR on one plan instance (seed 001, "Satisfying Uncertainty-Reduction Goals"; survey
// text around fig. 8): propagate the uncertain poses through the steps, decide every uncertainty
// precondition by bounding, repair failures by sensing or squeezing, otherwise post verification
// and recovery and count the error. choose_instance() examines instances in order and keeps the
// first with no error, else the one with the fewest (the earliest among equals).
//
// For each step in execution order (planner/uncertainty/propagation.hpp builds the preconditions
// from the state just before it):
//   1. decide its preconditions together (planner/uncertainty/deciding.hpp); a precondition fails
//      unless it is satisfied (violated and undecided both fail; undecided is reported as such);
//   2. if one fails, search the sets of range-scans and squeezes that fit before it
//      (planner/uncertainty/repair.hpp): a set is kept only if it turns some verdict to satisfied
//      without failing more steps, the smallest set among the best; each kept insertion records
//      the verdicts it turned, and the search what it tried and dropped (counts per kind);
//   3. if none helps: the error count goes up by one, and the step gets the verification
//      templates its action names and, per outcome, the recovery plan, instantiated with the
//      plan's values.
// While it searches, a step's variables are named after its Phase2Step::label, which a splice does
// not move (replays rebuild the same expressions, and DecisionCache answers them); the result is
// numbered by execution position (dx_g<position>, ...), as the reports show the steps. A set's
// replay decides for verdicts only (Need::kVerdicts: a set is scored by verdicts); the kept set's
// steps are then taken as its replay propagated them, and decided for the report's bounds.
// A failed step (any instance) also gets its sensor margin, the largest residual scale of the
// range-scan that would make it hold (AnalysedStep::sensor_scale_needed); with
// options.defer_sensor_margins only once add_sensor_margins() runs (plan(): the chosen instance's,
// by analyse_instances beside a later round or after the choice).
// The chosen instance's margins (planner/uncertainty/margins.hpp: tight bounds, blame, Monte Carlo
// and the reverse analysis of every precondition) are added to it after the choice.
//
// Example:
//   const std::vector<InstanceAnalysis> examined = analyse_instances(world, domain, instances);
//   const InstanceAnalysis& best = examined[choose_instance(examined)];
//   std::cout << best.errors << " errors\n";
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "spar/bounds/condition_set.hpp"
#include "spar/planner/instances.hpp"
#include "spar/planner/uncertainty/deciding.hpp"
#include "spar/planner/uncertainty/propagation.hpp"
#include "spar/planner/uncertainty/repair.hpp"
#include "spar/planner/vision.hpp"

namespace spar::planner {

struct VerificationPlan {
  std::string name;   // the verification template
  std::string sense;  // instantiated text
  std::string expect;
  struct Outcome {
    std::string when;
    std::string error;
    std::string recovery;                     // the recovery template's name
    std::vector<std::string> recovery_steps;  // instantiated
  };
  std::vector<Outcome> outcomes;
  std::optional<VisionCheck> vision;  // what a camera must see to accept (scenarios with cameras)
};

// One examined step (execution order), original or inserted by phase 2.
struct AnalysedStep {
  Phase2Step step;
  std::string action;  // template name
  bool inserted{false};
  std::vector<PreconditionResult> preconditions;
  bool failed{false};  // some precondition does not hold (after repair attempts)
  std::vector<VerificationPlan> verification;
  // Reverse analysis of the sensor, for a failed step: the largest scale s of the range-scan
  // residual (s times the scenario's) for which scanning the objects the step concerns would PROVE
  // every precondition of the step; nullopt when even a perfect sensor would not (or none exists).
  std::optional<double> sensor_scale_needed;
  // An inserted camera verification (Phase2Step::camera): what PSEIKI must see to accept.
  std::optional<VisionCheck> camera_verification;
  // A sensing step: the pose components its reading corrects (the executor keeps its belief in
  // the others, already known better than the residual; planner/uncertainty/propagation.hpp).
  std::vector<PoseComponent> corrects;
};

// A range-scan or squeeze phase 2 kept in the plan (planner/uncertainty/repair.hpp) to repair the
// failing instance step `for_instance_step`; the inserted step's Phase2Step::repair indexes it.
struct RepairAttempt {
  std::string action;  // the domain's sense or reduce action
  int object{-1};
  int for_instance_step{-1};  // the instance step (PlanInstance::steps index) that failed
  bool helped{true};          // kept insertions only: true
  // Bounds of the failing step's preconditions without and with the kept set.
  std::vector<bounds::BoundResult> before, after;
  std::vector<bounds::Verdict> verdicts_before, verdicts_after;
  // The verdicts this insertion turned to satisfied: satisfied with the kept set, not without it.
  std::vector<PreconditionRef> turned;
};

// The repair search for one failing instance step: what was tried, kept and dropped.
struct RepairSearch {
  int for_instance_step{-1};
  int candidates{0};  // range-scans and squeezes that fit before the step
  int sets_tried{0};
  int kept{0};
  std::map<std::string, int> dropped;  // candidates not kept, per kind (range-scan, squeeze)
  bool holds{false};                   // the step holds with the kept set
};

struct InstanceAnalysis {
  std::size_t instance{0};  // index into the instance list
  std::vector<AnalysedStep> steps;
  std::vector<RepairAttempt> repairs;         // kept insertions, in the order they were kept
  std::vector<RepairSearch> repair_searches;  // one per failing instance step searched
  // The final space: every variable with provenance (variables[id.index]) and its symbol in `pool`.
  std::vector<SpaceVariable> variables;
  std::vector<symbolic::Expr> symbols;
  int errors{0};
  // Step decisions made and reused (DecisionCache misses and hits: the repair search and the
  // resumed analysis after a repair decide steps again).
  std::size_t steps_decided{0}, steps_reused{0};
  // Analysed with options.reverse and defer_sensor_margins, and add_sensor_margins() has not run.
  bool sensor_margins_pending{false};
  std::unique_ptr<symbolic::ExprPool> pool;  // owns every expression above
};

struct AnalysisOptions {
  // Deciding: a quick bound first, the full one only where that leaves a precondition undecided.
  bounds::BoundOptions quick{.tolerance = 1e-2, .max_box_evaluations = 300};
  bounds::BoundOptions bound{.tolerance = 1e-3, .max_box_evaluations = 20'000};
  // The chosen instance's reported bounds (with inner values) use `report`, its reverse analysis
  // `quick` (deciding each scale).
  bounds::BoundOptions report{.tolerance = 1e-3, .max_box_evaluations = 5'000};
  bool repair{true};      // try range-scans and squeezes
  int squeeze_grasps{4};  // squeezes tried per failing step (other grasps than the pickup's)
  // Chosen-instance extras:
  bool reverse{true};
  double max_scale{8.0};          // reverse analysis searches scales in [0, max_scale]
  int reverse_iterations{12};     // bisection steps (resolution max_scale / 4096)
  bool scale_manipulator{false};  // also scale the arm's variables
  // Leave AnalysedStep::sensor_scale_needed empty for add_sensor_margins() to fill in later:
  // plan() examines its instances so and adds the chosen one's only (on on-back the three
  // instances' sensor margins were a third of their analysis).
  bool defer_sensor_margins{false};
  bool blame{true};
  std::size_t samples{2000};  // Monte Carlo samples per precondition (0: off)
  // A proved precondition's Monte Carlo is a self-check (its share is 0 by soundness): it draws
  // samples / proved_share points (at least one; 1: as many as any other).
  std::size_t proved_share{10};
  // Threads (common/parallel.hpp; 1: the calling thread only) for analyse_instances (after a
  // first instance with errors, the next ones that many at a time) and the margins. The results
  // do not depend on it. plan() sets it from PlanOptions::threads.
  unsigned threads{1};
};

// The instance's steps as phase 2 sees them, each labelled instance_step + 1 (Phase2Step::label).
[[nodiscard]] std::vector<Phase2Step> phase2_steps(const Domain& domain,
                                                   const PlanInstance& instance);

// Phase 2 on one instance. Throws PlanError if the instance does not fit its world.
[[nodiscard]] InstanceAnalysis analyse_instance(const WorldModel& world, const Domain& domain,
                                                const PlanInstance& instance,
                                                const AnalysisOptions& options = {});

// The sensor margins (AnalysedStep::sensor_scale_needed, when options.reverse) of an analysis
// made with options.defer_sensor_margins, as analyse_instance would have given them: the steps
// are propagated again to the last failed one (same labels, so the same expressions in
// analysis.pool). Does nothing unless analysis.sensor_margins_pending (they are there already)
// or without options.reverse. Extends the pool: not beside other work that reads it. Throws
// PlanError for an analysis without a pool (not one analyse_instance made).
void add_sensor_margins(const WorldModel& world, const Domain& domain, InstanceAnalysis& analysis,
                        const AnalysisOptions& options);

// The instance SPAR would choose: the first with no error, else the fewest (earliest on ties).
[[nodiscard]] std::size_t choose_instance(const std::vector<InstanceAnalysis>& examined);

// Examines `instances` in order until one has no error; returns every examined analysis (with
// options.threads > 1, the ones after a first with errors are analysed that many at once, the
// same analyses one at a time gives). With options.defer_sensor_margins and threads > 1, such a
// round also adds the sensor margins of the instance leading so far (choose_instance among those
// examined before it; plan() chooses it unless a later one has fewer errors): the round's
// analyses seldom take equal time, and the thread done first would wait. The chosen one's extras
// (tight bounds, blame, reverse analysis, Monte Carlo) are a separate step: add_margins
// (margins.hpp; plan() runs them beside the probability). `progress`, when set, is told each
// instance as it starts ("phase 2: plan instance 2 of 16").
[[nodiscard]] std::vector<InstanceAnalysis> analyse_instances(
    const WorldModel& world, const Domain& domain, const std::vector<PlanInstance>& instances,
    const AnalysisOptions& options = {},
    const std::function<void(std::string_view stage)>& progress = {});

}  // namespace spar::planner
