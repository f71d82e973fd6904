#include "spar/planner/uncertainty/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "spar/bounds/interval.hpp"
#include "spar/planner/error.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::planner {
namespace {

using bounds::Interval;
using bounds::Verdict;
using symbolic::Expr;

// The first action with `effect` (the one phase 2 splices in for sensing or squeezing), or -1.
int find_action(const Domain& domain, Effect effect) {
  for (std::size_t a = 0; a < domain.actions.size(); ++a)
    if (domain.actions[a].effect == effect) return static_cast<int>(a);
  return -1;
}

std::vector<Phase2Step> phase2_steps(const Domain& domain, const PlanInstance& instance) {
  std::vector<Phase2Step> steps;
  for (std::size_t i = 0; i < instance.steps.size(); ++i) {
    const InstanceStep& source = instance.steps[i];
    Phase2Step step;
    step.action = source.action;
    step.effect = domain.actions[source.action].effect;
    step.object = source.object;
    step.grasp = source.grasp;
    step.position = source.is_assembly() ? -1 : source.position;
    step.fixed_object = source.fixed_object;
    step.object_pose = source.object_pose;
    step.fixed_pose = source.fixed_pose;
    step.instance_step = static_cast<int>(i);
    steps.push_back(step);
  }
  return steps;
}

bool all_hold(const std::vector<PreconditionResult>& results) {
  return std::all_of(results.begin(), results.end(),
                     [](const PreconditionResult& r) { return r.verdict == Verdict::kSatisfied; });
}

// held_before[i]: the object held just before step i, or -1 (gripper empty).
std::vector<int> held_before(const std::vector<Phase2Step>& steps) {
  std::vector<int> held(steps.size() + 1, -1);
  for (std::size_t i = 0; i < steps.size(); ++i) {
    held[i + 1] = held[i];
    if (steps[i].effect == Effect::kGrasp) held[i + 1] = steps[i].object;
    if (steps[i].effect == Effect::kRelease || steps[i].effect == Effect::kInsert) held[i + 1] = -1;
  }
  return held;
}

bool moves(const Phase2Step& step, int object) {
  return step.object == object && moves_object(step.effect);
}

// The latest position <= until where a range-scan of `object` fits: the gripper is empty and the
// object is not moved between there and `until`. -1 if none.
int scan_position(const std::vector<Phase2Step>& steps, int until, int object) {
  const std::vector<int> held = held_before(steps);
  for (int i = until; i >= 0; --i) {
    if (i < until && moves(steps[i], object)) return -1;
    if (held[i] == -1) return i;
  }
  return -1;
}

// The last grasp of `object` before `until`, or -1.
int grasp_position(const std::vector<Phase2Step>& steps, int until, int object) {
  for (int i = until; i >= 0; --i)
    if (steps[i].effect == Effect::kGrasp && steps[i].object == object) return i;
  return -1;
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

std::string length_text(const Units& units, double metres) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.4g %s", units.to_file_length(metres),
                std::string(units.length_name()).c_str());
  return buffer;
}

std::vector<VerificationPlan> verification_plans(const WorldModel& world, const Domain& domain,
                                                 const Phase2Step& step) {
  const Scenario& scenario = world.scenario();
  std::map<std::string, std::string> values;
  if (step.object >= 0) values["{object}"] = scenario.objects[step.object].name;
  if (step.fixed_object >= 0) values["{fixed}"] = scenario.objects[step.fixed_object].name;
  if (step.grasp >= 0) {
    const geometry::Grasp& grasp = world.object(step.object).grasps[step.grasp];
    values["{grasp}"] = grasp.label;
    values["{width}"] = length_text(scenario.units, grasp.width);
    values["{height}"] =
        length_text(scenario.units, (step.object_pose * grasp.gripper_in_object).translation().z());
  }
  const auto fill = [&](std::string text) {
    for (const auto& [key, value] : values) text = replace_all(text, key, value);
    return text;
  };
  std::vector<VerificationPlan> plans;
  for (const std::string& name : domain.actions[step.action].verification) {
    const VerificationTemplate& verification = domain.verification(name);
    VerificationPlan plan{name, fill(verification.sense), fill(verification.expect), {}};
    for (const VerificationOutcome& outcome : verification.outcomes) {
      VerificationPlan::Outcome out{fill(outcome.when), outcome.error, outcome.recovery, {}};
      for (const std::string& line : domain.recovery(outcome.recovery).steps)
        out.recovery_steps.push_back(fill(line));
      plan.outcomes.push_back(std::move(out));
    }
    plans.push_back(std::move(plan));
  }
  return plans;
}

