// The planner's errors: every one is a spar::Error (common/error.hpp) whose message a person can
// act on. Scenario and domain files report `file:line:col: what is wrong`.
#pragma once

#include "spar/common/error.hpp"

namespace spar::planner {

// A mistake in a scenario file (or its meshes).
class ScenarioError : public spar::Error {
 public:
  using spar::Error::Error;
};

// A mistake in a domain file (action, verification or recovery templates).
class DomainError : public spar::Error {
 public:
  using spar::Error::Error;
};

// A request the planner cannot honour (bad options, a scenario with nothing to plan).
class PlanError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::planner
