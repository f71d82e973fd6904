// Interval kernels: special ranges (periods, poles, domains, division by zero) and RapidCheck
// soundness against MPFI at 256 bits as the oracle for true values at points of the interval.
#include "bounds/interval.hpp"

#include <gtest/gtest.h>
#include <mpfi.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <string>

namespace spar::bounds {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Interval, SinOverPeriodContainsMinusOneAndOne) {
  const Interval r = sin(Interval{0.0, 7.0});
  EXPECT_EQ(r.lo, -1.0);
  EXPECT_EQ(r.hi, 1.0);
}

TEST(Interval, SinNarrowAroundMaximumReachesOne) {
  const Interval r = sin(Interval{kPi / 2 - 1e-3, kPi / 2 + 1e-3});
  EXPECT_EQ(r.hi, 1.0);
  EXPECT_GT(r.lo, 0.999);
}

TEST(Interval, CosOnMonotonePieceIsTight) {
  const Interval r = cos(Interval{0.5, 1.0});
  EXPECT_LE(r.lo, std::cos(1.0));
  EXPECT_GE(r.hi, std::cos(0.5));
  EXPECT_LT(r.hi - r.lo, std::cos(0.5) - std::cos(1.0) + 1e-15);
}

TEST(Interval, CosAtLargeArgumentFindsMinimum) {
  // 1001π lies inside; cos there is -1.
  const double centre = 1001 * kPi;
  EXPECT_EQ(cos(Interval{centre - 1e-6, centre + 1e-6}).lo, -1.0);
}

TEST(Interval, TanAcrossPoleIsEntireAndFlagged) {
  const Interval r = tan(Interval{1.5, 1.6});
  EXPECT_TRUE(std::isinf(r.lo) && std::isinf(r.hi));
  EXPECT_TRUE(r.possibly_undefined);
  const Interval ok = tan(Interval{-1.0, 1.0});
  EXPECT_FALSE(ok.possibly_undefined);
  EXPECT_LE(ok.lo, std::tan(-1.0));
}

