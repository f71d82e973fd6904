// The one bisection phase 2 uses (reverse analysis of preconditions and of the sensor, tolerance
// allocation): the largest value of a parameter for which a monotone predicate still holds.
//
// Guided form: a predicate that costs most near its answer (the reverse analysis decides one
// precondition per scale; deciding near the threshold scale takes ~100 boxes, far from it one)
// may also say where it expects the answer, from what it learnt at the bracket's two ends. The
// search then probes there instead of at the middle, on the same grid of (hi - lo) / 2^iterations:
// for a monotone predicate every guess gives the answer the plain bisection gives (the largest
// grid value that holds), only in fewer probes when the guesses are good. Bad guesses cost at most
// three times the bisection's probes (after two guided probes in a row that did not halve the
// bracket, the next one bisects).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

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

// The same answer as largest_holding for a monotone predicate when the grid is exact in doubles
// (lo = 0, hi a power of two, iterations <= 40; else within rounding of it), with `guess(good,
// bad)` proposing where in [good, bad] the last holding value lies (NaN: no idea; the middle is
// probed). `good` and `bad` are always values the predicate was asked about (lo, hi or a probe), so
// the guess may use what it learnt there. A guess is rounded down to the grid and kept strictly
// inside the bracket.
template <class Predicate, class Guess>
[[nodiscard]] double largest_holding(double lo, double hi, int iterations, Predicate&& holds,
                                     Guess&& guess) {
  if (holds(hi)) return hi;
  const double step = (hi - lo) / std::ldexp(1.0, std::clamp(iterations, 0, 40));
  const auto on_grid = [&](double x, double good, double bad) {
    return std::clamp(lo + step * std::floor((x - lo) / step), good + step, bad - step);
  };
  double good = lo, bad = hi;
  int slow_guesses = 0;  // guided probes in a row that left more than half the bracket
  while (bad - good > 1.5 * step) {
    const double width = bad - good;
    double x = slow_guesses >= 2 ? std::numeric_limits<double>::quiet_NaN() : guess(good, bad);
    const bool guided = std::isfinite(x);
    x = on_grid(guided ? x : 0.5 * (good + bad), good, bad);
    (holds(x) ? good : bad) = x;
    slow_guesses = !guided ? 0 : bad - good > 0.5 * width ? slow_guesses + 1 : 0;
  }
  return good;
}

}  // namespace spar::planner::internal
