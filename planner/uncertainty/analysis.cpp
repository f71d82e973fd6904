#include "spar/planner/uncertainty/analysis.hpp"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <exception>
#include <functional>
#include <optional>
#include <set>

#include "spar/bounds/interval.hpp"
#include "spar/common/parallel.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/uncertainty/internal/bisection.hpp"
#include "spar/symbolic/operations.hpp"

namespace spar::planner {

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
    step.arm = source.reach.solution;
    step.instance_step = static_cast<int>(i);
    step.label = static_cast<int>(i) + 1;
    steps.push_back(step);
  }
  return steps;
}

namespace {

using bounds::Verdict;
using symbolic::Expr;

// The first action with `effect` (and for sense, `camera` as given: the one phase 2 splices in
// for sensing or squeezing), or -1.
int find_action(const Domain& domain, Effect effect, bool camera = false) {
  for (std::size_t a = 0; a < domain.actions.size(); ++a)
    if (domain.actions[a].effect == effect &&
        (effect != Effect::kSense || domain.actions[a].camera == camera))
      return static_cast<int>(a);
  return -1;
}

// What the repair may splice in with this scenario and domain (RepairKinds).
RepairKinds repair_kinds(const Scenario& scenario, const Domain& domain, int squeeze_grasps) {
  const bool verifying_camera =
      std::any_of(scenario.cameras.begin(), scenario.cameras.end(), [](const CameraSensor& camera) {
        return camera.residual.has_value() && camera.mount == sensing::Mount::kFixed;
      });
  return {.scan = scenario.range_scan ? find_action(domain, Effect::kSense) : -1,
          .look = verifying_camera ? find_action(domain, Effect::kSense, /*camera=*/true) : -1,
          .squeeze = find_action(domain, Effect::kReduce),
          .squeeze_grasps = squeeze_grasps};
}

// The components sensing step `label` corrected on `object`: those it allocated a residual for.
std::vector<PoseComponent> corrected_components(const UncertaintySpace& space, int object,
                                                int label) {
  std::vector<PoseComponent> out;
  for (const SpaceVariable& v : space.variables())
    if (v.provenance.source == UncertaintySource::kSensor && v.provenance.object == object &&
        v.provenance.step == label)
      out.push_back(v.component);
  return out;
}

bool all_hold(const std::vector<PreconditionResult>& results) {
  return std::all_of(results.begin(), results.end(),
                     [](const PreconditionResult& r) { return r.verdict == Verdict::kSatisfied; });
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

// What may hide the step's object from a camera: the other objects where they rest before the
// step, and the gripper at the step's grasp, closed on the object.
VisionOccluders occluders_at(const WorldModel& world, const Propagation& before,
                             const Phase2Step& step) {
  VisionOccluders occluders;
  for (int o = 0; o < static_cast<int>(world.scenario().objects.size()); ++o)
    if (o != step.object && before.on_table(o))
      occluders.objects.emplace_back(o, before.on_table(o)->ideal);
  if (step.grasp >= 0) {
    const geometry::Grasp& grasp = world.object(step.object).grasps[step.grasp];
    occluders.gripper = &world.gripper();
    occluders.gripper_pose = step.object_pose * grasp.gripper_in_object;
    occluders.opening = grasp.width;
  }
  return occluders;
}

std::vector<VerificationPlan> verification_plans(const WorldModel& world, const Domain& domain,
                                                 const Phase2Step& step,
                                                 const Propagation& before) {
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
  const std::optional<VisionCheck> vision =
      step.object >= 0
          ? vision_check(scenario, step.object, step.object_pose, occluders_at(world, before, step))
          : std::nullopt;
  std::vector<VerificationPlan> plans;
  for (const std::string& name : domain.actions[step.action].verification) {
    const VerificationTemplate& verification = domain.verification(name);
    VerificationPlan plan{name, fill(verification.sense), fill(verification.expect), {}, vision};
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
      : world_(world),
        domain_(domain),
        options_(options),
        pool_(pool),
        kinds_(repair_kinds(world.scenario(), domain, options.squeeze_grasps)),
        decisions_(options.quick, options.bound) {}

  void run(std::vector<Phase2Step> steps, InstanceAnalysis& out);
  // The sensor margins of an analysis run() made with options.defer_sensor_margins: its steps
  // propagated again (with their labels, so the same expressions) for the states before them.
  void add_sensor_margins(InstanceAnalysis& out) const;

 private:
  // One step propagated: its preconditions and the state after it (the space they are decided
  // in), by position in the steps.
  struct Propagated {
    std::vector<Precondition> built;
    Propagation after;
  };
  using PropagatedSteps = std::map<int, Propagated>;
  // A replay's steps and their decisions (by position).
  struct Replayed {
    PropagatedSteps steps;
    std::map<int, std::vector<PreconditionResult>> decided;
    bool gave_up{false};  // stopped at a step of `must_hold` with a precondition not satisfied
  };
  // Re-propagates `state` (the one before steps[from]) over steps[from..through] and decides the
  // preconditions of every step in that range as `need` asks; where `must_hold` is given, the
  // steps it is true of are built and decided first, the latest first, and the replay stops
  // (gave_up) as soon as one of their preconditions is known not to hold.
  [[nodiscard]] Replayed replay(
      Propagation state, std::vector<Phase2Step> steps, int from, int through, Need need,
      const std::function<bool(const Phase2Step&)>& must_hold = nullptr) const;
  // AnalysedStep::sensor_scale_needed for the failing step at `k`.
  [[nodiscard]] std::optional<double> sensor_margin(const std::vector<Phase2Step>& steps,
                                                    const std::vector<Propagation>& snapshots,
                                                    int k) const;
  // sensor_margin() of every failed step of the final plan `steps` (analysed[k] is steps[k],
  // snapshots[k] the state before it).
  void add_sensor_margins(const std::vector<Phase2Step>& steps,
                          const std::vector<Propagation>& snapshots,
                          std::vector<AnalysedStep>& analysed) const;
  // Searches the repair sets for the failing step at `k` (planner/uncertainty/repair.hpp); if one
  // is kept, splices it into `steps`, records it in `out`, sets `kept` to the steps its trial
  // propagated (from the returned position through the failing step) and returns the position
  // from which to resume; -1 if nothing helped.
  int repair(std::vector<Phase2Step>& steps, const std::vector<Propagation>& snapshots,
             const std::vector<AnalysedStep>& analysed, int k,
             const std::vector<PreconditionResult>& failing, InstanceAnalysis& out,
             PropagatedSteps& kept) const;
  // Sets out.variables, out.symbols and the preconditions' expressions to the chosen plan's
  // numbered by execution position (dx_g<position>, ...), as the reports show the steps;
  // `searched[k]` is the state the search reached before out.steps[k] (the last one after all),
  // numbered by Phase2Step::label.
  void number_by_position(InstanceAnalysis& out, const std::vector<Propagation>& searched) const;

  const WorldModel& world_;
  const Domain& domain_;
  const AnalysisOptions& options_;
  symbolic::ExprPool& pool_;
  const RepairKinds kinds_;  // the domain's actions the repair splices in, where usable
  // Every step decision of this instance: the repair search and the resumed
  // analysis after a repair decide many steps again over the same boxes.
  mutable DecisionCache decisions_;
};

// An inserted range-scan or camera verification looks at the object where it rests now.
void look_where_it_rests(Phase2Step& step, const Propagation& state) {
  if (step.effect == Effect::kSense && step.object >= 0 && state.on_table(step.object))
    step.object_pose = state.on_table(step.object)->ideal;
}

InstanceAnalyser::Replayed InstanceAnalyser::replay(
    Propagation state, std::vector<Phase2Step> steps, int from, int through, Need need,
    const std::function<bool(const Phase2Step&)>& must_hold) const {
  Replayed out;
  if (!must_hold) {
    for (int i = from; i <= through; ++i) {
      look_where_it_rests(steps[i], state);
      std::vector<Precondition> built = state.step(steps[i], steps[i].label);
      out.decided[i] = decisions_.decide(built, state.space(), need);
      out.steps.insert_or_assign(i, Propagated{std::move(built), state});
    }
    return out;
  }
  // Every step propagated, its preconditions built only when decided: the steps that must hold
  // first, the latest first (the failing step, the likeliest not to), so that giving up skips
  // building and deciding the others.
  std::map<int, DeferredStep> deferred;
  for (int i = from; i <= through; ++i) {
    look_where_it_rests(steps[i], state);
    deferred.emplace(i, state.step_deferred(steps[i], steps[i].label));
    out.steps.insert_or_assign(i, Propagated{{}, state});
  }
  for (auto step = out.steps.rbegin(); step != out.steps.rend(); ++step) {
    if (!must_hold(steps[step->first])) continue;
    step->second.built = deferred.at(step->first).build();
    std::optional<std::vector<PreconditionResult>> held =
        decisions_.decide_if_all_hold(step->second.built, step->second.after.space());
    if (!held) {
      out.gave_up = true;
      return out;
    }
    out.decided[step->first] = std::move(*held);
  }
  for (auto& [i, step] : out.steps)
    if (!out.decided.contains(i)) {
      step.built = deferred.at(i).build();
      out.decided[i] = decisions_.decide(step.built, step.after.space(), need);
    }
  return out;
}

// Adds one original step's decided preconditions to a repair score.
void add_to_score(RepairScore& score, int instance_step,
                  const std::vector<PreconditionResult>& results) {
  bool failed = false;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const bool satisfied = results[i].verdict == Verdict::kSatisfied;
    score.satisfied[{instance_step, static_cast<int>(i)}] = satisfied;
    score.unsatisfied += !satisfied;
    failed |= !satisfied;
  }
  score.failed += failed;
}

int InstanceAnalyser::repair(std::vector<Phase2Step>& steps,
                             const std::vector<Propagation>& snapshots,
                             const std::vector<AnalysedStep>& analysed, int k,
                             const std::vector<PreconditionResult>& failing, InstanceAnalysis& out,
                             PropagatedSteps& kept) const {
  const std::vector<RepairCandidate> candidates = repair_candidates(world_, steps, k, kinds_);
  if (candidates.empty()) return -1;
  int from = k;
  for (const RepairCandidate& c : candidates) from = std::min(from, c.position);
  // No repair: the original steps in [from, k] as already decided.
  RepairScore baseline;
  for (int i = from; i < k; ++i)
    if (steps[i].instance_step >= 0)
      add_to_score(baseline, steps[i].instance_step, analysed[i].preconditions);
  add_to_score(baseline, steps[k].instance_step, failing);
  const int first_record = static_cast<int>(out.repairs.size());
  std::map<unsigned, PropagatedSteps> propagated;  // per set tried
  // The steps a set's score counts: the original ones and the squeezes it inserts.
  const std::function<bool(const Phase2Step&)> scored = [&](const Phase2Step& step) {
    return step.instance_step >= 0 ||
           (step.effect == Effect::kReduce && step.repair >= first_record);
  };
  // A set's score needs verdicts only (RepairScore).
  const RepairChoice choice =
      choose_repair(candidates, baseline, [&](unsigned set, ScoreDepth depth) {
        const SplicedPlan trial = splice(steps, k, candidates, set, kinds_, first_record);
        Replayed replayed =
            replay(snapshots[from], trial.steps, from, trial.failing, Need::kVerdicts,
                   depth == ScoreDepth::kSettles ? scored : nullptr);
        RepairScore score;
        if (replayed.gave_up) return RepairScore::not_settling();
        for (const auto& [position, results] : replayed.decided) {
          const Phase2Step& step = trial.steps[position];
          if (step.instance_step >= 0)
            add_to_score(score, step.instance_step, results);
          else if (scored(step))
            score.admissible = score.admissible && all_hold(results);
        }
        propagated.insert_or_assign(set, std::move(replayed.steps));
        return score;
      });
  RepairSearch search{.for_instance_step = steps[k].instance_step,
                      .candidates = static_cast<int>(candidates.size()),
                      .sets_tried = choice.sets_tried,
                      .kept = std::popcount(choice.set),
                      .dropped = {},
                      .holds = choice.score.unsatisfied == 0 && choice.set != 0};
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (!(choice.set >> i & 1u)) ++search.dropped[repair_kind(candidates[i])];
  out.repair_searches.push_back(std::move(search));
  if (choice.set == 0) return -1;
  kept = std::move(propagated.at(choice.set));
  const Propagated& failing_after = kept.rbegin()->second;  // the trial's failing step
  const std::vector<PreconditionResult> after =
      decisions_.decide(failing_after.built, failing_after.after.space());
  int rank = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!(choice.set >> i & 1u)) continue;
    RepairAttempt record{.action = domain_.actions[action_of(candidates[i], kinds_)].name,
                         .object = candidates[i].object,
                         .for_instance_step = steps[k].instance_step,
                         .helped = true,
                         .before = {},
                         .after = {},
                         .verdicts_before = {},
                         .verdicts_after = {},
                         .turned = choice.turned[rank++]};
    for (const PreconditionResult& r : failing) {
      record.before.push_back(r.bound);
      record.verdicts_before.push_back(r.verdict);
    }
    for (const PreconditionResult& r : after) {
      record.after.push_back(r.bound);
      record.verdicts_after.push_back(r.verdict);
    }
    out.repairs.push_back(std::move(record));
  }
  steps = splice(steps, k, candidates, choice.set, kinds_, first_record).steps;
  return from;
}

