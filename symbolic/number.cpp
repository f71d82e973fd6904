#include "symbolic/number.hpp"

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <numeric>
#include <string>

namespace spar::symbolic {
namespace {

constexpr double kTwoPow53 = 9007199254740992.0;
constexpr int kMaxExactDecimalDigits = 16;  // longer literals become one-ulp enclosures, so that
                                            // a 17-digit printout of such a real re-parses to it

// The neighbours of a finite double, by stepping its bit pattern (the libm call costs more than
// the rest of a small rational's construction). Positive doubles order like their bit patterns,
// negative ones in reverse; from a zero of either sign the neighbours are ±denorm_min.
double next_up(double x) {
  if (x == 0.0) return std::numeric_limits<double>::denorm_min();
  auto bits = std::bit_cast<std::uint64_t>(x);
  bits = x > 0.0 ? bits + 1 : bits - 1;
  return std::bit_cast<double>(bits);
}
double next_down(double x) { return -next_up(-x); }

double widen_down(double x, int ulps) {
  for (int i = 0; i < ulps; ++i) x = next_down(x);
  return x;
}
double widen_up(double x, int ulps) {
  for (int i = 0; i < ulps; ++i) x = next_up(x);
  return x;
}

bool fits_int64(__int128 v) {
  return v >= std::numeric_limits<std::int64_t>::min() &&
         v <= std::numeric_limits<std::int64_t>::max();
}

__int128 gcd128(__int128 a, __int128 b) {
  if (a < 0) a = -a;
  if (b < 0) b = -b;
  while (b != 0) {
    const __int128 t = a % b;
    a = b;
    b = t;
  }
  return a;
}

void require_finite(double value, const char* what) {
  if (!std::isfinite(value)) {
    throw SymbolicError(std::string(what) + " is not a finite number (NaN or infinity)");
  }
}

}  // namespace

Number Number::integer(std::int64_t value) { return rational(value, 1); }

Number Number::rational(std::int64_t numerator, std::int64_t denominator) {
  if (denominator == 0) throw SymbolicError("division by zero in rational constant");
  return from_rational128(numerator, denominator);
}

Number Number::real(double value) {
  require_finite(value, "constant");
  if (value == std::trunc(value) && std::fabs(value) < kTwoPow53) {
    return integer(static_cast<std::int64_t>(value));
  }
  return from_enclosure(value, value, value);
}

Number Number::from_enclosure(double value, double lower, double upper) {
  require_finite(value, "constant");
  require_finite(lower, "constant enclosure");
  require_finite(upper, "constant enclosure");
  Number n;
  n.kind_ = Kind::kReal;
  n.value_ = value;
  n.lower_ = lower;
  n.upper_ = upper;
  return n;
}

Number Number::from_rational128(__int128 numerator, __int128 denominator) {
  if (denominator < 0) {
    numerator = -numerator;
    denominator = -denominator;
  }
  // Most operands are small: reduce in 64 bits where both parts fit (128-bit division is a
  // library call, several times slower). INT64_MIN is excluded: std::gcd needs |numerator|.
  if (fits_int64(numerator) && fits_int64(denominator) &&
      numerator != std::numeric_limits<std::int64_t>::min()) {
    const auto n = static_cast<std::int64_t>(numerator);
    const auto d = static_cast<std::int64_t>(denominator);
    const std::int64_t g = d == 1 ? 1 : std::gcd(n, d);
    numerator = n / g;
    denominator = d / g;
  } else {
    const __int128 g = gcd128(numerator, denominator);
    if (g > 1) {
      numerator /= g;
      denominator /= g;
    }
  }
  if (fits_int64(numerator) && fits_int64(denominator)) {
    Number n;
    n.numerator_ = static_cast<std::int64_t>(numerator);
    n.denominator_ = static_cast<std::int64_t>(denominator);
    n.set_rational_enclosure();
    return n;
  }
  // Overflow: keep a sound enclosure, the same one parse_decimal gives the 17-digit printout of
  // the value, so an overflowed constant survives print and parse. In long double (>= 64-bit
  // mantissa) the quotient is within 3 * 2^-64 relative of the true value; rounding it to double
  // adds at most half an ulp, so the true value lies strictly between the value's neighbours.
  static_assert(std::numeric_limits<long double>::digits >= 64);
  const double value = static_cast<double>(static_cast<long double>(numerator) /
                                           static_cast<long double>(denominator));
  return from_enclosure(value, next_down(value), next_up(value));
}

void Number::set_rational_enclosure() {
  const double n = static_cast<double>(numerator_);
  const double d = static_cast<double>(denominator_);
  value_ = n / d;
  if (std::fabs(n) <= kTwoPow53 && d <= kTwoPow53) {
    // n and d are exact; the quotient is correctly rounded, and fma tells whether it is exact.
    const bool exact = std::fma(value_, d, -n) == 0.0;
    lower_ = exact ? value_ : next_down(value_);
    upper_ = exact ? value_ : next_up(value_);
  } else {
    lower_ = widen_down(value_, 4);
    upper_ = widen_up(value_, 4);
  }
}

std::optional<Number> Number::parse_decimal(std::string_view text) {
  std::size_t i = 0;
  std::string digits;
  int fraction_digits = 0;
  bool seen_digit = false;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
    digits += text[i++];
    seen_digit = true;
  }
  if (i < text.size() && text[i] == '.') {
    ++i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
      digits += text[i++];
      ++fraction_digits;
      seen_digit = true;
    }
  }
  if (!seen_digit) return std::nullopt;
  long exponent = 0;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    bool negative = false;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
    if (i == text.size() || !std::isdigit(static_cast<unsigned char>(text[i]))) return std::nullopt;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
      exponent = std::min(exponent * 10 + (text[i++] - '0'), 100000L);
    }
    if (negative) exponent = -exponent;
  }
  if (i != text.size()) return std::nullopt;

  // Significant digits: strip leading zeros, then trailing zeros (moving them into the exponent).
  // Trailing zeros written after the point still count as written precision: "2.5000000000000000"
  // (17 digits) is the printout of a real and re-parses as one, while "1e20" or "2.5" are exact.
  const std::size_t first = digits.find_first_not_of('0');
  if (first == std::string::npos) return Number();
  std::string significant = digits.substr(first);
  const bool written_as_real =
      fraction_digits > 0 && static_cast<int>(significant.size()) > kMaxExactDecimalDigits;
  long scale = exponent - fraction_digits;
  while (significant.size() > 1 && significant.back() == '0') {
    significant.pop_back();
    ++scale;
  }
  if (!written_as_real && static_cast<int>(significant.size()) <= kMaxExactDecimalDigits &&
      std::labs(scale) <= 18) {
    __int128 mantissa = std::stoll(significant);
    __int128 power = 1;
    for (long k = 0; k < std::labs(scale); ++k) power *= 10;
    const __int128 numerator = scale >= 0 ? mantissa * power : mantissa;
    const __int128 denominator = scale >= 0 ? 1 : power;
    if (fits_int64(numerator)) return from_rational128(numerator, denominator);
  }
  const std::string literal(text);
  const double value = std::strtod(literal.c_str(), nullptr);
  if (!std::isfinite(value)) {
    throw SymbolicError("numeric literal '" + literal + "' is out of the range of a double");
  }
  // strtod rounds correctly, so one ulp each way encloses the decimal value.
  return from_enclosure(value, next_down(value), next_up(value));
}

