// Outward-rounded interval kernels. Directed rounding comes from the sign of the exact error of
// each double operation (two-sum, fma residuals), so the FPU rounding mode is never changed.
#include "spar/bounds/interval.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "spar/bounds/internal/rounded.hpp"

namespace spar::bounds {
namespace {

using internal::kInf;
using internal::next_down;
using internal::next_up;
// libm results are within one ulp on glibc; two ulps is the documented margin.
double libm_down(double x) { return next_down(next_down(x)); }
double libm_up(double x) { return next_up(next_up(x)); }

using internal::add_down;
using internal::add_up;
using internal::kTiny;
using internal::mul_down;
using internal::mul_up;
using internal::round_down;
using internal::round_up;

// Sign of (a/b - q) = sign(a - q*b) * sign(b).
double div_error(double a, double b, double q) {
  const double residual = std::fma(-q, b, a);
  return b > 0 ? residual : -residual;
}
// Quotients with an infinite operand are limits (exact); inf/inf is unknown (whole line).
double div_down(double a, double b) {
  if (a == 0) return 0.0;
  const double q = a / b;
  if (std::isnan(q)) return -kInf;
  if (std::isinf(a) || std::isinf(b)) return q;
  if (std::isinf(q)) return q > 0 ? next_down(q) : q;
  if (std::fabs(q) < kTiny) return next_down(q);
  return round_down(q, div_error(a, b, q));
}
double div_up(double a, double b) {
  if (a == 0) return 0.0;
  const double q = a / b;
  if (std::isnan(q)) return kInf;
  if (std::isinf(a) || std::isinf(b)) return q;
  if (std::isinf(q)) return q < 0 ? next_up(q) : q;
  if (std::fabs(q) < kTiny) return next_up(q);
  return round_up(q, div_error(a, b, q));
}

Interval make(double lo, double hi, bool undefined) { return Interval{lo, hi, undefined}; }

// A monotone increasing libm function on its domain.
template <class F>
Interval increasing(const Interval& a, F f, bool undefined) {
  return make(libm_down(f(a.lo)), libm_up(f(a.hi)), undefined || a.possibly_undefined);
}

constexpr double kPiLo = 0x1.921fb54442d18p+1;  // the double below pi
constexpr double kPiHi = 0x1.921fb54442d19p+1;  // the double above pi
constexpr double kHalfPiHi = 0x1.921fb54442d19p+0;

// Integers n with lo <= (n + offset) * pi <= hi may exist: conservative range [first, last].
// Returns false when the interval is too wide or too far out to reason about (caller uses the
// whole range).
bool multiples_of_pi(double lo, double hi, double offset, double& first, double& last) {
  if (!(std::fabs(lo) < 1e12 && std::fabs(hi) < 1e12)) return false;
  const double t_lo = lo / std::numbers::pi - offset, t_hi = hi / std::numbers::pi - offset;
  first = std::ceil(t_lo - 1e-12 * (1 + std::fabs(t_lo)));
  last = std::floor(t_hi + 1e-12 * (1 + std::fabs(t_hi)));
  return true;
}

// Far out x / pi tells where x lies in its period only to within multiples_of_pi's allowance,
// 1e-12 (1 + |t|) pi rad (t = x / pi): from |x| = 1e6 on that is more than 1e-6 rad, so a point
// near an extremum would get +-1 for a bound (cos(-999999999994) came out [0.66, 1]). A narrow
// interval there is moved by a multiple of 2 pi to [phase, phase + width], |phase| <= pi:
// glibc's sin and cos reduce every double argument correctly (within the two ulps libm_down/up
// allow), so atan2(sin(lo), cos(lo)) is lo's phase to within about 2e-15; kPhaseError covers that
// with room. The same interval, shifted by a multiple of 2 pi, has the same sin, cos and tan.
constexpr double kFarOut = 1e6;
constexpr double kPhaseError = 1e-13;
bool far_out(const Interval& a) {
  return std::isfinite(a.lo) && std::isfinite(a.hi) &&
         std::max(std::fabs(a.lo), std::fabs(a.hi)) >= kFarOut;
}
Interval reduced(const Interval& a) {
  const double phase = std::atan2(std::sin(a.lo), std::cos(a.lo));
  const double width = add_up(a.hi, -a.lo);  // exact for the narrow intervals reduced
  return make(add_down(phase, -kPhaseError), add_up(add_up(phase, width), kPhaseError),
              a.possibly_undefined);
}

// Shared by sin and cos: f has maxima at (2k + offset)π and minima at (2k + 1 + offset)π.
template <class F>
Interval periodic(const Interval& a, F f, double offset) {
  if (a.is_empty()) return a;
  if (a.hi - a.lo < 6.28 && far_out(a)) return periodic(reduced(a), f, offset);
  double first = 0, last = 0;
  if (!(a.hi - a.lo < 6.28) || !multiples_of_pi(a.lo, a.hi, offset, first, last)) {
    return make(-1, 1, a.possibly_undefined);
  }
  const double f_lo = f(a.lo), f_hi = f(a.hi);
  double lo = std::max(-1.0, libm_down(std::min(f_lo, f_hi)));
  double hi = std::min(1.0, libm_up(std::max(f_lo, f_hi)));
  for (double n = first; n <= last; n += 1) {
    if (std::fmod(n, 2.0) == 0) {
      hi = 1;
    } else {
      lo = -1;
    }
  }
  return make(lo, hi, a.possibly_undefined);
}

}  // namespace

double Interval::width() const { return is_empty() ? 0.0 : add_up(hi, -lo); }

double Interval::mid() const {
  if (is_empty()) return std::numeric_limits<double>::quiet_NaN();
  if (lo == -kInf && hi == kInf) return 0.0;
  if (lo == -kInf) return std::min(hi, -std::numeric_limits<double>::max());
  if (hi == kInf) return std::max(lo, std::numeric_limits<double>::max());
  const double m = 0.5 * lo + 0.5 * hi;
  return std::clamp(m, lo, hi);
}

Interval enclose(const symbolic::Number& number) { return {number.lower(), number.upper()}; }

Interval hull(const Interval& a, const Interval& b) {
  const bool undefined = a.possibly_undefined || b.possibly_undefined;
  if (a.is_empty()) return make(b.lo, b.hi, undefined);
  if (b.is_empty()) return make(a.lo, a.hi, undefined);
  return make(std::min(a.lo, b.lo), std::max(a.hi, b.hi), undefined);
}

Interval intersect(const Interval& a, const Interval& b) {
  const bool undefined = a.possibly_undefined || b.possibly_undefined;
  const double lo = std::max(a.lo, b.lo), hi = std::min(a.hi, b.hi);
  return lo <= hi ? make(lo, hi, undefined) : Interval::empty(undefined);
}

Interval operator/(const Interval& a, const Interval& b) {
  const bool undefined = a.possibly_undefined || b.possibly_undefined;
  if (a.is_empty() || b.is_empty()) return Interval::empty(undefined);
  if (b.lo > 0 || b.hi < 0) {
    const double lo = std::min(
        {div_down(a.lo, b.lo), div_down(a.lo, b.hi), div_down(a.hi, b.lo), div_down(a.hi, b.hi)});
    const double hi =
        std::max({div_up(a.lo, b.lo), div_up(a.lo, b.hi), div_up(a.hi, b.lo), div_up(a.hi, b.hi)});
    return make(lo, hi, undefined);
  }
  // The divisor contains 0: undefined there; enclose the quotient over the rest.
  if (b.lo == 0 && b.hi == 0) return Interval::empty(true);
  if (a.lo == 0 && a.hi == 0) return make(0, 0, true);
  if (a.lo < 0 && a.hi > 0) return Interval::entire(true);
  if (b.lo == 0) {  // b in (0, hi]
    return a.lo >= 0 ? make(div_down(a.lo, b.hi), kInf, true)
                     : make(-kInf, div_up(a.hi, b.hi), true);
  }
  if (b.hi == 0) {  // b in [lo, 0)
    return a.lo >= 0 ? make(-kInf, div_up(a.lo, b.lo), true)
                     : make(div_down(a.hi, b.lo), kInf, true);
  }
  return Interval::entire(true);
}

Interval square(const Interval& a) {
  if (a.is_empty()) return a;
  const double m = std::min(std::fabs(a.lo), std::fabs(a.hi));
  const double big = std::max(std::fabs(a.lo), std::fabs(a.hi));
  const double lo = (a.lo <= 0 && a.hi >= 0) ? 0.0 : std::max(0.0, mul_down(m, m));
  return make(lo, mul_up(big, big), a.possibly_undefined);
}

Interval pow_int(const Interval& a, int exponent) {
  if (a.is_empty()) return a;
  if (exponent == 0) return make(1, 1, a.possibly_undefined);
  if (exponent < 0) {
    const Interval positive = pow_int(a, -exponent);
    return Interval{1.0} / positive;
  }
  if (exponent == 1) return a;
  if (exponent == 2) return square(a);
  // |x|^n by binary powering with directed products (monotone for |x| >= 0, exact when the
  // products are); odd powers of negative numbers are -(|x|^n).
  const auto magnitude_power = [&](double m, bool up) {
    double result = 1.0, base = m;
    for (int k = exponent; k; k >>= 1) {
      if (k & 1) result = up ? mul_up(result, base) : mul_down(result, base);
      if (k > 1) base = up ? mul_up(base, base) : mul_down(base, base);
    }
    return result;
  };
  const auto power_down = [&](double x) {
    return x >= 0 ? magnitude_power(x, false) : -magnitude_power(-x, true);
  };
  const auto power_up = [&](double x) {
    return x >= 0 ? magnitude_power(x, true) : -magnitude_power(-x, false);
  };
  if (exponent % 2 == 1) {
    return make(power_down(a.lo), power_up(a.hi), a.possibly_undefined);
  }
  const double m = (a.lo <= 0 && a.hi >= 0) ? 0.0 : std::min(std::fabs(a.lo), std::fabs(a.hi));
  const double big = std::max(std::fabs(a.lo), std::fabs(a.hi));
  return make(power_down(m), power_up(big), a.possibly_undefined);
}

Interval pow(const Interval& base, const Interval& exponent) {
  // x^y = exp(y log x) for x > 0; 0^y = 0 for y > 0; undefined for x < 0 (non-constant y).
  const bool undefined = base.possibly_undefined || exponent.possibly_undefined || base.lo < 0 ||
                         (base.lo <= 0 && exponent.lo <= 0);
  const Interval x = intersect(base, Interval{0.0, kInf});
  if (x.is_empty() || exponent.is_empty()) return Interval::empty(true);
  Interval result = Interval::empty();
  if (x.hi > 0) {
    const Interval positive{std::max(x.lo, std::numeric_limits<double>::denorm_min()), x.hi};
    result = exp(exponent * log(positive));
    if (x.lo == 0) result = hull(result, Interval{0.0, exponent.lo <= 0 ? kInf : 0.0});
  } else if (exponent.hi > 0) {
    result = Interval{0.0};
  }
  result.possibly_undefined = undefined;
  return result;
}

Interval sqrt(const Interval& a) {
  if (a.is_empty()) return a;
  const bool undefined = a.possibly_undefined || a.lo < 0;
  if (a.hi < 0) return Interval::empty(true);
  const auto root = [](double x, bool up) {
    if (x <= 0) return 0.0;
    if (std::isinf(x)) return x;
    const double r = std::sqrt(x);
    const double error = std::fma(-r, r, x);  // sign of (sqrt(x) - r)
    return up ? round_up(r, error) : std::max(0.0, round_down(r, error));
  };
  return make(root(std::max(a.lo, 0.0), false), root(a.hi, true), undefined);
}

Interval cos(const Interval& a) {
  return periodic(
      a, [](double x) { return std::cos(x); }, 0.0);
}
Interval sin(const Interval& a) {
  return periodic(
      a, [](double x) { return std::sin(x); }, 0.5);
}

Interval tan(const Interval& a) {
  if (a.is_empty()) return a;
  if (a.hi - a.lo < 3.14 && far_out(a)) return tan(reduced(a));
  double first = 0, last = 0;
  // Poles at (n + 1/2)π.
  if (!(a.hi - a.lo < 3.14) || !multiples_of_pi(a.lo, a.hi, 0.5, first, last) || first <= last) {
    return Interval::entire(true);
  }
  return increasing(
      a, [](double x) { return std::tan(x); }, false);
}

Interval exp(const Interval& a) {
  if (a.is_empty()) return a;
  Interval r = increasing(
      a, [](double x) { return std::exp(x); }, false);
  r.lo = std::max(r.lo, 0.0);
  if (a.lo == -kInf) r.lo = 0;
  return r;
}

Interval log(const Interval& a) {
  if (a.is_empty()) return a;
  const bool undefined = a.possibly_undefined || a.lo <= 0;
  if (a.hi <= 0) return Interval::empty(true);
  const double lo = a.lo <= 0 ? -kInf : libm_down(std::log(a.lo));
  return make(lo, libm_up(std::log(a.hi)), undefined);
}

Interval abs(const Interval& a) {
  if (a.is_empty()) return a;
  if (a.lo >= 0) return a;
  if (a.hi <= 0) return -a;
  return make(0, std::max(-a.lo, a.hi), a.possibly_undefined);
}

Interval atan(const Interval& a) {
  if (a.is_empty()) return a;
  Interval r = increasing(
      a, [](double x) { return std::atan(x); }, false);
  r.lo = std::max(r.lo, -kHalfPiHi);
  r.hi = std::min(r.hi, kHalfPiHi);
  return r;
}

Interval asin(const Interval& a) {
  const Interval d = intersect(a, Interval{-1.0, 1.0});
  const bool undefined = a.possibly_undefined || a.lo < -1 || a.hi > 1;
  if (d.is_empty()) return Interval::empty(true);
  Interval r = increasing(
      d, [](double x) { return std::asin(x); }, undefined);
  r.lo = std::max(r.lo, -kHalfPiHi);
  r.hi = std::min(r.hi, kHalfPiHi);
  return r;
}

Interval acos(const Interval& a) {
  const Interval d = intersect(a, Interval{-1.0, 1.0});
  const bool undefined = a.possibly_undefined || a.lo < -1 || a.hi > 1;
  if (d.is_empty()) return Interval::empty(true);
  return make(std::max(0.0, libm_down(std::acos(d.hi))), std::min(kPiHi, libm_up(std::acos(d.lo))),
              undefined);
}

Interval atan2(const Interval& y, const Interval& x) {
  const bool inherited = y.possibly_undefined || x.possibly_undefined;
  if (y.is_empty() || x.is_empty()) return Interval::empty(inherited);
  const bool has_origin = y.contains(0) && x.contains(0);
  if (y.lo == 0 && y.hi == 0 && x.lo == 0 && x.hi == 0) return Interval::empty(true);
  // Off the branch cut (the non-positive x axis) the extremes over a box sit at its corners.
  const double y_lo = y.lo + 0.0;  // +0 so that atan2(0, negative) = +pi
  if (!has_origin && (y_lo >= 0 || y.hi < 0 || x.lo > 0)) {
    double lo = kInf, hi = -kInf;
    for (double cy : {y_lo, y.hi}) {
      for (double cx : {x.lo, x.hi}) {
        const double v = std::atan2(cy, cx);
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
    return make(std::max(-kPiHi, libm_down(lo)), std::min(kPiHi, libm_up(hi)), inherited);
  }
  return make(-kPiHi, kPiHi, inherited || has_origin);
}

Interval min(const Interval& a, const Interval& b) {
  const bool undefined = a.possibly_undefined || b.possibly_undefined;
  if (a.is_empty() || b.is_empty()) return Interval::empty(undefined);
  return make(std::min(a.lo, b.lo), std::min(a.hi, b.hi), undefined);
}

Interval max(const Interval& a, const Interval& b) {
  const bool undefined = a.possibly_undefined || b.possibly_undefined;
  if (a.is_empty() || b.is_empty()) return Interval::empty(undefined);
  return make(std::max(a.lo, b.lo), std::max(a.hi, b.hi), undefined);
}

}  // namespace spar::bounds