class InstanceAnalyser {
 public:
  InstanceAnalyser(const WorldModel& world, const Domain& domain, const AnalysisOptions& options,
                   symbolic::ExprPool& pool)
      : world_(world), domain_(domain), options_(options), pool_(pool) {}

  void run(std::vector<Phase2Step> steps, InstanceAnalysis& out);

 private:
  // Re-propagates from `snapshot` over steps[from..] and returns the decided preconditions of
  // the steps at positions in `watch` (others are propagated but not decided).
  std::map<int, std::vector<PreconditionResult>> replay(Propagation snapshot,
                                                        const std::vector<Phase2Step>& steps,
                                                        int from, int through,
                                                        const std::set<int>& watch) const;
  // AnalysedStep::sensor_scale_needed for the failing step at `k`.
  std::optional<double> sensor_margin(const std::vector<Phase2Step>& steps,
                                      const std::vector<Propagation>& snapshots, int k) const;
  // Tries the repairs for the failing step at `k`; on success replaces `steps` and returns the
  // position from which to resume; -1 if nothing helped.
  int repair(std::vector<Phase2Step>& steps, const std::vector<Propagation>& snapshots, int k,
             const std::vector<PreconditionResult>& failing, InstanceAnalysis& out) const;

  const WorldModel& world_;
  const Domain& domain_;
  const AnalysisOptions& options_;
  symbolic::ExprPool& pool_;
};

std::map<int, std::vector<PreconditionResult>> InstanceAnalyser::replay(
    Propagation state, const std::vector<Phase2Step>& steps, int from, int through,
    const std::set<int>& watch) const {
  std::map<int, std::vector<PreconditionResult>> decided;
  for (int i = from; i <= through; ++i) {
    const std::vector<Precondition> preconditions = state.step(steps[i], i + 1);
    if (watch.contains(i))
      decided[i] = decide(preconditions, state.space(), options_.quick, options_.bound);
  }
  return decided;
}

// How far the results are from holding: the sum over the preconditions of the sound bound's
// excess over the threshold (0 when every one is satisfied).
double shortfall(const std::vector<PreconditionResult>& results) {
  double total = 0;
  for (const PreconditionResult& r : results) {
    const bool upper = r.inequality.relation == bounds::Relation::kLess ||
                       r.inequality.relation == bounds::Relation::kLessEqual;
    const double excess =
        upper ? r.bound.hi - r.inequality.threshold : r.inequality.threshold - r.bound.lo;
    total += std::isfinite(excess) ? std::max(0.0, excess) : 1e300;
  }
  return total;
}

