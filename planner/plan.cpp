#include "planner/plan.hpp"

#include "planner/error.hpp"

namespace spar::planner {

const PlanInstance& PlanResult::chosen() const {
  if (instances.instances.empty())
    throw PlanError("no plan instance: " + (family.reason.empty() ? "none enumerated" : family.reason));
  return instances.instances.at(chosen_index);
}

PlanResult plan(Scenario scenario, const Domain& domain, const PlanOptions& options) {
  if (options.max_instances == 0) throw PlanError("max_instances must be at least 1");
  PlanResult result{.world = WorldModel(std::move(scenario)), .domain = domain, .family = {},
                    .instances = {}, .chosen_index = 0};
  result.family = post_plan(result.world, result.domain, options.posting);
  if (result.planned())
    result.instances =
        enumerate_instances(result.family, result.world, result.domain, options.max_instances);
  return result;
}

}  // namespace spar::planner