int Number::sign() const {
  if (is_rational()) return (numerator_ > 0) - (numerator_ < 0);
  if (lower_ > 0) return 1;
  if (upper_ < 0) return -1;
  return 0;
}

Number operator+(const Number& a, const Number& b) {
  if (a.is_rational() && b.is_rational()) {
    return Number::from_rational128(static_cast<__int128>(a.numerator_) * b.denominator_ +
                                        static_cast<__int128>(b.numerator_) * a.denominator_,
                                    static_cast<__int128>(a.denominator_) * b.denominator_);
  }
  return Number::from_enclosure(a.value_ + b.value_, next_down(a.lower_ + b.lower_),
                                next_up(a.upper_ + b.upper_));
}

Number operator-(const Number& a) {
  if (a.is_rational())
    return Number::from_rational128(-static_cast<__int128>(a.numerator_), a.denominator_);
  return Number::from_enclosure(-a.value_, -a.upper_, -a.lower_);
}

Number operator-(const Number& a, const Number& b) { return a + (-b); }

Number operator*(const Number& a, const Number& b) {
  if (a.is_rational() && b.is_rational()) {
    return Number::from_rational128(static_cast<__int128>(a.numerator_) * b.numerator_,
                                    static_cast<__int128>(a.denominator_) * b.denominator_);
  }
  const double p[4] = {a.lower_ * b.lower_, a.lower_ * b.upper_, a.upper_ * b.lower_,
                       a.upper_ * b.upper_};
  const auto [lo, hi] = std::minmax({p[0], p[1], p[2], p[3]});
  return Number::from_enclosure(a.value_ * b.value_, next_down(lo), next_up(hi));
}

