// Bounds an expression with an installed spar's symbolic and bounds libraries (tests/package;
// the shared-library install links only these two).
#include "spar/bounds/bound.hpp"

#include <iostream>

#include "spar/symbolic/parse.hpp"

int main() {
  spar::symbolic::ExprPool pool;
  const spar::symbolic::Expr f = spar::symbolic::parse(pool, "x^2 - x");
  spar::bounds::Box box;
  box.add(pool.variable("x"), 0.0, 1.0);
  const spar::bounds::BoundResult r = spar::bounds::bound(f, box, {.tolerance = 1e-9});
  std::cout << spar::symbolic::to_string(f) << " in [" << r.lo << ", " << r.hi << "]\n";
}
