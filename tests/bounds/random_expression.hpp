// Random expressions in x and y for the bounds properties (RapidCheck generators inside a
// property): shared by bound_test.cpp and condition_set_test.cpp.
#pragma once

#include <rapidcheck.h>

#include <vector>

#include "spar/symbolic/expr.hpp"

namespace spar::bounds::testing {

inline symbolic::Expr random_expression_or_throw(symbolic::ExprPool& pool);

// Builds an expression bottom-up from random choices (no recursion): nodes 0, 1 are x, y, node 2
// a constant; each new node applies one operation to earlier nodes. Construction folds constants,
// so a choice such as 0^-1 is a SymbolicError: that case is discarded, not a bounds failure.
inline symbolic::Expr random_expression(symbolic::ExprPool& pool) {
  try {
    return random_expression_or_throw(pool);
  } catch (const symbolic::SymbolicError& error) {
    RC_DISCARD(error.what());
  }
  return {};
}

inline symbolic::Expr random_expression_or_throw(symbolic::ExprPool& pool) {
  std::vector<symbolic::Expr> nodes = {
      pool.variable("x"), pool.variable("y"),
      pool.constant(symbolic::Number::rational(*rc::gen::inRange(-9, 10), 4))};
  const int steps = *rc::gen::inRange(1, 7);
  for (int step = 0; step < steps; ++step) {
    const int n = static_cast<int>(nodes.size());
    const symbolic::Expr a = nodes[*rc::gen::inRange(0, n)];
    const symbolic::Expr b = nodes[*rc::gen::inRange(0, n)];
    symbolic::Expr e;
    switch (*rc::gen::inRange(0, 21)) {
      case 0:
        e = a + b;
        break;
      case 1:
        e = a - b;
        break;
      case 2:
        e = a * b;
        break;
      case 3:
        e = a / b;
        break;
      case 4:
        e = symbolic::pow(a, *rc::gen::inRange(-3, 5));
        break;
      case 5:
        e = symbolic::sin(a);
        break;
      case 6:
        e = symbolic::cos(a);
        break;
      case 7:
        e = symbolic::tan(a);
        break;
      case 8:
        e = symbolic::sqrt(a);
        break;
      case 9:
        e = symbolic::exp(symbolic::sin(a));
        break;
      case 10:
        e = symbolic::log(a);
        break;
      case 11:
        e = symbolic::abs(a);
        break;
      case 12:
        e = symbolic::atan(a);
        break;
      case 13:
        e = symbolic::asin(symbolic::sin(a));
        break;
      case 14:
        e = symbolic::acos(symbolic::cos(a));
        break;
      case 15:
        e = symbolic::atan2(a, b);
        break;
      case 16:
        e = symbolic::min(a, b);
        break;
      case 17:
        e = symbolic::max(a, b);
        break;
      case 18:
        e = symbolic::pow(symbolic::abs(a) + 1, symbolic::sin(b));
        break;
      case 19:
        e = a * a - b;
        break;
      default:
        e = symbolic::sin(a) * symbolic::cos(b);
        break;
    }
    nodes.push_back(e);
  }
  return nodes.back();
}

}  // namespace spar::bounds::testing
