// Margins: the chosen instance's extras (seed 001's uncertainty report: how far each precondition
// is from failing, and why), added to an analysed instance once phase 2 has chosen it. Per
// precondition, as AnalysisOptions enable them:
//   tight bound   the bound with inner values (options.report; the natural pass that decided a
//                 satisfied precondition has none): [lo, hi] only shrinks, so the verdict stands;
//                 the witness is then the worst point of that bound;
//   blame         per variable, the share of the width of the mean-value enclosure over the box
//                 that goes when that variable is pinned to its nominal value 0
//                 (bounds::BoundProblem::width_shares: one interval gradient, first order: which
//                 variables take up the bound, not a bound), largest first;
//   Monte Carlo   the fraction of `samples` uniform points of the box where the inequality is
//                 false (on the expression's tape); a violation sampled for a precondition reported
//                 satisfied would be a soundness bug. A proved precondition's share is 0 by
//                 soundness, so its sampling is only that self-check and uses
//                 samples / proved_share points (PreconditionResult::monte_carlo_samples says how
//                 many). Each precondition draws from its own stream, seeded by its step and
//                 place, so its estimate does not depend on the others;
//   reverse       the largest uniform scale s in [0, max_scale] of the uncertainty of the objects
//                 it depends on (their initial / sensed variables, the arm's too when
//                 `scale_manipulator`) for which it is PROVED to hold: a bisection
//                 (internal/bisection.hpp) in which every accepted scale is a satisfied verdict
//                 (each scale decided, one side, early exit, no NLopt witness search), guided
//                 once a scale failed near the answer (the gap its bound kept says how far below
//                 the answer lies): the bisection's answer, in fewer of the costly decisions.
//
// Invariants: a step's preconditions share its variables and box, so two with one expression (the
// two sides of a clearance) have one tight bound and one blame, computed once; no verdict changes
// (a tight bound only shrinks [lo, hi]); every result field is a function of the precondition
// alone, so the margins do not depend on how the work is split or scheduled.
// Threads: the work splits into tasks that share nothing mutable, each on its own copy of one
// expression in a pool of its own (symbolic::copy_into: the same tape, so the same bounds as on
// the original), run on options.threads threads (common/parallel.hpp): one task per
// precondition (Monte Carlo, reverse analysis), the first of each expression in a step also with
// the tight bound and blame, on one compiled problem (the reverse analysis reuses the tight
// bound's SMP rewrite). Tasks are numbered costliest first (DAG nodes x variables), so that the
// threads finish together.
// Cost: a tight bound is up to report.max_box_evaluations boxes; a reverse analysis at most 2 +
// 3 x reverse_iterations decisions (2 + reverse_iterations unguided) of up to
// quick.max_box_evaluations boxes each (most settle in one box; those near the answer take ~100:
// on on-back's insertion, 3 such instead of 7); Monte Carlo `samples` tape evaluations.
//
// Example:
//   InstanceAnalysis analysis = analyse_instance(world, domain, instance, options);
//   AnalysisOptions extras = options;
//   extras.threads = spar::default_threads();
//   add_margins(analysis, extras);    // or MarginWork's parts, beside other work
//   std::cout << *analysis.steps[0].preconditions[0].holds_up_to_scale << '\n';
#pragma once

#include <cstddef>
#include <functional>
#include <string_view>
#include <vector>

#include "spar/planner/uncertainty/analysis.hpp"

namespace spar::planner {

// Adds the extras above to `analysis` (its expressions' pool is only read). `progress`, when
// set, is told on the calling thread how many tasks are done ("phase 2: margins: 12 of 40 done").
void add_margins(InstanceAnalysis& analysis, const AnalysisOptions& options,
                 const std::function<void(std::string_view stage)>& progress = {});

// add_margins in parts, for a caller that runs other work beside the margins on the same
// threads (plan(): the probability's Monte Carlo and the tolerance allocation,
// probability.hpp's ProbabilityWork). The constructor makes the tasks and their copies: it reads
// the analysis' pool, so it runs on the thread that owns the pool. run(t) does task t, on any
// thread, each task once, several at a time; the tasks write only their own preconditions'
// margin fields (bound, blame, Monte Carlo, holds_up_to_scale), so other work may read the
// analysis' other fields meanwhile. finish(), after every task, gives the second side of a
// clearance its first side's bound and blame and sets every witness.
class MarginWork {
 public:
  MarginWork(InstanceAnalysis& analysis, const AnalysisOptions& options);
  ~MarginWork();
  [[nodiscard]] std::size_t tasks() const;
  void run(std::size_t task);
  void finish();

 private:
  struct Task;  // one precondition's margins, on its own copy of the expression
  InstanceAnalysis* analysis_;
  AnalysisOptions options_;
  std::vector<Task> tasks_;
  std::vector<std::vector<std::size_t>> first_of_;  // per step and precondition: the first
                                                    // of its expression in the step
};

}  // namespace spar::planner
