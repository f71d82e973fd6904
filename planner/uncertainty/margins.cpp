#include "spar/planner/uncertainty/margins.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/bounds/inequality.hpp"
#include "spar/common/parallel.hpp"
#include "spar/planner/uncertainty/internal/bisection.hpp"
#include "spar/planner/uncertainty/internal/own_copy.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::planner {
namespace {

using bounds::Interval;
using bounds::Verdict;
using symbolic::Expr;

// PreconditionResult::blame: per variable, the share of the mean-value enclosure's width that goes
// when it is pinned to its nominal value 0 (BoundProblem::width_shares), largest first.
void add_blame(PreconditionResult& result, bounds::BoundProblem& problem) {
  std::vector<double> nominal(result.box.size());
  for (std::size_t v = 0; v < nominal.size(); ++v)
    nominal[v] = std::clamp(0.0, result.box[v].lo, result.box[v].hi);
  const std::vector<double> shares = problem.width_shares(result.box, nominal);
  result.blame.clear();
  for (std::size_t v = 0; v < shares.size(); ++v)
    result.blame.push_back({result.variables[v], shares[v]});
  std::stable_sort(result.blame.begin(), result.blame.end(),
                   [](const auto& a, const auto& b) { return a.share > b.share; });
}

// PreconditionResult::monte_carlo_violation: the fraction of `samples` uniform points of the box
// where the inequality, with expression f over `inputs`, is false.
void add_monte_carlo(PreconditionResult& result, Expr f, std::span<const Expr> inputs,
                     std::size_t samples, std::mt19937_64& random) {
  const symbolic::Tape tape = symbolic::Tape::compile({&f, 1}, inputs);
  symbolic::TapeEvaluator<double> evaluator(tape);
  std::size_t violations = 0;
  std::vector<double> point(inputs.size());
  double value[1];
  for (std::size_t s = 0; s < samples; ++s) {
    for (std::size_t v = 0; v < inputs.size(); ++v)
      point[v] = std::uniform_real_distribution<double>(result.box[v].lo, result.box[v].hi)(random);
    evaluator.evaluate(point, value);
    if (!holds(value[0], result.inequality.relation, result.inequality.threshold)) ++violations;
  }
  result.monte_carlo_violation = static_cast<double>(violations) / samples;
  result.monte_carlo_samples = samples;
}

// The reverse analysis' guess (internal/bisection.hpp) of where a precondition stops being
// proved. Values are oriented so that larger is worse (f for `<`, `<=`; -f for `>`, `>=`); per
// scale deciding gives the bound's side and the worst value it attained (early exit: a proof stops
// once the side is within the limit, a refutation at the first witness past it). A scale that
// failed WITHOUT such a witness failed near the answer: its side is where branch and bound got to
// with the whole budget, what a proof there would have had to bring within the limit. Only with
// such a failure at the bracket's failing end is there a guess: where the line through it and the
// next such failure above it meets the limit; with none above, the line through it and the proved
// end, whose side is taken as its attained value plus the room the failure kept (side - attained),
// at most its own side (a cheap proof attains little and stops with a loose side). Before, the
// search bisects (far from the answer the decisions are cheap anyway).
class ScaleGuess {
 public:
  explicit ScaleGuess(const bounds::Inequality& inequality)
      : sign_(inequality.relation == bounds::Relation::kLess ||
                      inequality.relation == bounds::Relation::kLessEqual
                  ? 1.0
                  : -1.0),
        limit_(sign_ * inequality.threshold) {}

  void record(double scale, const bounds::BoundResult& bound) {
    if (bound.has_inner_range())
      seen_[scale] = sign_ > 0 ? Seen{bound.inner_hi, bound.hi} : Seen{-bound.inner_lo, -bound.lo};
  }

