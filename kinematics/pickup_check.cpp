#include "kinematics/pickup_check.hpp"

namespace spar::kinematics {

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

std::array<PickupCheck, 4> check_pickup(const PickupPreconditions& preconditions,
                                        const bounds::BoundOptions& full) {
  bounds::BoundOptions cheap = full;
  cheap.inner = false;
  cheap.branch_and_bound = false;
  std::array<PickupCheck, 4> checks;
  for (std::size_t i = 0; i < checks.size(); ++i) {
    const PickupCondition& condition = preconditions.conditions[i];
    const bounds::Box box = uncertainty_box(condition.expression.pool(), preconditions.variables);
    PickupCheck& check = checks[i];
    check.condition = condition;
    check.bound = bounds::bound(condition.expression, box, cheap);
    check.verdict = decide(condition, check.bound);
    if (check.verdict == Verdict::kUndecided) {
      check.bound = bounds::bound(condition.expression, box, full);
      check.verdict = decide(condition, check.bound);
    }
  }
  return checks;
}

}  // namespace spar::kinematics