TEST(Interval, LogOfNegativePartIsFlaggedNotClamped) {
  const Interval r = log(Interval{-1.0, 2.0});
  EXPECT_TRUE(r.possibly_undefined);
  EXPECT_EQ(r.lo, -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(log(Interval{-2.0, -1.0}).is_empty());
  EXPECT_TRUE(log(Interval{-2.0, -1.0}).possibly_undefined);
}

TEST(Interval, SqrtAndAsinDomainsAreFlagged) {
  EXPECT_TRUE(sqrt(Interval{-1.0, 4.0}).possibly_undefined);
  EXPECT_EQ(sqrt(Interval{-1.0, 4.0}).hi, 2.0);  // sqrt(4) is exact: no widening
  EXPECT_TRUE(asin(Interval{0.5, 2.0}).possibly_undefined);
  EXPECT_TRUE(acos(Interval{2.0, 3.0}).is_empty());
  EXPECT_FALSE(asin(Interval{-1.0, 1.0}).possibly_undefined);
}

TEST(Interval, DivisionByIntervalContainingZero) {
  const Interval r = Interval{1.0, 2.0} / Interval{0.0, 4.0};
  EXPECT_EQ(r.lo, 0.25);
  EXPECT_TRUE(std::isinf(r.hi));
  EXPECT_TRUE(r.possibly_undefined);
  EXPECT_TRUE((Interval{1.0} / Interval{-1.0, 1.0}).possibly_undefined);
  EXPECT_TRUE((Interval{1.0} / Interval{0.0}).is_empty());
}

TEST(Interval, ExactOperationsAreNotWidened) {
  const Interval r = Interval{1.0, 2.0} * Interval{3.0, 4.0} + Interval{0.5};
  EXPECT_EQ(r.lo, 3.5);
  EXPECT_EQ(r.hi, 8.5);
  const Interval third = Interval{1.0} / Interval{3.0};
  EXPECT_LT(third.lo, third.hi);  // 1/3 is not a double: one ulp apart
  EXPECT_EQ(std::nextafter(third.lo, 1.0), third.hi);
}

TEST(Interval, PowIntOfNegativeBase) {
  const Interval cube = pow_int(Interval{-2.0, 1.0}, 3);
  EXPECT_LE(cube.lo, -8.0);
  EXPECT_GE(cube.hi, 1.0);
  const Interval even = pow_int(Interval{-2.0, 1.0}, 4);
  EXPECT_EQ(even.lo, 0.0);
  EXPECT_GE(even.hi, 16.0);
  EXPECT_TRUE(pow_int(Interval{-1.0, 1.0}, -2).possibly_undefined);
}

TEST(Interval, Atan2BranchCutGivesFullCircle) {
  const Interval r = atan2(Interval{-1.0, 1.0}, Interval{-2.0, -1.0});
  EXPECT_LE(r.lo, -3.14159);
  EXPECT_GE(r.hi, 3.14159);
  const Interval right = atan2(Interval{-1.0, 1.0}, Interval{1.0, 2.0});
  EXPECT_LE(right.lo, -kPi / 4);
  EXPECT_GE(right.hi, kPi / 4);
  EXPECT_LT(right.hi, 0.8);
}

TEST(Interval, EmptyPropagates) {
  const Interval e = Interval::empty();
  EXPECT_TRUE((e + Interval{1.0}).is_empty());
  EXPECT_TRUE(sin(e).is_empty());
}

// ---- MPFI oracle -------------------------------------------------------------------------

struct Mpfi {
  mpfi_t value;
  Mpfi() { mpfi_init2(value, 256); }
  ~Mpfi() { mpfi_clear(value); }
};

using MpfiUnary = int (*)(mpfi_ptr, mpfi_srcptr);

struct Kernel {
  const char* name;
  std::function<Interval(const Interval&)> ours;
  MpfiUnary oracle;
  double domain_lo, domain_hi;  // points outside are skipped
};

const std::vector<Kernel>& kernels() {
  static const std::vector<Kernel> all = {
      {"sin", [](const Interval& x) { return sin(x); }, mpfi_sin, -1e300, 1e300},
      {"cos", [](const Interval& x) { return cos(x); }, mpfi_cos, -1e300, 1e300},
      {"tan", [](const Interval& x) { return tan(x); }, mpfi_tan, -1e300, 1e300},
      {"exp", [](const Interval& x) { return exp(x); }, mpfi_exp, -700, 700},
      {"log", [](const Interval& x) { return log(x); }, mpfi_log, 1e-300, 1e300},
      {"sqrt", [](const Interval& x) { return sqrt(x); }, mpfi_sqrt, 0, 1e300},
      {"atan", [](const Interval& x) { return atan(x); }, mpfi_atan, -1e300, 1e300},
      {"asin", [](const Interval& x) { return asin(x); }, mpfi_asin, -1, 1},
      {"acos", [](const Interval& x) { return acos(x); }, mpfi_acos, -1, 1},
      {"abs", [](const Interval& x) { return abs(x); }, mpfi_abs, -1e300, 1e300},
      {"square", [](const Interval& x) { return square(x); }, mpfi_sqr, -1e150, 1e150},
      {"cube", [](const Interval& x) { return pow_int(x, 3); },
       [](mpfi_ptr r, mpfi_srcptr x) {
         mpfi_t t;
         mpfi_init2(t, 256);
         mpfi_sqr(t, x);
         const int c = mpfi_mul(r, t, x);
         mpfi_clear(t);
         return c;
       },
       -1e100, 1e100},
      {"inverse", [](const Interval& x) { return Interval{1.0} / x; }, mpfi_inv, -1e300, 1e300},
  };
  return all;
}

// A random interval [centre, centre + width], width from 1e-9 to 1e3, and a point inside.
struct Sample {
  Interval x;
  double point;
};
Sample random_sample() {
  const double centre =
      *rc::gen::map(rc::gen::inRange(-2000000, 2000000), [](int v) { return v / 1000.0; });
  const double exponent =
      *rc::gen::map(rc::gen::inRange(-900, 300), [](int v) { return v / 100.0; });
  const double width = std::pow(10.0, exponent);
  const double fraction =
      *rc::gen::map(rc::gen::inRange(0, 1001), [](int v) { return v / 1000.0; });
  const Interval x{centre, centre + width};
  return {x, std::min(x.hi, centre + fraction * width)};
}

// Property: the true f(t) (a 256-bit MPFI enclosure of it) lies inside our f(X) for t in X.
RC_GTEST_PROP(Interval, EveryKernelContainsTrueValuesAtPoints, ()) {
  const Sample s = random_sample();
  for (const Kernel& k : kernels()) {
    if (s.point < k.domain_lo || s.point > k.domain_hi) continue;
    if (std::string(k.name) == "inverse" && s.point == 0) continue;
    const Interval ours = k.ours(s.x);
    Mpfi point, image;
    mpfi_set_d(point.value, s.point);
    k.oracle(image.value, point.value);
    RC_ASSERT(mpfr_cmp_d(&image.value->left, ours.lo) >= 0);
    RC_ASSERT(mpfr_cmp_d(&image.value->right, ours.hi) <= 0);
  }
}

// Tightness: on intervals inside a monotone piece, our width is within a few ulps of MPFI's.
TEST(Interval, WidthsMatchMpfiOnMonotonePieces) {
  for (const Kernel& k : kernels()) {
    const std::string name = k.name;
    if (name == "tan" || name == "inverse") continue;
    const Interval x{0.125, 0.75};
    Mpfi in, out;
    mpfi_interv_d(in.value, x.lo, x.hi);
    k.oracle(out.value, in.value);
    const double mpfi_width =
        mpfr_get_d(&out.value->right, MPFR_RNDU) - mpfr_get_d(&out.value->left, MPFR_RNDD);
    const Interval ours = k.ours(x);
    EXPECT_LE(ours.hi - ours.lo, mpfi_width + 1e-14) << name;
  }
}

}  // namespace
}  // namespace spar::bounds