  double operator()(double good, double bad) const {
    const double none = std::numeric_limits<double>::quiet_NaN();
    const auto failed_near = [&](const Seen& s) { return s.attained < limit_ && s.side > limit_; };
    const auto b = seen_.find(bad);
    if (b == seen_.end() || !failed_near(b->second)) return none;
    const auto above = std::find_if(std::next(b), seen_.end(),
                                    [&](const auto& s) { return failed_near(s.second); });
    if (above != seen_.end()) {
      const double slope = (above->second.side - b->second.side) / (above->first - bad);
      return slope > 0 ? bad - (b->second.side - limit_) / slope : none;
    }
    const auto g = seen_.find(good);
    if (g == seen_.end()) return none;
    const double room = b->second.side - b->second.attained;
    const double good_side = std::min(g->second.side, g->second.attained + room);
    return good + (bad - good) * (limit_ - good_side) / (b->second.side - good_side);
  }

 private:
  struct Seen {
    double attained, side;  // oriented: larger is worse
  };
  double sign_, limit_;
  std::map<double, Seen> seen_;  // by scale
};

// PreconditionResult::holds_up_to_scale: the largest s in [0, max_scale] for which the inequality
// is PROVED over the box whose objects' ranges (and the arm's, if asked) are s times the space's.
// Each scale is decided, not bounded tightly (BoundOptions::decide: one side, early exit); a scale
// counts only when the sound bound proves it. The scales probed are guided by ScaleGuess: the
// answer is the bisection's (monotone verdicts), in fewer decisions near it.
std::optional<double> proved_scale(const PreconditionResult& result, bounds::BoundProblem& problem,
                                   const std::vector<SpaceVariable>& variables,
                                   const AnalysisOptions& options) {
  bounds::BoundOptions deciding = options.quick;
  deciding.decide = bounds::DecisionTarget{result.inequality.relation, result.inequality.threshold};
  deciding.inner = false;  // only a proof counts here: NLopt's violating witness would not
  // Every scale shares the SMP rewrite of the reported box, not one rewrite per scale: half the
  // time of this analysis went into building them.
  for (const Interval& range : result.box) deciding.rewrite_widths.push_back(range.width());
  ScaleGuess guess(result.inequality);
  const auto proved_at = [&](double scale) {
    std::vector<Interval> box = result.box;
    for (std::size_t v = 0; v < box.size(); ++v) {
      const SpaceVariable& meta = variables[result.variables[v].index];
      if (of_the_arm(meta.provenance.source) && !options.scale_manipulator) continue;
      box[v] = Interval(meta.lower * scale, meta.upper * scale);
    }
    const bounds::BoundResult bound = problem.bound(box, deciding);
    guess.record(scale, bound);
    return bounds::decide(result.inequality, bound) == Verdict::kSatisfied;
  };
  if (!proved_at(0.0)) return std::nullopt;
  return internal::largest_holding(0.0, options.max_scale, options.reverse_iterations, proved_at,
                                   guess);
}

}  // namespace

// The margins of analysis.steps[step].preconditions[index], over its own copy of the
// precondition (internal/own_copy.hpp), so that it may run on any thread: it writes only its own
// fields of that precondition.
struct MarginWork::Task {
  bool tight_bound;  // bound and blame too: the first precondition of its expression in the step
  std::size_t step, index;
  internal::OwnCopy copy;
  // What the task is expected to cost, in no unit; only the order matters. A tight bound, a
  // reverse analysis and the sampling each evaluate the expression's DAG per box or point, and
  // branch and bound splits along the box's variables, so nodes x variables, the tight bound's
  // task counted twice (on on-back's insertion these tasks take 10-14 ms, a pickup's 0.2-1).
  [[nodiscard]] std::size_t expected_cost(const PreconditionResult& result) const {
    return result.nodes * std::max<std::size_t>(1, result.box.size()) * (tight_bound ? 2 : 1);
  }
};

