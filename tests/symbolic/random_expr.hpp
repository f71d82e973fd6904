// Random expressions for property tests. An expression is decoded from a vector of integers (a
// "recipe"), so RapidCheck shrinks a failing case by shrinking the vector. Each 4 integers are one
// step: an operation and the indices of its operands among the values built so far (the leaves x,
// y, z and a few constants come first). Alongside the Expr, the recipe is evaluated step by step
// in plain doubles at a given point: an oracle that never touches spar's canonical forms.
#pragma once

#include <rapidcheck.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "spar/symbolic/expr.hpp"

namespace spar::symbolic::testing {

struct BuiltExpr {
  Expr expr;
  double reference;  // the recipe evaluated in doubles at the point
  double magnitude;  // largest |intermediate| met, to scale the tolerance
};

inline const std::vector<std::string>& random_variable_names() {
  static const std::vector<std::string> names{"x", "y", "z"};
  return names;
}

// smooth_only: no abs/min/max/atan2-cuts, for derivative tests.
inline BuiltExpr build_random_expr(ExprPool& pool, const std::vector<int>& recipe,
                                   const std::map<std::string, double>& point,
                                   bool smooth_only = false) {
  std::vector<Expr> exprs;
  std::vector<double> values;
  for (const auto& name : random_variable_names()) {
    exprs.push_back(pool.variable(name));
    values.push_back(point.at(name));
  }
  const std::pair<Number, double> constants[] = {{Number::integer(2), 2.0},
                                                 {Number::rational(1, 3), 1.0 / 3.0},
                                                 {Number::integer(-1), -1.0},
                                                 {Number::real(0.7), 0.7}};
  for (const auto& [n, v] : constants) {
    exprs.push_back(pool.constant(n));
    values.push_back(v);
  }
  double magnitude = 1.0;
  const int op_count = smooth_only ? 13 : 18;
  for (std::size_t k = 0; k + 3 < recipe.size(); k += 4) {
    const int op = recipe[k] % op_count;
    const std::size_t i = static_cast<std::size_t>(recipe[k + 1]) % exprs.size();
    const std::size_t j = static_cast<std::size_t>(recipe[k + 2]) % exprs.size();
    const Expr a = exprs[i], b = exprs[j];
    const double u = values[i], v = values[j];
    const int n = recipe[k + 3] % 7 - 3;  // small integer exponent
    // The recipe's doubles and spar's canonical form round differently, by some 1e-15 of the
    // magnitude. A step that would turn that noise into more than the tests' tolerance (1e-9 of
    // the magnitude) is skipped: dividing by, or taking the log, the square root or a negative
    // power of, a value within `small` of 0 (at a pole, which infinity hangs on the sign of a
    // zero, and a later step may make it finite: atan2(1/(0·tan x), x) is ±π/2); asin or acos
    // within 1e-6 of ±1 (or past it by less: defined on one side, not on the other); tan within
    // 1e-3 of a pole; atan2 near its cut.
    const double noise = 1e-9 * magnitude, small = 1e-6 * magnitude;
    const auto near_zero = [&](double w) { return !(std::fabs(w) > small); };
    const auto near_unit = [](double w) { return std::fabs(1 - std::fabs(w)) < 1e-6; };
    Expr e;
    double r;
    // Construction folds exact constants, so a step such as (x - x)^-2 divides by an exact zero
    // and throws SymbolicError (documented in number.hpp); such a step is skipped.
    try {
      switch (op) {
        case 0:
          e = a + b;
          r = u + v;
          break;
        case 1:
          e = a - b;
          r = u - v;
          break;
        case 2:
          e = a * b;
          r = u * v;
          break;
        case 3:
          if (near_zero(v)) continue;
          e = a / b;
          r = u / v;
          break;
        case 4:
          if ((n == 0 && u == 0) || (n < 0 && near_zero(u))) continue;
          e = pow(a, static_cast<std::int64_t>(n));
          r = std::isnan(u) ? u : std::pow(u, n);  // libm's pow(NaN, 0) is 1; spar keeps undefined
          break;
        case 5:
          e = sin(a);
          r = std::sin(u);
          break;
        case 6:
          e = cos(a);
          r = std::cos(u);
          break;
        case 7:
          e = exp(a);
          r = std::exp(u);
          break;
        case 8:
          if (near_zero(u)) continue;
          e = log(a);
          r = std::log(u);
          break;
        case 9:
          if (near_zero(u)) continue;
          e = sqrt(a);
          r = std::sqrt(u);
          break;
        case 10:
          e = atan(a);
          r = std::atan(u);
          break;
        case 11:
          if (!(std::fabs(std::cos(u)) > 1e-3)) continue;
          e = tan(a);
          r = std::tan(u);
          break;
        case 12:
          e = a * pool.constant(Number::rational(recipe[k + 3] % 11 - 5, 4));
          r = u * ((recipe[k + 3] % 11 - 5) / 4.0);
          break;
        case 13:
          e = abs(a);
          r = std::fabs(u);
          break;
        case 14:
          e = min(a, b);
          r = std::isnan(u) || std::isnan(v) ? NAN : std::fmin(u, v);  // fmin drops one NaN
          break;
        case 15:
          e = max(a, b);
          r = std::isnan(u) || std::isnan(v) ? NAN : std::fmax(u, v);
          break;
        case 16:
          // Near atan2's cut (y = 0, x <= 0) the sign of a zero decides the value (±π, or 0
          // against π at the origin), and two evaluations of one value may give zeros of either
          // sign or noise around 0 (x·0 is -0.0 at a negative x in the recipe's doubles, an exact
          // 0 in spar; a tape may skip the "+ 0" the node oracle adds; an undefined y, NaN here,
          // may evaluate to a zero there).
          if (!(std::fabs(u) > noise) && !(v > noise)) continue;
          e = atan2(a, b);
          r = std::atan2(u, v);
          break;
        default:
          if (near_unit(u) || near_unit(v)) continue;
          e = asin(a) + acos(b);
          r = std::asin(u) + std::acos(v);
          break;
      }
    } catch (const SymbolicError&) {
      continue;
    }
    exprs.push_back(e);
    values.push_back(r);
    if (std::isfinite(r)) magnitude = std::max(magnitude, std::fabs(r));
  }
  return {exprs.back(), values.back(), magnitude};
}

inline rc::Gen<std::vector<int>> random_recipe(int max_steps = 12) {
  return rc::gen::suchThat(rc::gen::container<std::vector<int>>(rc::gen::inRange(0, 1 << 16)),
                           [max_steps](const std::vector<int>& r) {
                             return r.size() >= 4 && r.size() <= 4u * max_steps;
                           });
}

inline rc::Gen<std::map<std::string, double>> random_point() {
  return rc::gen::map(rc::gen::container<std::vector<int>>(3, rc::gen::inRange(-3000, 3000)),
                      [](const std::vector<int>& v) {
                        return std::map<std::string, double>{{"x", v[0] / 1000.0 + 1e-3},
                                                             {"y", v[1] / 1000.0 - 2e-3},
                                                             {"z", v[2] / 1000.0}};
                      });
}

}  // namespace spar::symbolic::testing
