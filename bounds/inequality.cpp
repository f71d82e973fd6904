#include "bounds/inequality.hpp"

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
  switch (relation) {
    case Relation::kLess:
      return "<";
    case Relation::kLessEqual:
      return "<=";
    case Relation::kGreater:
      return ">";
    case Relation::kGreaterEqual:
      return ">=";
  }
  return "?";
}

Verdict decide(const Inequality& inequality, const BoundResult& bound) {
  const double t = inequality.threshold;
  // A bound proves nothing where f may be undefined, nor when no point of the box was feasible.
  const bool provable = !bound.possibly_undefined && bound.status != BoundStatus::kInfeasible;
  const bool has_argmin = !bound.argmin.empty(), has_argmax = !bound.argmax.empty();
  switch (inequality.relation) {
    case Relation::kLess:
      if (provable && bound.hi < t) return Verdict::kSatisfied;
      if (has_argmax && bound.inner_hi >= t) return Verdict::kViolated;
      break;
    case Relation::kLessEqual:
      if (provable && bound.hi <= t) return Verdict::kSatisfied;
      if (has_argmax && bound.inner_hi > t) return Verdict::kViolated;
      break;
    case Relation::kGreater:
      if (provable && bound.lo > t) return Verdict::kSatisfied;
      if (has_argmin && bound.inner_lo <= t) return Verdict::kViolated;
      break;
    case Relation::kGreaterEqual:
      if (provable && bound.lo >= t) return Verdict::kSatisfied;
      if (has_argmin && bound.inner_lo < t) return Verdict::kViolated;
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