int InstanceAnalyser::repair(std::vector<Phase2Step>& steps,
                             const std::vector<Propagation>& snapshots, int k,
                             const std::vector<PreconditionResult>& failing,
                             InstanceAnalysis& out) const {
  const int scan = find_action(domain_, Effect::kSense);
  const int squeeze = find_action(domain_, Effect::kReduce);
  const bool insertion = steps[k].effect == Effect::kInsert;
  // The repairs to try, in order. A squeeze uses another grasp than the pickup's (with the same
  // one its preconditions would be the failing pickup's own): every grasp the robot reaches where
  // the object lies, up to AnalysisOptions::squeeze_grasps of them; it re-centres the object
  // across that grasp's fingers and leaves only the arm's rotation error.
  enum class Kind { kScanFixed, kScanHeld, kSqueeze };
  struct Repair {
    Kind kind;
    int grasp{-1};
  };
  std::vector<Repair> kinds;
  if (scan >= 0 && world_.scenario().range_scan) {
    if (insertion) kinds.push_back({Kind::kScanFixed});
    kinds.push_back({Kind::kScanHeld});
  }
  const int pickup_at = insertion ? grasp_position(steps, k, steps[k].object) : k;
  if (squeeze >= 0 && pickup_at >= 0 && steps[pickup_at].position >= 0) {
    const Phase2Step& pickup = steps[pickup_at];
    const ObjectWorld& object = world_.object(pickup.object);
    int added = 0;
    for (std::size_t g = 0; g < object.grasps.size() && added < options_.squeeze_grasps; ++g)
      if (static_cast<int>(g) != pickup.grasp && object.reachable[g][pickup.position]) {
        kinds.push_back({Kind::kSqueeze, static_cast<int>(g)});
        ++added;
      }
  }

  std::vector<Phase2Step> current = steps;
  int failing_at = k;
  int earliest = k;  // the earliest insertion kept so far
  double best = shortfall(failing);
  std::vector<PreconditionResult> latest = failing;
  const std::size_t first_attempt = out.repairs.size();
  for (const auto& [kind, squeeze_grasp] : kinds) {
    const Phase2Step& failed = current[failing_at];
    const int grasp_at =
        insertion ? grasp_position(current, failing_at, failed.object) : failing_at;
    Phase2Step step;
    int position = -1;
    if (kind == Kind::kSqueeze) {
      if (grasp_at < 0) continue;
      step = current[grasp_at];
      step.action = squeeze;
      step.effect = Effect::kReduce;
      step.grasp = squeeze_grasp;
      step.instance_step = -1;
      position = grasp_at;
    } else {
      const int object = kind == Kind::kScanFixed ? failed.fixed_object : failed.object;
      const int until = kind == Kind::kScanFixed ? failing_at : grasp_at;
      if (until < 0) continue;
      position = scan_position(current, until, object);
      if (position < 0) continue;
      step.action = scan;
      step.effect = Effect::kSense;
      step.object = object;
    }
    std::vector<Phase2Step> trial = current;
    trial.insert(trial.begin() + position, step);
    const int moved = failing_at + 1;
    std::set<int> watch = {moved};
    if (kind == Kind::kSqueeze) watch.insert(position);
    const int from = std::min(position, earliest);
    // Replay from the earliest change: snapshots before it are unaffected.
    const auto decided = replay(snapshots[from], trial, from, moved, watch);
    const bool own_ok = kind != Kind::kSqueeze || all_hold(decided.at(position));
    const std::vector<PreconditionResult>& after = decided.at(moved);
    RepairAttempt attempt;
    attempt.action = domain_.actions[step.action].name;
    attempt.object = step.object;
    attempt.for_instance_step = current[failing_at].instance_step;
    for (const PreconditionResult& r : latest) {
      attempt.before.push_back(r.bound);
      attempt.verdicts_before.push_back(r.verdict);
    }
    for (const PreconditionResult& r : after) {
      attempt.after.push_back(r.bound);
      attempt.verdicts_after.push_back(r.verdict);
    }
    const double remaining = shortfall(after);
    // Keep an insertion that brings the step closer to holding; it is final if the step holds.
    const bool kept = own_ok && (all_hold(after) || remaining < best);
    attempt.helped = kept;
    out.repairs.push_back(std::move(attempt));
    if (!kept) continue;
    current = std::move(trial);
    failing_at = moved;
    earliest = std::min(earliest, position);
    best = remaining;
    latest = after;
    if (all_hold(after)) {
      steps = std::move(current);
      return earliest;
    }
  }
  // Nothing made the step hold: the insertions are dropped and marked as such.
  for (std::size_t i = first_attempt; i < out.repairs.size(); ++i) out.repairs[i].helped = false;
  return -1;
}

std::optional<double> InstanceAnalyser::sensor_margin(const std::vector<Phase2Step>& steps,
                                                      const std::vector<Propagation>& snapshots,
                                                      int k) const {
  const int scan = find_action(domain_, Effect::kSense);
  if (scan < 0 || !world_.scenario().range_scan) return std::nullopt;
  const Phase2Step& failed = steps[k];
  std::vector<std::pair<int, int>> targets;  // (object, until)
  if (failed.effect == Effect::kInsert) targets.push_back({failed.fixed_object, k});
  const int grasp_at = failed.effect == Effect::kInsert
                           ? grasp_position(steps, k, failed.object)
                           : (failed.effect == Effect::kGrasp ? k : -1);
  if (grasp_at >= 0) targets.push_back({failed.object, grasp_at});
  std::vector<int> positions;
  for (const auto& [object, until] : targets)
    positions.push_back(scan_position(steps, until, object));
  std::vector<Phase2Step> trial = steps;
  int inserted = 0, earliest = k;
  // Insert the later position first so the earlier one stays valid.
  for (int t = static_cast<int>(targets.size()) - 1; t >= 0; --t) {
    if (positions[t] < 0) continue;
    Phase2Step step;
    step.action = scan;
    step.effect = Effect::kSense;
    step.object = targets[t].first;
    trial.insert(trial.begin() + positions[t], step);
    ++inserted;
    earliest = std::min(earliest, positions[t]);
  }
  if (inserted == 0) return std::nullopt;
  const int moved = k + inserted;
  const auto holds_at = [&](double scale) {
    Propagation start = snapshots[earliest];
    start.set_sensor_scale(scale);
    return all_hold(replay(start, trial, earliest, moved, {moved}).at(moved));
  };
  if (!holds_at(0.0)) return std::nullopt;
  double good = 0.0, bad = options_.max_scale;
  if (holds_at(bad)) return bad;
  for (int i = 0; i < options_.reverse_iterations; ++i) {
    const double mid = 0.5 * (good + bad);
    (holds_at(mid) ? good : bad) = mid;
  }
  return good;
}

