// Deciding: whether each uncertainty precondition of a step holds over the box of the instance's
// uncertainty variables (seed 001, "Satisfying Uncertainty-Reduction Goals", with SUP/INF).
//
// A precondition `f rel t` is satisfied only when the SOUND bound of f over the box proves it,
// violated when an attained value (a witness point) breaks it, undecided otherwise
// (bounds/inequality.hpp). The step's preconditions are decided together, cheapest first: one tape
// for all of them, the natural interval pass and the value at the box centre; a quick bound
// (`quick`) where that cannot tell; the full bound (`full`) only where the quick one cannot.
//
// Invariants: PreconditionResult::variables are the expression's variables as ids of the space it
// was decided in, ascending; box[i] is the range of variables[i] there; witness (when not empty)
// is a point of that box in the same order.
// Cost: one tape evaluation over intervals and one at the centre per step; a bound only for the
// preconditions the natural pass leaves undecided. DecisionCache remembers whole steps: phase 2's
// repair search replays the same steps over the same boxes many times; CompiledStep keeps one
// step's compiled problems for many boxes (the sensor margin's scales).
//
// Example:
//   const std::vector<Precondition> built = propagation.step(step, 1);
//   const std::vector<PreconditionResult> results =
//       decide(built, propagation.space(), {.tolerance = 1e-2, .max_box_evaluations = 300}, {});
//   for (const PreconditionResult& r : results) std::cout << bounds::to_string(r.verdict) << '\n';
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/bounds/condition_set.hpp"
#include "spar/bounds/inequality.hpp"
#include "spar/planner/uncertainty/builders.hpp"
#include "spar/planner/uncertainty/space.hpp"

namespace spar::planner {

// Which stage of deciding settled a precondition (the header comment's order).
enum class DecidedBy { kNaturalPass, kQuickBound, kFullBound };

struct PreconditionResult {
  Builder kind{Builder::kPickup};  // the builder that made it
  bounds::Inequality inequality;
  bool length{true};     // the expression is a length in metres (else dimensionless)
  std::size_t nodes{0};  // DAG nodes of the expression
  bounds::Verdict verdict{bounds::Verdict::kUndecided};
  DecidedBy decided_by{DecidedBy::kNaturalPass};  // the last stage tried (undecided: the full)
  bounds::BoundResult bound;
  std::vector<VariableId> variables;  // the step's variables (ascending ids), in box order
  std::vector<bounds::Interval> box;  // their ranges
  std::vector<double> witness;        // the worst point found (variables order)
  // Beyond SPAR (chosen instance only; empty / nullopt otherwise):
  struct Blame {
    VariableId variable;
    double share{0.0};  // fraction of the natural enclosure's width removed by pinning it
  };
  std::vector<Blame> blame;                     // largest share first
  std::optional<double> holds_up_to_scale;      // reverse analysis: proved for scales <= this
  std::optional<double> monte_carlo_violation;  // fraction of samples violating
  std::size_t monte_carlo_samples{0};           // behind it (fewer when proved: proved_share)
};

// The variables of `expressions` as ids of `space`, ascending. Throws PlanError for a variable
// that is not the space's.
[[nodiscard]] std::vector<VariableId> variables_of(std::span<const symbolic::Expr> expressions,
                                                   const UncertaintySpace& space);

// The precondition's expression in spar's infix syntax (parseable by `spar bound`), or "" when
// its tree form exceeds 1e7 nodes (joint uncertainty composes the chain's rotations; `nodes` is
// the DAG's). Printed on demand, for the reports: printing every examined instance's
// preconditions took 8% of analysing one.
[[nodiscard]] std::string printed_expression(const PreconditionResult& result);

// Sound enclosures of `expressions` over the current ranges of their variables in `space`: the
// natural interval extension, one interval pass over one tape of them all (cost O(DAG nodes of
// them together); each enclosure is the one a tape of that expression alone gives). Throws
// PlanError for a variable that is not the space's.
[[nodiscard]] std::vector<bounds::Interval> natural_enclosures(
    std::span<const symbolic::Expr> expressions, const UncertaintySpace& space);

// A step's preconditions compiled once (one ConditionSet tape; a BoundProblem per expression
// the natural pass leaves undecided, built on first need and kept, with its SMP rewrites per box
// widths) and decided over the current ranges of any space holding the same variables (the same
// ids): what decide() answers, without compiling again. Phase 2's sensor margin decides one step
// at many residual scales this way (Propagation::set_sensor_scale changes ranges only).
// A result does not depend on earlier calls (ConditionSet and BoundProblem guarantee it).
class CompiledStep {
 public:
  CompiledStep(const std::vector<Precondition>& preconditions, const UncertaintySpace& space);
  // With `ids` = variables_of(the preconditions' expressions, space), known already.
  CompiledStep(const std::vector<Precondition>& preconditions, const UncertaintySpace& space,
               std::vector<VariableId> ids);
  // Gives up (nullopt) once `give_up_after` preconditions are known not to be satisfied
  // (bounds::ConditionSet::decide_all); never without it.
  [[nodiscard]] std::optional<std::vector<PreconditionResult>> decide(
      const UncertaintySpace& space, const bounds::BoundOptions& quick,
      const bounds::BoundOptions& full,
      std::size_t give_up_after = std::numeric_limits<std::size_t>::max());
  // Whether decide() would find every precondition satisfied, stopping at the first that is not.
  [[nodiscard]] bool all_hold(const UncertaintySpace& space, const bounds::BoundOptions& quick,
                              const bounds::BoundOptions& full);

