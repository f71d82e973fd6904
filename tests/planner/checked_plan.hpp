// Issue 21's planner tests share these: scenarios written as text and changed one line at a time,
// phase 1 with every plan instance passed through both independent checkers
// (plan_checker.hpp's steps, collision_checker.hpp's geometry), and a plan's actions as text.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "spar/planner/plan.hpp"
#include "tests/common/replaced.hpp"
#include "tests/planner/collision_checker.hpp"
#include "tests/planner/plan_checker.hpp"

namespace spar::planner::testing {

using test_support::replaced;

inline Scenario scenario_of(const std::string& yaml) {
  return parse_scenario(yaml, "test.yaml", ".");
}

// Phase 1 only (at most `max_instances` instances, `max_nodes` partial plans); every instance
// found must pass check_instance and the independent collision checker.
inline PlanResult plan_checked(const Scenario& scenario, std::size_t max_instances = 4,
                               std::size_t max_nodes = 20'000) {
  PlanOptions options;
  options.uncertainty = false;
  options.max_instances = max_instances;
  options.posting.max_nodes = max_nodes;
  PlanResult result = plan(scenario, builtin_domain(), options);
  std::vector<std::vector<geometry::Grasp>> grasps;
  for (std::size_t o = 0; o < result.world.object_count(); ++o)
    grasps.push_back(result.world.object(static_cast<int>(o)).grasps);
  const IndependentCollisionChecker collisions(scenario, grasps);
  for (const PlanInstance& instance : result.instances.instances) {
    const std::vector<std::string> problems = check_instance(scenario, grasps, instance);
    EXPECT_TRUE(problems.empty()) << "instance " << instance.index << ": " << problems.front();
    const std::vector<std::string> hits = collisions.check(instance);
    EXPECT_TRUE(hits.empty()) << "instance " << instance.index << ": " << hits.front();
  }
  return result;
}

// "pickup block", "putdown block", ... of an instance.
inline std::vector<std::string> actions(const Scenario& scenario, const PlanInstance& instance) {
  std::vector<std::string> out;
  for (const InstanceStep& step : instance.steps)
    out.push_back(step.action_name + " " + scenario.objects[step.object].name);
  return out;
}

}  // namespace spar::planner::testing
