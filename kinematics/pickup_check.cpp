#include "kinematics/pickup_check.hpp"

namespace spar::kinematics {

using bounds::Interval;

namespace {

std::vector<symbolic::Expr> condition_expressions(const PickupPreconditions& preconditions) {
  std::vector<symbolic::Expr> outputs;
  for (const PickupCondition& condition : preconditions.conditions) {
    outputs.push_back(condition.expression);
  }
  return outputs;
}

std::vector<symbolic::Expr> variable_expressions(const PickupPreconditions& preconditions) {
  symbolic::ExprPool& pool = preconditions.conditions[0].expression.pool();
  std::vector<symbolic::Expr> inputs;
  for (const UncertaintyVariable& v : preconditions.variables) {
    inputs.push_back(pool.variable(v.name));
  }
  return inputs;
}

}  // namespace

const char* to_string(Verdict verdict) {
  switch (verdict) {
    case Verdict::kSatisfied:
      return "satisfied";
    case Verdict::kViolated:
      return "violated";
    case Verdict::kUndecided:
      return "undecided";
  }
  return "?";
}

bounds::Box uncertainty_box(symbolic::ExprPool& pool,
                            std::span<const UncertaintyVariable> variables) {
  bounds::Box box;
  for (const UncertaintyVariable& v : variables) box.add(pool.variable(v.name), v.lower, v.upper);
  return box;
}

Verdict decide(const PickupCondition& condition, const bounds::BoundResult& bound) {
  if (condition.positive) {
    if (bound.lo > 0.0) return Verdict::kSatisfied;
    if (!bound.argmin.empty() && bound.inner_lo <= 0.0) return Verdict::kViolated;
  } else {
    if (bound.hi < 0.0) return Verdict::kSatisfied;
    if (!bound.argmax.empty() && bound.inner_hi >= 0.0) return Verdict::kViolated;
  }
  return Verdict::kUndecided;
}

PickupChecker::PickupChecker(const PickupPreconditions& preconditions)
    : preconditions_(preconditions),
      inputs_(variable_expressions(preconditions)),
      tape_(symbolic::Tape::compile(condition_expressions(preconditions), inputs_)),
      evaluator_(tape_),
      box_(inputs_.size()),
      centre_(inputs_.size()) {}

std::array<PickupCheck, 4> PickupChecker::check(std::span<const UncertaintyVariable> variables,
                                                const bounds::BoundOptions& full) {
  if (variables.size() != inputs_.size()) {
    throw KinematicsError("pickup check: expected " + std::to_string(inputs_.size()) +
                          " uncertainty variables, got " + std::to_string(variables.size()));
  }
  std::vector<double> centre_point(variables.size());
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const UncertaintyVariable& v = variables[i];
    if (v.name != preconditions_.variables[i].name) {
      throw KinematicsError("pickup check: variable " + std::to_string(i) + " is '" + v.name +
                            "', expected '" + preconditions_.variables[i].name + "'");
    }
    if (!(v.lower <= v.upper)) {
      throw KinematicsError("pickup check: empty range for '" + v.name + "'");
    }
    box_[i] = Interval{v.lower, v.upper};
    centre_point[i] = box_[i].mid();
    centre_[i] = Interval{centre_point[i]};
  }
  std::array<Interval, 4> natural, at_centre;
  evaluator_.evaluate(box_, natural);
  evaluator_.evaluate(centre_, at_centre);

  std::array<PickupCheck, 4> checks;
  for (std::size_t i = 0; i < checks.size(); ++i) {
    PickupCheck& check = checks[i];
    check.condition = preconditions_.conditions[i];
    bounds::BoundResult& bound = check.bound;
    bound.lo = natural[i].lo;
    bound.hi = natural[i].hi;
    // f(centre) lies in at_centre[i]: the centre attains a value <= hi and one >= lo of it.
    bound.inner_lo = at_centre[i].hi;
    bound.inner_hi = at_centre[i].lo;
    bound.argmin = bound.argmax = centre_point;
    bound.status = bounds::BoundStatus::kEffortLimit;
    bound.possibly_undefined = natural[i].possibly_undefined;
    bound.evaluations = 1;
    check.verdict = bound.possibly_undefined ? Verdict::kUndecided : decide(check.condition, bound);
    if (check.verdict != Verdict::kSatisfied) {
      // Not proved by the natural extension: a centre violation is real, but the full bound
      // also tightens [lo, hi] and finds the worst witness.
      bound = bounds::bound(check.condition.expression,
                            uncertainty_box(check.condition.expression.pool(), variables), full);
      check.verdict = decide(check.condition, bound);
    }
  }
  return checks;
}

std::array<PickupCheck, 4> check_pickup(const PickupPreconditions& preconditions,
                                        const bounds::BoundOptions& full) {
  PickupChecker checker(preconditions);
  return checker.check(preconditions.variables, full);
}

}  // namespace spar::kinematics
