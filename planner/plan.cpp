#include "spar/planner/plan.hpp"

#include <algorithm>
#include <latch>
#include <optional>
#include <string>

#include "spar/common/deadline.hpp"
#include "spar/common/parallel.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/uncertainty/margins.hpp"

namespace spar::planner {

const PlanInstance& PlanResult::chosen() const {
  if (instances.instances.empty())
    throw PlanError("no plan instance: " +
                    (family.reason.empty() ? "none enumerated" : family.reason));
  return instances.instances.at(chosen_index);
}

const InstanceAnalysis* PlanResult::chosen_analysis() const {
  for (const InstanceAnalysis& analysis : examined)
    if (analysis.instance == chosen_index) return &analysis;
  return nullptr;
}

bool PlanResult::planned() const {
  if (sensing)
    return !branches.empty() && std::all_of(branches.begin(), branches.end(),
                                            [](const PlanBranch& b) { return b.result.planned(); });
  return family.status == PostingStatus::kPlanned;
}

namespace {

// The world model of `scenario`, nothing planned yet.
PlanResult started(Scenario scenario, const Domain& domain, const PlanOptions& options) {
  AnalysisOptions analysis = options.analysis;
  analysis.threads = options.threads;
  return {.world = WorldModel(std::move(scenario), options.threads),
          .domain = domain,
          .family = {},
          .instances = {},
          .examined = {},
          .chosen_index = 0,
          .probability = {},
          .tolerances = {},
          .chosen_checks = {},
          .analysis = analysis};
}

// The chosen instance's margins (margins.hpp) and, when asked, its probability and tolerance
// allocation (probability.hpp), as one list of tasks on the plan's threads, so that the cores
// share all of it. Each part reads the analysis' pool when it is built, so on this thread: the
// probability's (its Jacobian, a few ms) while the other threads start on the margins (the
// costliest first). Its two tasks, the allocation and the Monte Carlo (each one task, the
// longest), come right after the first margin task and wait until it is built.
void add_extras(PlanResult& result, InstanceAnalysis& chosen, const PlanOptions& options,
                const std::function<void(std::string_view)>& stage) {
  stage(options.probability ? "phase 2: margins, probability, tolerance allocation"
                            : "phase 2: margins");
  MarginWork margins(chosen, result.analysis);
  std::optional<ProbabilityWork> probability;
  std::latch built(1);
  const auto build_probability = [&] {
    const struct CountDown {
      std::latch& latch;
      ~CountDown() { latch.count_down(); }
    } when_done{built};
    // The allocation is one task among the margins' here, so its rows get half the threads: on
    // all of them its verification only competed with the margins for the cores (on-back's
    // extras on two threads: 45 ms with it on two, 42 on one).
    probability.emplace(result.world.scenario(), chosen, *options.probability,
                        AllocationOptions{.algebra = options.probability->algebra,
                                          .threads = std::max(1u, options.threads / 2)});
  };
  const std::size_t first_probability =
      options.probability ? std::min<std::size_t>(1, margins.tasks()) : 0;
  const std::size_t probability_tasks = options.probability ? 2 : 0;
  const std::size_t tasks = margins.tasks() + probability_tasks;
  const std::string of_total = " of " + std::to_string(tasks) + " done";
  run_tasks(
      tasks, options.threads,
      [&](std::size_t t) {
        if (t < first_probability || t >= first_probability + probability_tasks) {
          margins.run(t < first_probability ? t : t - probability_tasks);
          return;
        }
        built.wait();
        if (!probability) return;  // its building threw: run_tasks rethrows that
        if (t == first_probability)
          probability->allocate();
        else
          probability->sample();
      },
      [&](std::size_t finished) {
        stage("phase 2: extras: " + std::to_string(finished) + of_total);
      },
      options.probability ? std::function<void()>(build_probability) : std::function<void()>());
  margins.finish();
  if (probability) {
    result.probability = probability->probability();
    result.tolerances = probability->tolerances();
  }
}

// Sense first, then plan each hypothesis of object `index` as the truth.
PlanResult plan_branches(Scenario scenario, std::size_t index, const Domain& domain,
                         const PlanOptions& options) {
  check_deadline();
  if (options.progress) options.progress("sense planning: aspects and candidate operations");
  PlanResult result = started(std::move(scenario), domain, options);
  const Scenario& uncertain = result.world.scenario();
  const ObjectSpec& object = uncertain.objects[index];
  SensePlan sensed = plan_sensing(uncertain, result.world);
  result.sensing = std::move(sensed.objects.front());  // the only uncertain object
  const sensing::Selection& selection = result.sensing->selection;
  if (!selection.resolved) {
    const double least = selection.sequence.empty()
                             ? selection.ambiguity_before
                             : selection.sequence.back().predicted_max_ambiguity;
    result.family.reason = "sensing cannot tell the hypotheses of '" + object.name +
                           "' apart: the chosen operations leave " + std::to_string(least) +
                           " bits in the worst case, sensing.ambiguity_threshold is " +
                           std::to_string(uncertain.sensing.ambiguity_threshold);
    return result;
  }
  for (std::size_t h = 0; h < object.hypotheses.size(); ++h)
    result.branches.push_back(
        {.object = object.name,
         .outcome = object.hypotheses[h].label,
         .result = plan(uncertain.resolved(object.name, h), domain, options)});
  return result;
}

}  // namespace

PlanResult plan(Scenario scenario, const Domain& domain, const PlanOptions& options) {
  if (options.max_instances == 0) throw PlanError("max_instances must be at least 1");
  std::optional<std::size_t> uncertain;
  for (std::size_t i = 0; i < scenario.objects.size(); ++i) {
    const ObjectSpec& object = scenario.objects[i];
    if (!object.uncertain()) continue;
    if (uncertain)
      throw ScenarioError(object.location.str() + ": objects '" +
                          scenario.objects[*uncertain].name + "' and '" + object.name +
                          "' are both uncertain: spar plan branches on one uncertain object "
                          "(spar sense-plan chooses sensing for several)");
    uncertain = i;
  }
  if (uncertain) return plan_branches(std::move(scenario), *uncertain, domain, options);
  // Every stage (and every phase 2 instance) is also where a time limit is checked
  // (common/deadline.hpp: `spar plan --time-limit`); the long loops inside check it too.
  const std::function<void(std::string_view)> stage = [&](std::string_view text) {
    check_deadline();
    if (options.progress) options.progress(text);
  };
  stage("world model: grasps and reachability");
  PlanResult result = started(std::move(scenario), domain, options);
  stage("phase 1: constraint posting");
  PostingOptions posting = options.posting;
  // A complete family counts only if one of its instances is collision-free.
  posting.accept = [&](const PlanFamily& family) -> std::optional<std::string> {
    InstanceEnumerator instances(family, result.world, result.domain, 20'000,
                                 /*measure=*/false);
    if (instances.next()) return std::nullopt;
    return "none of its " + std::to_string(instances.examined()) +
           " plan instances examined is collision-free (the first: " + instances.first_conflict() +
           ")";
  };
  result.family = post_plan(result.world, result.domain, posting);
  if (!result.planned()) return result;
  stage("phase 1: plan instances");
  result.instances =
      enumerate_instances(result.family, result.world, result.domain, options.max_instances);
  if (options.uncertainty && !result.instances.instances.empty()) {
    AnalysisOptions examining = result.analysis;
    // Sensor margins for the chosen instance only: below, unless analyse_instances added them
    // on a thread that had finished its round's analysis (add_sensor_margins is then a no-op).
    examining.defer_sensor_margins = true;
    result.examined = analyse_instances(result.world, result.domain, result.instances.instances,
                                        examining, stage);
    InstanceAnalysis& chosen = result.examined[choose_instance(result.examined)];
    result.chosen_index = chosen.instance;
    add_sensor_margins(result.world, result.domain, chosen, result.analysis);
    // The chosen plan's collision checks in phase 2's order: a squeeze phase 2 inserted happens
    // in the world as it is before the step that follows it.
    WorldState state = result.world.initial_state();
    const PlanInstance& instance = result.chosen();
    for (const AnalysedStep& analysed : chosen.steps) {
      if (analysed.step.instance_step >= 0) {
        const InstanceStep& step = instance.steps[analysed.step.instance_step];
        result.chosen_checks.emplace_back(step.collision, step.carried);
        apply_step(state, step, result.domain);
      } else if (analysed.step.grasp >= 0) {
        const std::vector<int> group = state.moving_with(analysed.step.object);
        result.chosen_checks.emplace_back(
            result.world.check_grasp(state, analysed.step.object, analysed.step.grasp,
                                     analysed.step.object_pose),
            std::vector<int>(group.begin() + 1, group.end()));
      } else {
        result.chosen_checks.emplace_back();
      }
    }
    add_extras(result, chosen, options, stage);
  }
  return result;
}

}  // namespace spar::planner
