// Plans a scenario with an installed spar (tests/package).
#include "spar/planner/plan.hpp"

#include <iostream>

#include "spar/reports/plan_json.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: plan_consumer SCENARIO\n";
    return 2;
  }
  spar::planner::PlanOptions options;
  options.probability.reset();
  const auto result = spar::planner::plan(spar::planner::load_scenario(argv[1]),
                                          spar::planner::builtin_domain(), options);
  std::cout << "status " << spar::reports::plan_json(result)["status"].get<std::string>() << '\n';
}
