// Interval: a closed real interval [lo, hi] of doubles with outward rounding and a domain flag.
//
// Contract: for every operation op and every real x in X (y in Y), op(x, y) lies in op(X, Y)
// whenever op(x, y) is defined. Rounding is outward without touching the FPU mode: + - * / and
// sqrt use error-free transformations (two-sum, fma residuals) and move a bound by one ulp only
// when the double result is not exact; libm functions (sin, exp, ...) are widened by two ulps.
// Periodic functions find their extrema (sin, cos) and poles (tan) over any width; far out
// (|x| >= 1e12) a narrow interval is first moved to its phase in [-pi, pi] (glibc reduces sin
// and cos correctly), so sin(1e15) is enclosed within ~1e-13, not by [-1, 1].
//
// Invariants: lo <= hi, or the interval is empty (lo = +inf, hi = -inf). Bounds may be infinite.
// `possibly_undefined` is set when some point of the arguments is outside an operation's domain
// (log of a non-positive part, sqrt below zero, asin outside [-1, 1], division by an interval
// containing 0, a pole of tan, ...); the result then encloses the operation on the defined part
// (empty when no point is defined) and the flag propagates through every later operation.
// Nothing here throws: hot loops read the flag.
//
// Example:
//   Interval x{-1.0, 2.0};
//   Interval y = sin(x) * x + 1.0;               // encloses every sin(t)*t+1, t in [-1, 2]
//   Interval z = log(x);                         // [-inf, log 2], possibly_undefined = true
//   assert(y.contains(std::sin(0.5) * 0.5 + 1));
//   using Eval = symbolic::TapeEvaluator<Interval>;   // plugs into compiled tapes
#pragma once

#include <algorithm>
#include <limits>

#include "spar/bounds/internal/rounded.hpp"
#include "spar/symbolic/number.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds {

struct Interval {
  double lo{0.0};                  // lower bound; +inf for the empty interval
  double hi{0.0};                  // upper bound; -inf for the empty interval
  bool possibly_undefined{false};  // some point met a domain error on the way here

  constexpr Interval() = default;
  constexpr Interval(double value) : lo(value), hi(value) {}  // NOLINT: a point is an interval
  constexpr Interval(double lower, double upper, bool undefined = false)
      : lo(lower), hi(upper), possibly_undefined(undefined) {}

  [[nodiscard]] static constexpr Interval empty(bool undefined = false) {
    return {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
            undefined};
  }
  [[nodiscard]] static constexpr Interval entire(bool undefined = false) {
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            undefined};
  }
  [[nodiscard]] constexpr bool is_empty() const { return !(lo <= hi); }
  [[nodiscard]] constexpr bool contains(double x) const { return lo <= x && x <= hi; }
  [[nodiscard]] constexpr bool is_bounded() const {
    return lo > -std::numeric_limits<double>::infinity() &&
           hi < std::numeric_limits<double>::infinity();
  }
  // hi - lo rounded up (0 for empty).
  [[nodiscard]] double width() const;
  // A point inside (the midpoint when bounded).
  [[nodiscard]] double mid() const;
};

// The enclosure [lower(), upper()] of an expression constant.
[[nodiscard]] Interval enclose(const symbolic::Number& number);

[[nodiscard]] Interval hull(const Interval& a, const Interval& b);
[[nodiscard]] Interval intersect(const Interval& a, const Interval& b);

// + - * inline (internal/rounded.hpp says why), defined at the end of this header.
inline Interval operator+(const Interval& a, const Interval& b);
inline Interval operator-(const Interval& a, const Interval& b);
inline Interval operator*(const Interval& a, const Interval& b);
Interval operator/(const Interval& a, const Interval& b);
inline Interval operator-(const Interval& a);

[[nodiscard]] Interval square(const Interval& a);
[[nodiscard]] Interval pow_int(const Interval& a, int exponent);
[[nodiscard]] Interval pow(const Interval& base, const Interval& exponent);  // base >= 0 domain
[[nodiscard]] Interval sqrt(const Interval& a);
[[nodiscard]] Interval sin(const Interval& a);
[[nodiscard]] Interval cos(const Interval& a);
[[nodiscard]] Interval tan(const Interval& a);
[[nodiscard]] Interval exp(const Interval& a);
[[nodiscard]] Interval log(const Interval& a);
[[nodiscard]] Interval abs(const Interval& a);
[[nodiscard]] Interval atan(const Interval& a);
[[nodiscard]] Interval asin(const Interval& a);
[[nodiscard]] Interval acos(const Interval& a);
[[nodiscard]] Interval atan2(const Interval& y, const Interval& x);
[[nodiscard]] Interval min(const Interval& a, const Interval& b);
[[nodiscard]] Interval max(const Interval& a, const Interval& b);