std::optional<double> InstanceAnalyser::sensor_margin(const std::vector<Phase2Step>& steps,
                                                      const std::vector<Propagation>& snapshots,
                                                      int k) const {
  const RepairKinds scanning{.scan = kinds_.scan};  // the range scanner's residual is scaled
  if (scanning.scan < 0) return std::nullopt;
  std::vector<RepairCandidate> scans = repair_candidates(world_, steps, k, scanning);
  if (scans.empty()) return std::nullopt;
  const unsigned all = (1u << scans.size()) - 1;
  const SplicedPlan trial = splice(steps, k, scans, all, scanning, -1);
  int earliest = k;
  for (const RepairCandidate& c : scans) earliest = std::min(earliest, c.position);
  // Propagated and compiled once: a scale is new ranges of the residuals' scale variables.
  Propagation state = snapshots[earliest];
  state.set_sensor_scale(1.0);
  std::vector<Precondition> failing;
  for (int i = earliest; i <= trial.failing; ++i)
    failing = state.step(trial.steps[i], trial.steps[i].label);
  CompiledStep compiled(failing, state.space());
  // Only proofs count here (a scale holds when every precondition is proved): no NLopt search
  // for violating witnesses (deciding's gradient corner still ends most refuted scales at once).
  bounds::BoundOptions quick = options_.quick, full = options_.bound;
  quick.inner = full.inner = false;
  quick.stop_at_witness = full.stop_at_witness = true;  // only whether all hold
  const auto holds_at = [&](double scale) {
    state.set_sensor_scale(scale);
    return compiled.all_hold(state.space(), quick, full);
  };
  if (!holds_at(0.0)) return std::nullopt;
  return internal::largest_holding(0.0, options_.max_scale, options_.reverse_iterations, holds_at);
}

