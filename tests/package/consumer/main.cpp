// Bounds an expression and plans a scenario with an installed spar (tests/package).
#include <iostream>

#include "spar/bounds/bound.hpp"
#include "spar/planner/plan.hpp"
#include "spar/reports/plan_json.hpp"
#include "spar/symbolic/parse.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: consumer SCENARIO\n";
    return 2;
  }
  spar::symbolic::ExprPool pool;
  const spar::symbolic::Expr f = spar::symbolic::parse(pool, "x^2 - x");
  spar::bounds::Box box;
  box.add(pool.variable("x"), 0.0, 1.0);
  const spar::bounds::BoundResult r = spar::bounds::bound(f, box, {.tolerance = 1e-9});
  std::cout << spar::symbolic::to_string(f) << " in [" << r.lo << ", " << r.hi << "]\n";
  spar::planner::PlanOptions options;
  options.probability.reset();
  const auto result = spar::planner::plan(spar::planner::load_scenario(argv[1]),
                                          spar::planner::builtin_domain(), options);
  std::cout << "status " << spar::reports::plan_json(result)["status"].get<std::string>() << '\n';
}
