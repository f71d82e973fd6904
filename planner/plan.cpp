#include "spar/planner/plan.hpp"

#include "spar/common/deadline.hpp"
#include "spar/planner/error.hpp"

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

PlanResult plan(Scenario scenario, const Domain& domain, const PlanOptions& options) {
  if (options.max_instances == 0) throw PlanError("max_instances must be at least 1");
  // Every stage (and every phase 2 instance) is also where a time limit is checked
  // (common/deadline.hpp: `spar plan --time-limit`); the long loops inside check it too.
  const std::function<void(std::string_view)> stage = [&](std::string_view text) {
    check_deadline();
    if (options.progress) options.progress(text);
  };
  stage("world model: grasps and reachability");
  PlanResult result{.world = WorldModel(std::move(scenario)),
                    .domain = domain,
                    .family = {},
                    .instances = {},
                    .examined = {},
                    .chosen_index = 0,
                    .probability = {},
                    .tolerances = {},
                    .chosen_checks = {},
                    .analysis = options.analysis};
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
    result.examined = analyse_instances(result.world, result.domain, result.instances.instances,
                                        options.analysis, stage);
    const InstanceAnalysis& chosen = result.examined[choose_instance(result.examined)];
    result.chosen_index = chosen.instance;
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
    if (options.probability) {
      stage("probability: moments, Monte Carlo, tolerance allocation");
      result.probability = analyse_probability(chosen, *options.probability);
      result.tolerances = allocate_tolerances(result.world.scenario(), chosen,
                                              {.algebra = options.probability->algebra});
    }
  }
  return result;
}

}  // namespace spar::planner
