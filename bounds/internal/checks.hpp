// Validation shared by bound(), BoundProblem and ConditionSet, so a bad box gets the same message
// from each. Each throws BoundsError naming the variable.
#pragma once

#include <span>
#include <string>

#include "bounds/interval.hpp"
#include "symbolic/expr.hpp"

namespace spar::bounds::internal {

// A NaN, infinite or empty (lo > hi) range.
void check_range(const std::string& name, double lo, double hi);
// Not a variable, or already among `earlier`.
void check_variable(symbolic::Expr variable, std::span<const symbolic::Expr> earlier);
// ranges.size() != variables.size(), or any range check_range refuses.
void check_ranges(std::span<const symbolic::Expr> variables, std::span<const Interval> ranges);
// A free variable of `expression` that is not among `variables`; `what` names the expression in
// the message ("the expression", "the constraint", "inequality 'clear'").
void check_uses_only(symbolic::Expr expression, std::span<const symbolic::Expr> variables,
                     const std::string& what);

}  // namespace spar::bounds::internal
