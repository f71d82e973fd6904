// The one bisection phase 2 uses (reverse analysis of preconditions and of the sensor, tolerance
// allocation): the largest value of a parameter for which a monotone predicate still holds.
#pragma once

namespace spar::planner::internal {

// The largest x in [lo, hi] with holds(x), to within (hi - lo) / 2^iterations, for a predicate
// that holds up to some x* and fails above it; the caller has checked holds(lo). Returns hi when
// holds(hi); otherwise the last value found to hold (never one that failed).
template <class Predicate>
[[nodiscard]] double largest_holding(double lo, double hi, int iterations, Predicate&& holds) {
  if (holds(hi)) return hi;
  double good = lo, bad = hi;
  for (int i = 0; i < iterations; ++i) {
    const double middle = 0.5 * (good + bad);
    (holds(middle) ? good : bad) = middle;
  }
  return good;
}

}  // namespace spar::planner::internal
