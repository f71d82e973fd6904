#include "spar/kinematics/pickup_check.hpp"

#include <string>

#include "spar/kinematics/internal/pickup_shared.hpp"

namespace spar::kinematics {

namespace {

bounds::ConditionSet condition_set(const PickupPreconditions& preconditions) {
  std::vector<bounds::Inequality> inequalities;
  for (const PickupCondition& condition : preconditions.conditions) {
    inequalities.push_back(as_inequality(condition));
  }
  symbolic::ExprPool& pool = preconditions.conditions[0].expression.pool();
  std::vector<symbolic::Expr> variables;
  for (const UncertaintyVariable& v : preconditions.variables) {
    variables.push_back(pool.variable(v.name));
  }
  return bounds::ConditionSet(std::move(inequalities), std::move(variables));
}

}  // namespace

void internal::pickup_ranges(std::span<const UncertaintyVariable> expected,
                             std::span<const UncertaintyVariable> given,
                             std::span<bounds::Interval> ranges) {
  if (given.size() != expected.size()) {
    throw KinematicsError("pickup check: expected " + std::to_string(expected.size()) +
                          " uncertainty variables, got " + std::to_string(given.size()));
  }
  for (std::size_t i = 0; i < given.size(); ++i) {
    const UncertaintyVariable& v = given[i];
    if (v.name != expected[i].name) {
      throw KinematicsError("pickup check: variable " + std::to_string(i) + " is '" + v.name +
                            "', expected '" + expected[i].name + "'");
    }
    if (!(v.lower <= v.upper)) {
      throw KinematicsError("pickup check: empty range for '" + v.name + "'");
    }
    ranges[i] = bounds::Interval{v.lower, v.upper};
  }
}

bounds::Box uncertainty_box(symbolic::ExprPool& pool,
                            std::span<const UncertaintyVariable> variables) {
  bounds::Box box;
  for (const UncertaintyVariable& v : variables) box.add(pool.variable(v.name), v.lower, v.upper);
  return box;
}

bounds::Inequality as_inequality(const PickupCondition& condition) {
  return {condition.name, condition.expression,
          condition.positive ? bounds::Relation::kGreater : bounds::Relation::kLess, 0.0};
}

PickupChecker::PickupChecker(const PickupPreconditions& preconditions)
    : preconditions_(preconditions), conditions_(condition_set(preconditions)) {}

std::array<PickupCheck, 4> PickupChecker::check(std::span<const UncertaintyVariable> variables,
                                                const bounds::BoundOptions& full) {
  std::vector<bounds::Interval> ranges(preconditions_.variables.size());
  internal::pickup_ranges(preconditions_.variables, variables, ranges);
  const std::vector<bounds::ConditionCheck> decided =
      conditions_.check(ranges, full, bounds::Escalation::kNotSatisfied);
  std::array<PickupCheck, 4> checks;
  for (std::size_t i = 0; i < checks.size(); ++i) {
    checks[i] = {preconditions_.conditions[i], decided[i].bound, decided[i].verdict};
  }
  return checks;
}

std::array<PickupCheck, 4> check_pickup(const PickupPreconditions& preconditions,
                                        const bounds::BoundOptions& full) {
  PickupChecker checker(preconditions);
  return checker.check(preconditions.variables, full);
}

}  // namespace spar::kinematics
