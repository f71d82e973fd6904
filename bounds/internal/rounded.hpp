// Rounded double operations for the interval kernels: a + b and a * b rounded down or up, one ulp
// outward exactly when the double result is not the exact one. The sign of the exact error comes
// from an error-free transformation (two-sum; fma residual), so the FPU rounding mode is never
// changed. Inline, with the four arithmetic operators of Interval (interval.hpp): they run on
// every instruction of every box branch and bound evaluates (a fifth of `spar plan`'s
// instructions on peg_block_on_back), and GCC kept them as calls into interval.cpp; inline they
// save 5-7% of its CPU (bench/RESULTS.md, twenty-second landing).
//
// Rules (r = the double result; "exact" = the real result):
//   - add: the two-sum error (exact - r) decides; from finite operands an infinite r overflowed
//     (inexact toward the infinity); an infinite operand makes r exact.
//   - mul: a zero factor gives exactly 0 (also 0 * inf: an exact zero bound times an infinite
//     bound of another factor); below kTiny the fma residual may itself round (underflow), so the
//     result widens unconditionally; otherwise the fma residual's sign decides.
//
// Example:
//   using namespace spar::bounds::internal;
//   const double lo = add_down(0.1, 0.2), hi = add_up(0.1, 0.2);
//   assert(lo < hi && lo <= 0.3 && 0.3 <= hi);  // 0.1 + 0.2 is inexact: one ulp apart
//   assert(mul_down(0.5, 4.0) == 2.0 && mul_up(0.5, 4.0) == 2.0);  // exact: not widened
#pragma once

#include <cmath>

#include "spar/bounds/internal/ulp.hpp"

namespace spar::bounds::internal {

// Below this magnitude an fma residual may itself round (underflow): widen unconditionally.
inline constexpr double kTiny = 0x1p-960;

// r = a op b in double; `error` = (exact - r) sign.
[[nodiscard]] inline double round_down(double r, double error) {
  return error < 0 ? next_down(r) : r;
}
[[nodiscard]] inline double round_up(double r, double error) { return error > 0 ? next_up(r) : r; }

[[nodiscard]] inline double add_error(double a, double b, double r) {
  if (!std::isfinite(r)) return (std::isfinite(a) && std::isfinite(b)) ? (r > 0 ? -1 : 1) : 0;
  const double bb = r - a;
  return (a - (r - bb)) + (b - bb);
}
[[nodiscard, gnu::always_inline]] inline double add_down(double a, double b) {
  const double r = a + b;
  return round_down(r, add_error(a, b, r));
}
[[nodiscard, gnu::always_inline]] inline double add_up(double a, double b) {
  const double r = a + b;
  return round_up(r, add_error(a, b, r));
}

[[nodiscard, gnu::always_inline]] inline double mul_down(double a, double b) {
  if (a == 0 || b == 0) return 0.0;
  const double r = a * b;
  if (!std::isfinite(r)) return (std::isfinite(a) && std::isfinite(b) && r > 0) ? next_down(r) : r;
  if (std::fabs(r) < kTiny) return next_down(r);
  return round_down(r, std::fma(a, b, -r));
}
[[nodiscard, gnu::always_inline]] inline double mul_up(double a, double b) {
  if (a == 0 || b == 0) return 0.0;
  const double r = a * b;
  if (!std::isfinite(r)) return (std::isfinite(a) && std::isfinite(b) && r < 0) ? next_up(r) : r;
  if (std::fabs(r) < kTiny) return next_up(r);
  return round_up(r, std::fma(a, b, -r));
}

}  // namespace spar::bounds::internal