void InstanceAnalyser::run(std::vector<Phase2Step> steps, InstanceAnalysis& out) {
  std::vector<Propagation> snapshots = {Propagation(world_, domain_, pool_)};
  std::vector<AnalysedStep> analysed;
  std::set<int> attempted;  // instance steps whose repair was tried (once each)
  int k = 0;
  while (k < static_cast<int>(steps.size())) {
    Propagation state = snapshots[k];
    // An inserted range-scan looks at the object where it rests now.
    if (steps[k].effect == Effect::kSense && steps[k].object >= 0 &&
        state.on_table(steps[k].object))
      steps[k].object_pose = state.on_table(steps[k].object)->ideal;
    const std::vector<Precondition> preconditions = state.step(steps[k], k + 1);
    AnalysedStep step{
        .step = steps[k],
        .action = domain_.actions[steps[k].action].name,
        .inserted = steps[k].instance_step < 0,
        .preconditions = decide(preconditions, state.space(), options_.quick, options_.bound),
        .failed = false,
        .verification = {},
        .sensor_scale_needed = std::nullopt};
    if (!all_hold(step.preconditions) && options_.repair && !step.inserted &&
        !attempted.contains(steps[k].instance_step)) {
      attempted.insert(steps[k].instance_step);
      const int resume = repair(steps, snapshots, k, step.preconditions, out);
      if (resume >= 0) {
        snapshots.erase(snapshots.begin() + resume + 1, snapshots.end());
        analysed.erase(analysed.begin() + resume, analysed.end());
        k = resume;
        continue;
      }
    }
    if (!all_hold(step.preconditions)) {
      step.failed = true;
      if (options_.reverse) step.sensor_scale_needed = sensor_margin(steps, snapshots, k);
      step.verification = verification_plans(world_, domain_, steps[k]);
      ++out.errors;
    }
    analysed.push_back(std::move(step));
    snapshots.erase(snapshots.begin() + k + 1, snapshots.end());
    snapshots.push_back(std::move(state));
    ++k;
  }
  out.steps = std::move(analysed);
  out.variables = snapshots.back().space().variables();
  out.symbols = snapshots.back().space().symbols();
}

bool holds(const bounds::Inequality& inequality, double value) {
  switch (inequality.relation) {
    case bounds::Relation::kLess:
      return value < inequality.threshold;
    case bounds::Relation::kLessEqual:
      return value <= inequality.threshold;
    case bounds::Relation::kGreater:
      return value > inequality.threshold;
    case bounds::Relation::kGreaterEqual:
      return value >= inequality.threshold;
  }
  return false;
}

}  // namespace

InstanceAnalysis analyse_instance(const WorldModel& world, const Domain& domain,
                                  const PlanInstance& instance, const AnalysisOptions& options) {
  InstanceAnalysis analysis;
  analysis.instance = instance.index;
  analysis.pool = std::make_unique<symbolic::ExprPool>();
  InstanceAnalyser(world, domain, options, *analysis.pool)
      .run(phase2_steps(domain, instance), analysis);
  for (AnalysedStep& step : analysis.steps)
    for (PreconditionResult& result : step.preconditions) {
      result.expression = symbolic::to_string(result.inequality.expression);
      result.nodes = symbolic::dag_size(result.inequality.expression);
    }
  return analysis;
}

