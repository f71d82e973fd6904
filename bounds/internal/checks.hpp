// Validation and result bookkeeping shared by bound(), BoundProblem and ConditionSet, so a bad box
// gets the same message from each and every result keeps BoundResult's invariants. The checks
// throw BoundsError naming the variable.
#pragma once

#include <span>
#include <string>

#include "spar/bounds/bound.hpp"
#include "spar/bounds/interval.hpp"
#include "spar/symbolic/expr.hpp"

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

// Offers `point`, where f's enclosure is `value` (defined, not empty), as a witness: it becomes
// argmin if value.hi < inner_lo and argmax if value.lo > inner_hi (inner_lo / inner_hi are then
// the rigorous argmin_value.hi / argmax_value.lo until order_inner_bounds()).
void offer_witness(BoundResult& result, std::span<const double> point, const Interval& value);
// Final inner bounds: without witnesses inner_lo = hi and inner_hi = lo; else argmin_value.hi and
// argmax_value.lo clamped into [lo, hi], and their midpoint for both if they cross by a rounding
// (1e-12 relative); crossing by more, inner_lo = hi and inner_hi = lo (nothing attained known).
void order_inner_bounds(BoundResult& result);

}  // namespace spar::bounds::internal