 private:
  std::vector<Precondition> preconditions_;
  std::vector<VariableId> ids_;
  std::optional<bounds::ConditionSet> set_;
};

// Decides `preconditions` over the space's current ranges (see the header comment).
[[nodiscard]] std::vector<PreconditionResult> decide(const std::vector<Precondition>& preconditions,
                                                     const UncertaintySpace& space,
                                                     const bounds::BoundOptions& quick,
                                                     const bounds::BoundOptions& full);

// What a caller needs of a step's decision.
enum class Need {
  kBounds,    // decide()'s results
  kVerdicts,  // the same verdicts; a precondition a witness breaks before any box is bounded
              // keeps the natural enclosure as its bound (bounds::BoundOptions::stop_at_witness)
};

// decide() with memory: a step whose preconditions (expressions, relations, thresholds, kinds) and
// variables (symbols and ranges, in the order of their ids) equal those of a step decided before
// gets the earlier results, with PreconditionResult::variables the ids of those symbols in the
// space asked (a replay with a step spliced in earlier shifts the ids, not the symbols: see
// Phase2Step::label). decide() is a deterministic function of exactly these (and of the options,
// fixed per cache), so a hit returns what deciding again would return.
// Invariants: every entry was computed with the options given at construction, with
// stop_at_witness where `Need::kVerdicts` asked; an entry is `exact` (decide()'s results) unless
// one of its bounds stopped at a witness. A kBounds request never gets an entry that is not
// exact: it decides the step again and replaces the entry.
// Cost: a key is O(preconditions + variables) to build; a hit costs a map lookup and a copy.
class DecisionCache {
 public:
  DecisionCache(bounds::BoundOptions quick, bounds::BoundOptions full)
      : quick_(std::move(quick)), full_(std::move(full)) {}
  [[nodiscard]] std::vector<PreconditionResult> decide(
      const std::vector<Precondition>& preconditions, const UncertaintySpace& space,
      Need need = Need::kBounds);
  // decide(..., Need::kVerdicts) where every precondition is satisfied; nullopt, and nothing
  // kept, once one is known not to be (CompiledStep::decide giving up after one).
  [[nodiscard]] std::optional<std::vector<PreconditionResult>> decide_if_all_hold(
      const std::vector<Precondition>& preconditions, const UncertaintySpace& space);
  [[nodiscard]] std::size_t hits() const { return hits_; }
  [[nodiscard]] std::size_t misses() const { return misses_; }  // steps decided

 private:
  struct Entry {
    std::vector<PreconditionResult> results;
    bool exact{true};
  };
  // decide() giving up once `give_up_after` preconditions are known not to be satisfied.
  [[nodiscard]] std::optional<std::vector<PreconditionResult>> decide_giving_up(
      const std::vector<Precondition>& preconditions, const UncertaintySpace& space, Need need,
      std::size_t give_up_after);
  bounds::BoundOptions quick_, full_;
  std::map<std::vector<std::uint64_t>, Entry> entries_;
  std::size_t hits_{0}, misses_{0};
};

}  // namespace spar::planner