MarginWork::MarginWork(InstanceAnalysis& analysis, const AnalysisOptions& options)
    : analysis_(&analysis), options_(options), first_of_(analysis.steps.size()) {
  // One task per precondition, the first of each expression in a step with the tight bound its
  // second side (a clearance) shares; the copies made here, where the pool may be read.
  for (std::size_t k = 0; k < analysis.steps.size(); ++k) {
    std::map<std::uint32_t, std::size_t> by_expression;
    for (std::size_t i = 0; i < analysis.steps[k].preconditions.size(); ++i) {
      const PreconditionResult& result = analysis.steps[k].preconditions[i];
      const auto [first, fresh] = by_expression.try_emplace(result.inequality.expression.id(), i);
      first_of_[k].push_back(first->second);
      if (fresh || options.samples > 0 || options.reverse)
        tasks_.push_back({fresh, k, i, internal::own_copy(analysis, result)});
    }
  }
  // The costliest first (longest processing time first): run_tasks hands the tasks out in order,
  // so the last ones to start are short and the threads finish together. With the insertion's
  // tasks last, on-back's margins beside the tolerance allocation took 54 ms on two threads
  // where 41 suffice. The order changes no result: each task writes its own precondition's fields.
  const auto cost = [&](const Task& task) {
    return task.expected_cost(analysis.steps[task.step].preconditions[task.index]);
  };
  std::stable_sort(tasks_.begin(), tasks_.end(),
                   [&](const Task& a, const Task& b) { return cost(a) > cost(b); });
}

MarginWork::~MarginWork() = default;

std::size_t MarginWork::tasks() const { return tasks_.size(); }

void MarginWork::run(std::size_t t) {
  const Task& task = tasks_[t];
  PreconditionResult& result = analysis_->steps[task.step].preconditions[task.index];
  // One problem for the task's bounds: the reverse analysis reuses the SMP rewrite the tight
  // bound built for this box.
  std::optional<bounds::BoundProblem> problem;
  if (task.tight_bound || options_.reverse) problem.emplace(task.copy.f, task.copy.inputs);
  if (task.tight_bound) {
    // A tight bound with inner values: [lo, hi] only shrinks, so the verdict stands.
    result.bound = problem->bound(result.box, options_.report);
    if (options_.blame) add_blame(result, *problem);
  }
  if (options_.samples > 0) {
    // Each precondition its own stream: its estimate does not depend on how many points the
    // others drew (fewer for the proved ones).
    std::seed_seq seeds{std::size_t{20261201}, task.step, task.index};
    std::mt19937_64 random(seeds);
    const bool proved = result.verdict == Verdict::kSatisfied;
    add_monte_carlo(result, task.copy.f, task.copy.inputs,
                    proved
                        ? std::max<std::size_t>(
                              1, options_.samples / std::max<std::size_t>(1, options_.proved_share))
                        : options_.samples,
                    random);
  }
  if (options_.reverse)
    result.holds_up_to_scale = proved_scale(result, *problem, analysis_->variables, options_);
}

void MarginWork::finish() {
  // The second side of a clearance shares its expression's tight bound and blame.
  for (std::size_t k = 0; k < analysis_->steps.size(); ++k) {
    std::vector<PreconditionResult>& results = analysis_->steps[k].preconditions;
    for (std::size_t i = 0; i < results.size(); ++i) {
      if (first_of_[k][i] != i) {
        results[i].bound = results[first_of_[k][i]].bound;
        results[i].blame = results[first_of_[k][i]].blame;
      }
      results[i].witness = bounds::witness(results[i].inequality, results[i].bound);
    }
  }
}

void add_margins(InstanceAnalysis& analysis, const AnalysisOptions& options,
                 const std::function<void(std::string_view)>& progress) {
  MarginWork work(analysis, options);
  const std::string of_total = " of " + std::to_string(work.tasks()) + " done";
  run_tasks(
      work.tasks(), options.threads, [&](std::size_t t) { work.run(t); },
      [&](std::size_t finished) {
        if (progress) progress("phase 2: margins: " + std::to_string(finished) + of_total);
      });
  work.finish();
}

}  // namespace spar::planner
