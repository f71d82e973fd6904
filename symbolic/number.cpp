#include "spar/symbolic/number.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <stdexcept>
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
  // INT64_MIN is left out so that negation stays exact (and "-9223372036854775808" reads back).
  if (fits_int64(numerator) && fits_int64(denominator) &&
      numerator != std::numeric_limits<std::int64_t>::min()) {
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
  if (exact_in_double(numerator_) && exact_in_double(denominator_)) {
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
  bool seen_digit = false, has_point = false;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
    digits += text[i++];
    seen_digit = true;
  }
  if (i < text.size() && text[i] == '.') {
    ++i;
    has_point = true;
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
  // (17 digits) is the printout of a real and re-parses as one, as does "31664425652737800." (a
  // point and 17 digits), while "1e20" or "2.5" are exact.
  const std::size_t first = digits.find_first_not_of('0');
  if (first == std::string::npos) return Number();
  std::string significant = digits.substr(first);
  const bool written_as_real =
      has_point && static_cast<int>(significant.size()) > kMaxExactDecimalDigits;
  long scale = exponent - fraction_digits;
  while (significant.size() > 1 && significant.back() == '0') {
    significant.pop_back();
    ++scale;
  }
  // Without a point, up to 19 digits (any int64: the printout of a rational) are exact too.
  const int max_digits = has_point ? kMaxExactDecimalDigits : 19;
  if (!written_as_real && static_cast<int>(significant.size()) <= max_digits &&
      std::labs(scale) <= 18) {
    __int128 mantissa = 0;
    for (const char digit : significant) mantissa = mantissa * 10 + (digit - '0');
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
  if (a.is_zero()) return b;
  if (b.is_zero()) return a;
  if (a.is_rational() && b.is_rational()) {
    return Number::from_rational128(static_cast<__int128>(a.numerator_) * b.denominator_ +
                                        static_cast<__int128>(b.numerator_) * a.denominator_,
                                    static_cast<__int128>(a.denominator_) * b.denominator_);
  }
  return Number::from_enclosure(a.value_ + b.value_, next_down(a.lower_ + b.lower_),
                                next_up(a.upper_ + b.upper_));
}

Number operator-(const Number& a) {
  if (a.is_rational() && Number::exact_in_double(a.numerator_) &&
      Number::exact_in_double(a.denominator_)) {
    // Still reduced, and its enclosure is set_rational_enclosure's mirrored: -n/d rounds to
    // -(n/d), exact exactly when n/d is, and next_down(-v) = -next_up(v).
    Number negated = a;
    negated.numerator_ = -a.numerator_;
    negated.value_ = -a.value_;
    negated.lower_ = -a.upper_;
    negated.upper_ = -a.lower_;
    return negated;
  }
  if (a.is_rational())
    return Number::from_rational128(-static_cast<__int128>(a.numerator_), a.denominator_);
  return Number::from_enclosure(-a.value_, -a.upper_, -a.lower_);
}

Number operator-(const Number& a, const Number& b) { return a + (-b); }

Number operator*(const Number& a, const Number& b) {
  if (a.is_zero() || b.is_zero()) return Number();
  if (a.is_one()) return b;
  if (b.is_one()) return a;
  if (a.is_minus_one()) return -b;
  if (b.is_minus_one()) return -a;
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
  if (is_rational()) return rational_power(exponent);
  if (exponent < 0) {
    if (sign() == 0) throw SymbolicError("0 raised to a negative power (division by zero)");
    if (exponent == std::numeric_limits<std::int64_t>::min()) {
      throw SymbolicError("exponent out of range");
    }
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

namespace {

// A positive number (high + low)·2^exponent with high in [1/2, 1) and |low| <= ulp(high)/2: a
// pair of long doubles carries ~128 significant bits, and the exponent cannot overflow, so huge
// powers keep their leading digits. `error` bounds the relative error of the represented value.
struct Scaled {
  long double high = 0.5L;
  long double low = 0.0L;
  __int128 exponent = 1;
  long double error = 0.0L;

  explicit Scaled(std::uint64_t magnitude = 1) {
    int shift = 0;
    high = std::frexp(static_cast<long double>(magnitude), &shift);  // exact: 64 bits
    exponent = shift;
  }

  // (h1 + l1)(h2 + l2) = h1·h2 + (h1·l2 + l1·h2 + l1·l2): h1·h2 exactly as p + e (fma), the cross
  // terms rounded (their relative weight is 2^-63, so three roundings cost < 2^-125), l1·l2
  // (< 2^-128 relative) dropped, then p + cross renormalised exactly (|p| >= |cross|). Each
  // product adds less than 2^-122 to the relative error.
  void times(const Scaled& other) {
    const long double p = high * other.high;
    const long double e = std::fma(high, other.high, -p);
    const long double cross = e + (high * other.low + low * other.high);
    const long double sum = p + cross;
    const long double tail = cross - (sum - p);
    int shift = 0;
    high = std::frexp(sum, &shift);
    low = std::ldexp(tail, -shift);
    exponent += other.exponent + shift;
    error = error + other.error + error * other.error + 0x1p-122L;
  }
};

// magnitude^n for n >= 0 by square-and-multiply.
Scaled scaled_power(std::uint64_t magnitude, std::uint64_t n) {
  Scaled base(magnitude);
  Scaled result;
  while (n > 0) {
    if ((n & 1) != 0) result.times(base);
    n >>= 1;
    if (n > 0) base.times(Scaled(base));
  }
  return result;
}

std::uint64_t magnitude_of(std::int64_t v) {
  return v < 0 ? std::uint64_t{0} - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v);
}

// Exact a^n for a 64-bit a and n >= 0, or nullopt if it overflows.
std::optional<std::int64_t> exact_power(std::int64_t a, std::uint64_t n) {
  std::int64_t result = 1;
  while (n > 0) {
    if ((n & 1) != 0 && __builtin_mul_overflow(result, a, &result)) return std::nullopt;
    n >>= 1;
    // a^2 overflowing with bits of n left: the result (a multiple of a^2) overflows too.
    if (n > 0 && __builtin_mul_overflow(a, a, &a)) return std::nullopt;
  }
  return result;
}

}  // namespace

Number Number::rational_power(std::int64_t exponent) const {
  if (is_zero()) {
    if (exponent < 0) throw SymbolicError("0 raised to a negative power (division by zero)");
    return exponent == 0 ? Number::integer(1) : Number();
  }
  // Exact first: in lowest terms, p^n / q^n is too.
  const bool inverse = exponent < 0;
  const std::uint64_t n = magnitude_of(exponent);
  const auto p = exact_power(numerator_, n);
  const auto q = exact_power(denominator_, n);
  if (p && q) return inverse ? Number::rational(*q, *p) : Number::rational(*p, *q);

  // Overflow: p^n / q^n in double-long-double, then one rounding to double. The quotient is
  // within relative error E of the true value; when E < 2^-55 (a quarter of the double spacing
  // below the value; E < 2^-57 for every 64-bit n, checked) rounding to the nearest double adds
  // at most half a spacing, so the true value lies strictly between the neighbours of the
  // result.
  const bool negative = numerator_ < 0 && (n & 1) != 0;
  const Scaled top = scaled_power(magnitude_of(numerator_), n);
  const Scaled bottom = scaled_power(static_cast<std::uint64_t>(denominator_), n);
  const Scaled& numerator = inverse ? bottom : top;
  const Scaled& denominator = inverse ? top : bottom;
  // quotient = n / d: q1 rounded, its residual exact by fma, then the low parts.
  const long double q1 = numerator.high / denominator.high;  // in (1/2, 2)
  const long double residual =
      std::fma(-q1, denominator.high, numerator.high) + (numerator.low - q1 * denominator.low);
  const long double quotient = q1 + residual / denominator.high;
  const long double error =
      numerator.error + denominator.error + 2 * numerator.error * denominator.error + 0x1p-63L;
  const __int128 binary_exponent = numerator.exponent - denominator.exponent;
  const double sign = negative ? -1.0 : 1.0;
  const auto out_of_range = [&] {
    return SymbolicError("constant out of the range of a double (about 2^" +
                         std::to_string(static_cast<long long>(binary_exponent)) + ")");
  };
  if (binary_exponent > std::numeric_limits<double>::max_exponent) throw out_of_range();
  if (binary_exponent < std::numeric_limits<double>::min_exponent - 60) {  // below every subnormal
    return from_enclosure(sign * 0.0, -std::numeric_limits<double>::denorm_min(),
                          std::numeric_limits<double>::denorm_min());
  }
  const long double scaled = std::ldexp(quotient, static_cast<int>(binary_exponent));  // exact
  const double value = sign * static_cast<double>(scaled);
  if (!std::isfinite(value) || !std::isfinite(next_up(std::fabs(value)))) throw out_of_range();
  if (!(error < 0x1p-55L)) throw std::logic_error("Number::pow: error bound above 2^-55");
  return from_enclosure(value, next_down(value), next_up(value));
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
  // The words == compares (a real's value and lower bound suffice), both zeros alike, mixed
  // multiplicatively (std::hash<double> hashed the bytes: 1% of a phase 2 analysis).
  const auto word = [](double x) { return std::bit_cast<std::uint64_t>(x == 0.0 ? 0.0 : x); };
  const std::uint64_t a = is_rational() ? static_cast<std::uint64_t>(numerator_) : word(value_);
  const std::uint64_t b = is_rational() ? static_cast<std::uint64_t>(denominator_) : word(lower_);
  std::uint64_t h = (a * 0x9E3779B97F4A7C15ull) ^ (b * 0xBF58476D1CE4E5B9ull);
  h ^= h >> 31;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 29;
  // The kind enters the mix, not a low bit: open-addressing tables take the low bits as the slot.
  return h ^ (static_cast<std::uint64_t>(kind_) * 0xD6E8FEB86659FD93ull);
}

std::string Number::to_string() const {
  if (is_rational()) {
    if (denominator_ == 1) return std::to_string(numerator_);
    const std::string fraction = std::to_string(numerator_) + "/" + std::to_string(denominator_);
    // Terminating decimals print exactly as decimals when short: 1/10 -> "0.1".
    std::int64_t d = denominator_;
    int twos = 0, fives = 0;
    while (d % 2 == 0) d /= 2, ++twos;
    while (d % 5 == 0) d /= 5, ++fives;
    const int places = std::max(twos, fives);
    // At most 16 significant digits: a longer decimal with a point reads back as a real.
    if (d == 1 && places <= 12) {
      // numerator/denominator == numerator * 2^(places-twos) * 5^(places-fives) / 10^places.
      __int128 scaled = static_cast<__int128>(numerator_);
      for (int k = twos; k < places; ++k) scaled *= 2;
      for (int k = fives; k < places; ++k) scaled *= 5;
      const bool negative = scaled < 0;
      const __int128 magnitude = negative ? -scaled : scaled;
      // Past 64 bits the digits are too many anyway (and would not survive the conversion).
      if (!fits_int64(magnitude)) return fraction;
      std::string digits = std::to_string(static_cast<std::int64_t>(magnitude));
      if (static_cast<int>(digits.size()) > kMaxExactDecimalDigits) return fraction;
      if (static_cast<int>(digits.size()) <= places) {
        digits.insert(0, places - digits.size() + 1, '0');
      }
      const std::size_t point = digits.size() - static_cast<std::size_t>(places);
      std::string text(negative ? "-" : "");
      text.append(digits, 0, point).append(1, '.').append(digits, point);
      return text;
    }
    return fraction;
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
