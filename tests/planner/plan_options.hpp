// PlanOptions, scenarios and look-ups the planner tests share.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <string>

#include "spar/planner/domain.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/scenario.hpp"

namespace spar::planner::testing {

// Phase 2 without the chosen-instance extras that cost time (reverse analysis, blame, Monte
// Carlo); the tight re-bound of the chosen instance still runs and gives every precondition its
// witnesses.
inline PlanOptions quick_options(std::size_t max_instances) {
  PlanOptions options;
  options.max_instances = max_instances;
  options.analysis.reverse = false;
  options.analysis.blame = false;
  options.analysis.samples = 0;
  return options;
}

inline const std::filesystem::path kExamples = std::filesystem::path(SPAR_SOURCE_DIR) / "examples";

// examples/NAME.yaml.
inline Scenario example(const std::string& name) {
  return load_scenario(kExamples / (name + ".yaml"));
}

// The peg picked up from its block (tests/planner/data/phase2_peg_pickup.yaml).
inline Scenario peg_pickup() {
  return load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml");
}

// The index of the domain's first action with `effect` (a test failure, -1, when none has it).
inline int action_with(const Domain& domain, Effect effect) {
  for (std::size_t a = 0; a < domain.actions.size(); ++a)
    if (domain.actions[a].effect == effect) return static_cast<int>(a);
  ADD_FAILURE() << "the domain has no action with that effect";
  return -1;
}

}  // namespace spar::planner::testing
