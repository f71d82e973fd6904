#include "spar/bounds/inequality.hpp"

namespace spar::bounds {

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

const char* to_string(Relation relation) {
  return relation_name(relation).data();  // the table's literals are null-terminated
}

Verdict decide(const Inequality& inequality, const BoundResult& bound) {
  const double t = inequality.threshold;
  // Violations are read from the rigorous values at the witnesses (the inner bounds may be
  // clamped or averaged: see BoundResult).
  // A bound proves nothing where f may be undefined, nor when no point of the box was feasible.
  const bool provable = !bound.possibly_undefined && bound.status != BoundStatus::kInfeasible;
  const bool has_argmin = !bound.argmin_value.is_empty();
  const bool has_argmax = !bound.argmax_value.is_empty();
  switch (inequality.relation) {
    case Relation::kLess:
      if (provable && bound.hi < t) return Verdict::kSatisfied;
      if (has_argmax && bound.argmax_value.lo >= t) return Verdict::kViolated;
      break;
    case Relation::kLessEqual:
      if (provable && bound.hi <= t) return Verdict::kSatisfied;
      if (has_argmax && bound.argmax_value.lo > t) return Verdict::kViolated;
      break;
    case Relation::kGreater:
      if (provable && bound.lo > t) return Verdict::kSatisfied;
      if (has_argmin && bound.argmin_value.hi <= t) return Verdict::kViolated;
      break;
    case Relation::kGreaterEqual:
      if (provable && bound.lo >= t) return Verdict::kSatisfied;
      if (has_argmin && bound.argmin_value.hi < t) return Verdict::kViolated;
      break;
  }
  return Verdict::kUndecided;
}

const std::vector<double>& witness(const Inequality& inequality, const BoundResult& bound) {
  const bool upper =
      inequality.relation == Relation::kLess || inequality.relation == Relation::kLessEqual;
  return upper ? bound.argmax : bound.argmin;
}

}  // namespace spar::bounds