void InstanceAnalyser::add_sensor_margins(const std::vector<Phase2Step>& steps,
                                          const std::vector<Propagation>& snapshots,
                                          std::vector<AnalysedStep>& analysed) const {
  for (std::size_t k = 0; k < analysed.size(); ++k)
    if (analysed[k].failed)
      analysed[k].sensor_scale_needed = sensor_margin(steps, snapshots, static_cast<int>(k));
}

void InstanceAnalyser::add_sensor_margins(InstanceAnalysis& out) const {
  std::vector<Phase2Step> steps;
  std::optional<std::size_t> through;  // the states needed: up to the last failed step
  for (std::size_t k = 0; k < out.steps.size(); ++k) {
    steps.push_back(out.steps[k].step);
    if (out.steps[k].failed) through = k;
  }
  if (!through) return;
  std::vector<Propagation> snapshots = {Propagation(world_, domain_, pool_)};
  for (std::size_t k = 0; k < *through; ++k) {
    Propagation state = snapshots.back();
    (void)state.step(steps[k], steps[k].label);
    snapshots.push_back(std::move(state));
  }
  add_sensor_margins(steps, snapshots, out.steps);
}

void InstanceAnalyser::run(std::vector<Phase2Step> steps, InstanceAnalysis& out) {
  std::vector<Propagation> snapshots = {Propagation(world_, domain_, pool_)};
  std::vector<AnalysedStep> analysed;
  std::set<int> attempted;  // instance steps whose repair was tried (once each)
  // The steps the kept repair's trial propagated: the same steps from the same state (the trial's
  // steps are `steps` since the splice, and its state before them snapshots[resume]).
  PropagatedSteps kept;
  int k = 0;
  while (k < static_cast<int>(steps.size())) {
    Propagation state = snapshots[k];
    look_where_it_rests(steps[k], state);
    std::vector<Precondition> preconditions;
    if (const auto trial = kept.find(k); trial != kept.end()) {
      preconditions = std::move(trial->second.built);
      state = std::move(trial->second.after);
      kept.erase(trial);
    } else {
      preconditions = state.step(steps[k], steps[k].label);
    }
    AnalysedStep step{.step = steps[k],
                      .action = domain_.actions[steps[k].action].name,
                      .inserted = steps[k].instance_step < 0,
                      .preconditions = decisions_.decide(preconditions, state.space()),
                      .failed = false,
                      .verification = {},
                      .sensor_scale_needed = std::nullopt,
                      .camera_verification = std::nullopt,
                      .corrects = {}};
    if (steps[k].effect == Effect::kSense)
      step.corrects = corrected_components(state.space(), steps[k].object, steps[k].label);
    if (steps[k].camera >= 0) {
      // What the camera must see (the scene as repair_candidates found the camera with).
      std::vector<CameraVerification> camera =
          verifying_cameras(world_.scenario(), steps[k].object, steps[k].object_pose,
                            resting_occluders(world_, steps, k, steps[k].object), steps[k].camera);
      if (!camera.empty()) step.camera_verification = std::move(camera.front().check);
    }
    if (!all_hold(step.preconditions) && options_.repair && !step.inserted &&
        !attempted.contains(steps[k].instance_step)) {
      attempted.insert(steps[k].instance_step);
      PropagatedSteps trial;
      const int resume = repair(steps, snapshots, analysed, k, step.preconditions, out, trial);
      if (resume >= 0) {
        kept = std::move(trial);
        snapshots.erase(snapshots.begin() + resume + 1, snapshots.end());
        analysed.erase(analysed.begin() + resume, analysed.end());
        k = resume;
        continue;
      }
    }
    if (!all_hold(step.preconditions)) {
      step.failed = true;
      step.verification = verification_plans(world_, domain_, steps[k], snapshots[k]);
      ++out.errors;
    }
    analysed.push_back(std::move(step));
    snapshots.erase(snapshots.begin() + k + 1, snapshots.end());
    snapshots.push_back(std::move(state));
    ++k;
  }
  if (options_.reverse && !options_.defer_sensor_margins)
    add_sensor_margins(steps, snapshots, analysed);
  out.sensor_margins_pending = options_.reverse && options_.defer_sensor_margins;
  out.steps = std::move(analysed);
  out.steps_decided = decisions_.misses();
  out.steps_reused = decisions_.hits();
  number_by_position(out, snapshots);
}

