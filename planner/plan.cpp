#include "spar/planner/plan.hpp"

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
  for (const ObjectSpec& object : scenario.objects)
    if (object.uncertain())
      throw ScenarioError(object.location.str() + ": object '" + object.name + "' is uncertain (" +
                          std::to_string(object.hypotheses.size()) +
                          " hypotheses): spar plan does not plan branches per sensing outcome "
                          "yet; spar sense-plan chooses the sensing operations");
  const auto stage = [&](std::string_view text) {
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
                    .tolerances = {}};
  stage("phase 1: constraint posting");
  result.family = post_plan(result.world, result.domain, options.posting);
  if (!result.planned()) return result;
  stage("phase 1: plan instances");
  result.instances =
      enumerate_instances(result.family, result.world, result.domain, options.max_instances);
  if (options.uncertainty && !result.instances.instances.empty()) {
    result.examined = analyse_instances(result.world, result.domain, result.instances.instances,
                                        options.analysis, options.progress);
    const InstanceAnalysis& chosen = result.examined[choose_instance(result.examined)];
    result.chosen_index = chosen.instance;
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