Number operator/(const Number& a, const Number& b) {
  if (b.is_rational()) {
    if (b.numerator_ == 0) throw SymbolicError("division by zero");
    if (a.is_rational()) {
      return Number::from_rational128(static_cast<__int128>(a.numerator_) * b.denominator_,
                                      static_cast<__int128>(a.denominator_) * b.numerator_);
    }
  }
  if (b.lower_ <= 0 && b.upper_ >= 0) {
    throw SymbolicError("division by a constant that may be zero (" + b.to_string() + ")");
  }
  const double q[4] = {a.lower_ / b.lower_, a.lower_ / b.upper_, a.upper_ / b.lower_,
                       a.upper_ / b.upper_};
  const auto [lo, hi] = std::minmax({q[0], q[1], q[2], q[3]});
  return Number::from_enclosure(a.value_ / b.value_, next_down(lo), next_up(hi));
}

Number Number::pow(std::int64_t exponent) const {
  if (exponent < 0) {
    if (is_zero()) throw SymbolicError("0 raised to a negative power (division by zero)");
    return Number::integer(1) / pow(-exponent);
  }
  Number result = Number::integer(1);
  Number base = *this;
  while (exponent > 0) {  // square-and-multiply; every step keeps a sound enclosure
    if (exponent & 1) result = result * base;
    exponent >>= 1;
    if (exponent > 0) base = base * base;
  }
  return result;
}

bool operator==(const Number& a, const Number& b) {
  if (a.kind_ != b.kind_) return false;
  if (a.is_rational()) return a.numerator_ == b.numerator_ && a.denominator_ == b.denominator_;
  return a.value_ == b.value_ && a.lower_ == b.lower_ && a.upper_ == b.upper_;
}

bool operator<(const Number& a, const Number& b) {
  if (a.value_ != b.value_) return a.value_ < b.value_;
  if (a.kind_ != b.kind_) return a.kind_ < b.kind_;
  if (a.is_rational()) {
    return static_cast<__int128>(a.numerator_) * b.denominator_ <
           static_cast<__int128>(b.numerator_) * a.denominator_;
  }
  if (a.lower_ != b.lower_) return a.lower_ < b.lower_;
  return a.upper_ < b.upper_;
}

std::size_t Number::hash() const {
  const std::hash<std::int64_t> hash_int;
  const std::hash<double> hash_double;
  std::size_t h = is_rational() ? hash_int(numerator_) * 31 + hash_int(denominator_)
                                : hash_double(value_) * 31 + hash_double(lower_);
  return h * 2 + static_cast<std::size_t>(kind_);
}

std::string Number::to_string() const {
  if (is_rational()) {
    if (denominator_ == 1) return std::to_string(numerator_);
    // Terminating decimals print exactly as decimals when short: 1/10 -> "0.1".
    std::int64_t d = denominator_;
    int twos = 0, fives = 0;
    while (d % 2 == 0) d /= 2, ++twos;
    while (d % 5 == 0) d /= 5, ++fives;
    const int places = std::max(twos, fives);
    if (d == 1 && places <= 12) {
      // numerator/denominator == numerator * 2^(places-twos) * 5^(places-fives) / 10^places.
      __int128 scaled = static_cast<__int128>(numerator_);
      for (int k = twos; k < places; ++k) scaled *= 2;
      for (int k = fives; k < places; ++k) scaled *= 5;
      const bool negative = scaled < 0;
      std::string digits = std::to_string(static_cast<long long>(negative ? -scaled : scaled));
      if (static_cast<int>(digits.size()) <= places) {
        digits.insert(0, places - digits.size() + 1, '0');
      }
      const std::size_t point = digits.size() - static_cast<std::size_t>(places);
      std::string text(negative ? "-" : "");
      text.append(digits, 0, point).append(1, '.').append(digits, point);
      return text;
    }
    return std::to_string(numerator_) + "/" + std::to_string(denominator_);
  }
  // A real whose nearest double is 0 (an underflowed literal such as 1e-400, enclosed by
  // [-min, +min] subnormal): digits that are all zeros read back as the exact 0, so it prints as
  // another literal below half the smallest subnormal, which reads back as this same real.
  if (value_ == 0) return std::signbit(value_) ? "-1e-400" : "1e-400";
  char buffer[40];
  // 17 significant digits, trailing zeros kept ('#'), so that the text reads back as a real.
  std::snprintf(buffer, sizeof buffer, "%#.17g", value_);
  return buffer;
}

}  // namespace spar::symbolic