void InstanceAnalyser::number_by_position(InstanceAnalysis& out,
                                          const std::vector<Propagation>& searched) const {
  // The steps before the first one labelled otherwise than by position are numbered already, and
  // so is the state the search reached before it.
  std::size_t first = 0;
  while (first < out.steps.size() && out.steps[first].step.label == static_cast<int>(first) + 1)
    ++first;
  const UncertaintySpace& space = searched.back().space();
  if (first == out.steps.size()) {
    out.variables = space.variables();
    out.symbols = space.symbols();
    return;
  }
  // The steps from there propagated again, numbered by position: the same allocations in the same
  // order (so every VariableId, box and witness stands) and the same expressions over renamed
  // symbols.
  Propagation state = searched.at(first);
  for (std::size_t i = first; i < out.steps.size(); ++i) {
    const std::vector<Precondition> built = state.step(out.steps[i].step, static_cast<int>(i) + 1);
    std::vector<PreconditionResult>& results = out.steps[i].preconditions;
    if (built.size() != results.size())
      throw PlanError("internal: step " + std::to_string(i + 1) +
                      " has other preconditions when numbered by position");
    for (std::size_t j = 0; j < built.size(); ++j)
      results[j].inequality.expression = built[j].inequality.expression;
  }
  if (state.space().size() != space.size())
    throw PlanError("internal: the plan has other variables when numbered by position");
  out.variables = state.space().variables();
  out.symbols = state.space().symbols();
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
    for (PreconditionResult& result : step.preconditions)
      result.nodes = symbolic::dag_size(result.inequality.expression);
  return analysis;
}

