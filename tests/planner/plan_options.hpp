// PlanOptions the planner tests share.
#pragma once

#include <cstddef>

#include "spar/planner/plan.hpp"

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

}  // namespace spar::planner::testing