void add_margins(InstanceAnalysis& analysis, const AnalysisOptions& options) {
  std::mt19937_64 random(20261201);
  const bounds::BoundOptions& quick = options.quick;
  for (AnalysedStep& step : analysis.steps) {
    for (PreconditionResult& result : step.preconditions) {
      std::vector<Expr> inputs;
      for (const VariableId id : result.variables) inputs.push_back(analysis.symbols[id.index]);
      bounds::BoundProblem problem(result.inequality.expression, inputs);
      // A tight bound with inner values for every precondition (the natural pass that decided a
      // satisfied one has none): [lo, hi] only shrinks, so the verdict stands.
      result.bound = problem.bound(result.box, options.report);
      result.witness = bounds::witness(result.inequality, result.bound);
      if (options.blame) {
        const double width = result.bound.hi - result.bound.lo;
        result.blame.clear();
        for (std::size_t v = 0; v < inputs.size(); ++v) {
          std::vector<Interval> pinned = result.box;
          pinned[v] = Interval(0.0);
          const bounds::BoundResult without = problem.bound(pinned, quick);
          const double share = width > 0 ? (width - (without.hi - without.lo)) / width : 0.0;
          result.blame.push_back({result.variables[v], std::clamp(share, 0.0, 1.0)});
        }
        std::stable_sort(result.blame.begin(), result.blame.end(),
                         [](const auto& a, const auto& b) { return a.share > b.share; });
      }
      if (options.samples > 0) {
        const symbolic::Tape tape =
            symbolic::Tape::compile({&result.inequality.expression, 1}, inputs);
        symbolic::TapeEvaluator<double> evaluator(tape);
        std::size_t violations = 0;
        std::vector<double> point(inputs.size());
        double value[1];
        for (std::size_t s = 0; s < options.samples; ++s) {
          for (std::size_t v = 0; v < inputs.size(); ++v)
            point[v] =
                std::uniform_real_distribution<double>(result.box[v].lo, result.box[v].hi)(random);
          evaluator.evaluate(point, value);
          if (!holds(result.inequality, value[0])) ++violations;
        }
        result.monte_carlo_violation = static_cast<double>(violations) / options.samples;
      }
      if (options.reverse) {
        // Scale the ranges of the objects' variables (and the arm's if asked) by s.
        const auto proved_at = [&](double scale) {
          std::vector<Interval> box = result.box;
          for (std::size_t v = 0; v < inputs.size(); ++v) {
            const SpaceVariable& meta = analysis.variables[result.variables[v].index];
            if (meta.provenance.source == UncertaintySource::kManipulator &&
                !options.scale_manipulator)
              continue;
            box[v] = Interval(meta.lower * scale, meta.upper * scale);
          }
          return bounds::decide(result.inequality, problem.bound(box, quick)) ==
                 Verdict::kSatisfied;
        };
        std::optional<double> proved;
        if (proved_at(0.0)) {
          double good = 0.0, bad = options.max_scale;
          if (proved_at(bad)) {
            good = bad;
          } else {
            for (int i = 0; i < options.reverse_iterations; ++i) {
              const double mid = 0.5 * (good + bad);
              (proved_at(mid) ? good : bad) = mid;
            }
          }
          proved = good;
        }
        result.holds_up_to_scale = proved;
      }
    }
  }
}

std::size_t choose_instance(const std::vector<InstanceAnalysis>& examined) {
  if (examined.empty()) throw PlanError("no plan instance was examined");
  std::size_t best = 0;
  for (std::size_t i = 1; i < examined.size(); ++i)
    if (examined[i].errors < examined[best].errors) best = i;
  return best;
}

std::vector<InstanceAnalysis> analyse_instances(
    const WorldModel& world, const Domain& domain, const std::vector<PlanInstance>& instances,
    const AnalysisOptions& options, const std::function<void(std::string_view)>& progress) {
  const auto stage = [&](const std::string& text) {
    if (progress) progress(text);
  };
  std::vector<InstanceAnalysis> examined;
  for (const PlanInstance& instance : instances) {
    stage("phase 2: plan instance " + std::to_string(examined.size() + 1) + " of " +
          std::to_string(instances.size()));
    examined.push_back(analyse_instance(world, domain, instance, options));
    if (examined.back().errors == 0) break;
  }
  if (examined.empty()) return examined;
  stage("phase 2: margins of the chosen instance (blame, reverse analysis, Monte Carlo)");
  add_margins(examined[choose_instance(examined)], options);
  return examined;
}

}  // namespace spar::planner