void add_sensor_margins(const WorldModel& world, const Domain& domain, InstanceAnalysis& analysis,
                        const AnalysisOptions& options) {
  if (!analysis.pool)
    throw PlanError(
        "add_sensor_margins: the analysis has no expression pool (give it one that "
        "analyse_instance made)");
  if (!options.reverse || !analysis.sensor_margins_pending) return;
  InstanceAnalyser(world, domain, options, *analysis.pool).add_sensor_margins(analysis);
  analysis.sensor_margins_pending = false;
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
  // The first instance alone (most plans have no error there), then, while every one examined has
  // an error, the next `threads` at once: each analysis is independent (its own pool; the world
  // model is only read, its memo tables under a lock), so the ones kept are what one at a time
  // gives, and those past the first without an error are dropped.
  for (std::size_t next = 0;
       next < instances.size() && (examined.empty() || examined.back().errors > 0);) {
    const std::size_t count =
        examined.empty() ? 1 : std::clamp<std::size_t>(options.threads, 1, instances.size() - next);
    for (std::size_t i = 0; i < count; ++i)
      stage("phase 2: plan instance " + std::to_string(next + i + 1) + " of " +
            std::to_string(instances.size()));
    std::vector<std::optional<InstanceAnalysis>> analysed(count);
    std::vector<std::exception_ptr> failed(analysed.size());
    InstanceAnalysis* leader =
        examined.empty() || options.threads < 2 ? nullptr : &examined[choose_instance(examined)];
    if (leader && !leader->sensor_margins_pending) leader = nullptr;
    run_tasks(analysed.size() + (leader ? 1 : 0), options.threads, [&](std::size_t i) {
      if (i == analysed.size()) {
        // If this fails, the margins stay pending: add_sensor_margins runs them again (and
        // throws) for the caller if this instance is chosen.
        try {
          add_sensor_margins(world, domain, *leader, options);
        } catch (...) {
        }
        return;
      }
      try {
        analysed[i] = analyse_instance(world, domain, instances[next + i], options);
      } catch (...) {
        failed[i] = std::current_exception();  // thrown below only if its turn comes
      }
    });
    for (std::size_t i = 0; i < analysed.size(); ++i) {
      if (failed[i]) std::rethrow_exception(failed[i]);
      examined.push_back(std::move(*analysed[i]));
      if (examined.back().errors == 0) break;
    }
    next += analysed.size();
  }
  return examined;
}

}  // namespace spar::planner
