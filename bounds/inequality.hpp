// Inequalities and their verdicts: the one vocabulary for "does this precondition hold over the
// box?".
//
// An Inequality is `expression relation threshold` (relation from bound.hpp: <, <=, >, >=). Given
// a BoundResult of the expression over a box, decide() returns
//   satisfied  the SOUND bound proves it at every point of the box: hi < threshold for `<`,
//              hi <= threshold for `<=`, lo > threshold for `>`, lo >= threshold for `>=` (a strict
//              relation needs strict proof), and the expression is defined on the whole box
//              (not possibly_undefined) and the result is not infeasible;
//   violated   an attained witness value breaks it, rigorously: for `<` / `<=` the value at
//              argmax is >= / > threshold (argmax_value.lo, a lower bound of f(argmax), is), for
//              `>` / `>=` the value at argmin is <= / < threshold (argmin_value.hi is); the
//              witness point is given;
//   undecided  neither: the bound is not tight enough to tell, or the expression may be undefined
//              somewhere in the box. Planning counts it as a failure but reports it as its own.
// Since lo <= f(argmin) and f(argmax) <= hi, satisfied and violated exclude each other. NaN
// thresholds are refused where inequalities are built (ConditionSet); decide() on one gives
// undecided.
//
// Example:
//   const Inequality clearance{"0 < [0,1,0,0] P1^-1 C1", y1, Relation::kGreater, 0.0};
//   const BoundResult r = bound(clearance.expression, box);
//   if (decide(clearance, r) == Verdict::kViolated)
//     report(witness(clearance, r));                  // the point where it fails
#pragma once

#include <span>
#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/symbolic/expr.hpp"

namespace spar::bounds {

enum class Verdict { kSatisfied, kViolated, kUndecided };
[[nodiscard]] const char* to_string(Verdict verdict);    // "satisfied", "violated", "undecided"
[[nodiscard]] const char* to_string(Relation relation);  // "<", "<=", ">", ">="

// expression <relation> threshold.
struct Inequality {
  std::string name;  // for reports, e.g. "0 < [0,1,0,0] P1^-1 C1"
  symbolic::Expr expression;
  Relation relation{Relation::kLessEqual};
  double threshold{0.0};
};

[[nodiscard]] Verdict decide(const Inequality& inequality, const BoundResult& bound);

// The point that decides the inequality's worst case: argmax for `<` and `<=`, argmin for `>` and
// `>=` (a violating point when decide() says violated). Empty if the bound found none (or if
// there are no variables).
[[nodiscard]] const std::vector<double>& witness(const Inequality& inequality,
                                                 const BoundResult& bound);

}  // namespace spar::bounds