[[gnu::always_inline]] inline Interval operator+(const Interval& a, const Interval& b) {
  const bool undefined = a.possibly_undefined || b.possibly_undefined;
  if (a.is_empty() || b.is_empty()) return Interval::empty(undefined);
  // Adding an exact zero is exact (gradient accumulation starts from zero adjoints); + 0.0 keeps
  // what the rounded sum gives a -0 bound (+0).
  if (b.lo == 0 && b.hi == 0) return {a.lo + 0.0, a.hi + 0.0, undefined};
  if (a.lo == 0 && a.hi == 0) return {b.lo + 0.0, b.hi + 0.0, undefined};
  return {internal::add_down(a.lo, b.lo), internal::add_up(a.hi, b.hi), undefined};
}

inline Interval operator-(const Interval& a) { return {-a.hi, -a.lo, a.possibly_undefined}; }

inline Interval operator-(const Interval& a, const Interval& b) { return a + (-b); }

[[gnu::always_inline]] inline Interval operator*(const Interval& a, const Interval& b) {
  using internal::mul_down;
  using internal::mul_up;
  const bool undefined = a.possibly_undefined || b.possibly_undefined;
  if (a.is_empty() || b.is_empty()) return Interval::empty(undefined);
  if (a.is_bounded() && b.is_bounded()) {
    // Finite bounds: the signs say which end-point products are the least and the greatest, and
    // mul_down/mul_up are monotone in the exact product, so this is the four-product formula
    // below, bit for bit, with two or four products instead of eight.
    const bool a_positive = a.lo >= 0, a_negative = a.hi <= 0;
    const bool b_positive = b.lo >= 0, b_negative = b.hi <= 0;
    if (a_positive) {
      if (b_positive) return {mul_down(a.lo, b.lo), mul_up(a.hi, b.hi), undefined};
      if (b_negative) return {mul_down(a.hi, b.lo), mul_up(a.lo, b.hi), undefined};
      return {mul_down(a.hi, b.lo), mul_up(a.hi, b.hi), undefined};
    }
    if (a_negative) {
      if (b_positive) return {mul_down(a.lo, b.hi), mul_up(a.hi, b.lo), undefined};
      if (b_negative) return {mul_down(a.hi, b.hi), mul_up(a.lo, b.lo), undefined};
      return {mul_down(a.lo, b.hi), mul_up(a.lo, b.lo), undefined};
    }
    if (b_positive) return {mul_down(a.lo, b.hi), mul_up(a.hi, b.hi), undefined};
    if (b_negative) return {mul_down(a.hi, b.lo), mul_up(a.lo, b.lo), undefined};
    return {std::min(mul_down(a.lo, b.hi), mul_down(a.hi, b.lo)),
            std::max(mul_up(a.lo, b.lo), mul_up(a.hi, b.hi)), undefined};
  }
  const double lo = std::min(
      {mul_down(a.lo, b.lo), mul_down(a.lo, b.hi), mul_down(a.hi, b.lo), mul_down(a.hi, b.hi)});
  const double hi =
      std::max({mul_up(a.lo, b.lo), mul_up(a.lo, b.hi), mul_up(a.hi, b.lo), mul_up(a.hi, b.hi)});
  return {lo, hi, undefined};
}

}  // namespace spar::bounds

template <>
struct spar::symbolic::TapeDomain<spar::bounds::Interval> {
  using I = spar::bounds::Interval;
  static I constant(const Number& n) { return spar::bounds::enclose(n); }
  static I square(const I& x) { return spar::bounds::square(x); }
  static I pow_int(const I& x, int n) { return spar::bounds::pow_int(x, n); }
  static I pow(const I& x, const I& y) { return spar::bounds::pow(x, y); }
#define SPAR_INTERVAL_UNARY(Name, name, ...) \
  static I name(const I& x) { return spar::bounds::name(x); }
#define SPAR_INTERVAL_BINARY(Name, name, ...) \
  static I name(const I& a, const I& b) { return spar::bounds::name(a, b); }
  SPAR_UNARY_FUNCTIONS(SPAR_INTERVAL_UNARY)
  SPAR_BINARY_FUNCTIONS(SPAR_INTERVAL_BINARY)
#undef SPAR_INTERVAL_UNARY
#undef SPAR_INTERVAL_BINARY
};
