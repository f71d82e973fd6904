// Validation and result bookkeeping shared by bound(), BoundProblem and ConditionSet, so a bad box
// gets the same message from each and every result keeps BoundResult's invariants. The checks
// throw BoundsError naming the variable.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <string>

#include "spar/bounds/bound.hpp"
#include "spar/bounds/interval.hpp"
#include "spar/symbolic/expr.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds::internal {

// A NaN, infinite or empty (lo > hi) range.
void check_range(const std::string& name, double lo, double hi);
// Not a variable, or already among `earlier`.
void check_variable(symbolic::Expr variable, std::span<const symbolic::Expr> earlier);
// ranges.size() != variables.size(), or any range check_range refuses.
void check_ranges(std::span<const symbolic::Expr> variables, std::span<const Interval> ranges);
// Tape::compile(outputs, variables) for non-null outputs and variables check_variable accepted,
// where an output using a variable that is not listed throws BoundsError naming the first such
// output (`what(i)`: "the expression", "the constraint", "inequality 'clear'") and the variable.
// The compile walks the DAG anyway; the walk that finds the names runs only when it fails.
[[nodiscard]] symbolic::Tape compile_checked(std::span<const symbolic::Expr> outputs,
                                             std::span<const symbolic::Expr> variables,
                                             const std::function<std::string(std::size_t)>& what);

// Offers `point`, where f's enclosure is `value` (defined, not empty), as a witness: it becomes
// argmin if value.hi < inner_lo and argmax if value.lo > inner_hi (inner_lo / inner_hi are then
// the rigorous argmin_value.hi / argmax_value.lo until order_inner_bounds(), bound.hpp).
void offer_witness(BoundResult& result, std::span<const double> point, const Interval& value);

}  // namespace spar::bounds::internal
