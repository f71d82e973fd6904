// Number: the constants of spar's expressions.
//
// A Number is either
//   * an exact rational `numerator / denominator` (64-bit, denominator > 0, lowest terms): every
//     constant that came from an integer or a short decimal literal ("0.1" is exactly 1/10), and
//     every sum, product or integer power of such constants that does not overflow; or
//   * a real: a double `value` together with a guaranteed enclosure `[lower, upper]` of the true
//     quantity. A double handed in by a caller (measured data) is exact: lower = value = upper.
//     A decimal literal written with more than 16 significant digits (zeros after the point
//     count), and a rational result that overflows 64 bits, become the nearest double enclosed by
//     its two neighbours; any arithmetic on reals widens the enclosure outward by one ulp per
//     rounded operation, so the enclosure stays sound.
// NaN and infinities are never Numbers: constructing one throws SymbolicError.
//
// The bounds engine turns a Number into an interval with `lower()`/`upper()`, which are outward
// rounded for rationals that are not exactly representable (1/10, 1/3), so constants are enclosed,
// never rounded.
//
// Example:
//   Number tenth = Number::rational(1, 10);            // exact
//   Number sum = tenth + tenth + tenth;                  // exactly 3/10
//   assert(sum == Number::rational(3, 10));
//   Number measured = Number::real(0.254);               // the double itself, exactly
//   double lo = sum.lower(), hi = sum.upper();           // lo < 0.3 < hi: both enclose 3/10
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "spar/symbolic/error.hpp"

namespace spar::symbolic {

class Number {
 public:
  // Zero.
  constexpr Number() = default;

  [[nodiscard]] static Number integer(std::int64_t value);
  [[nodiscard]] static const Number& one();  // integer(1), built once
  // Throws SymbolicError if denominator == 0.
  [[nodiscard]] static Number rational(std::int64_t numerator, std::int64_t denominator);
  // An exact double (measured data). Integers of magnitude below 2^53 become exact rationals, so
  // 2.0 and 2 are the same constant. Throws SymbolicError for NaN or infinity.
  [[nodiscard]] static Number real(double value);
  // Parses a decimal literal such as "12", "0.25", "4.27e-05". Returns an exact rational when it
  // fits in 64 bits and has at most 16 significant digits (any number of digits up to 19 without
  // a decimal point: every int64 reads back exactly), else a one-ulp enclosure of the
  // nearest double. nullopt if not a literal.
  [[nodiscard]] static std::optional<Number> parse_decimal(std::string_view text);

  [[nodiscard]] bool is_rational() const { return kind_ == Kind::kRational; }
  [[nodiscard]] bool is_zero() const { return is_rational() && numerator_ == 0; }
  [[nodiscard]] bool is_one() const {
    return is_rational() && numerator_ == 1 && denominator_ == 1;
  }
  [[nodiscard]] bool is_minus_one() const {
    return is_rational() && numerator_ == -1 && denominator_ == 1;
  }
  [[nodiscard]] bool is_integer() const { return is_rational() && denominator_ == 1; }
  // Sign of the true value: -1, 0, +1, or 0 for a real enclosure that straddles zero.
  [[nodiscard]] int sign() const;
  [[nodiscard]] bool is_negative() const { return sign() < 0; }

  // Only meaningful when is_rational().
  [[nodiscard]] std::int64_t numerator() const { return numerator_; }
  [[nodiscard]] std::int64_t denominator() const { return denominator_; }

  // Nearest double to the value.
  [[nodiscard]] double value() const { return value_; }
  // A double interval guaranteed to contain the true value.
  [[nodiscard]] double lower() const { return lower_; }
  [[nodiscard]] double upper() const { return upper_; }

  // Exact rationals combine exactly (a result that overflows 64 bits becomes a one-ulp real, see
  // above); a real operand widens the enclosure by one ulp, except with an exact 0 addend or an
  // exact 0 or +-1 factor, which are exact (0·a is the exact 0).
  friend Number operator+(const Number& a, const Number& b);
  friend Number operator-(const Number& a, const Number& b);
  friend Number operator*(const Number& a, const Number& b);
  // Throws SymbolicError on division by an exact zero or by a real enclosure containing zero.
  friend Number operator/(const Number& a, const Number& b);
  friend Number operator-(const Number& a);
  // a^n for an integer n; throws SymbolicError for 0^negative. For a rational base: the exact
  // rational when it fits 64 bits, else the double v within one ulp of the true value enclosed
  // by v's two neighbours (the form parse_decimal reads back from v's printout; "1e-400"'s below
  // every subnormal), however large n is; a value beyond the double range throws.
  [[nodiscard]] Number pow(std::int64_t exponent) const;

  // Structural equality: same kind and same representation. A rational never equals a real
  // (Number::real turns integers into rationals, so 2.0 == 2, but 0.5 stays a real).
  friend bool operator==(const Number& a, const Number& b);
  // Total order used to sort: by value, then kind, then bits. Consistent with ==.
  friend bool operator<(const Number& a, const Number& b);
  [[nodiscard]] std::size_t hash() const;

  // "3", "-1/2", "0.1" (rationals whose denominator is 2^a 5^b print as exact decimals when short),
  // reals with 17 significant digits, trailing zeros kept (a real that rounds to 0, such as the
  // literal 1e-400, prints as "1e-400"). parse_decimal reads every form back; a
  // real read back is the one-ulp enclosure of its value (identical for parsed or overflowed
  // reals).
  [[nodiscard]] std::string to_string() const;

 private:
  enum class Kind : std::uint8_t { kRational, kReal };
  static Number from_rational128(__int128 numerator, __int128 denominator);
  // Whether an integer converts to double exactly by its magnitude alone: |v| <= 2^53. (Compared
  // as integers: 2^53 + 1 converts to 2^53, which a test on the converted double would pass.)
  static constexpr bool exact_in_double(std::int64_t v) {
    constexpr std::int64_t kLimit = std::int64_t{1} << 53;
    return v >= -kLimit && v <= kLimit;
  }
  static Number from_enclosure(double value, double lower, double upper);
  void set_rational_enclosure();
  [[nodiscard]] Number rational_power(std::int64_t exponent) const;

  Kind kind_{Kind::kRational};
  std::int64_t numerator_{0};    // rational only; sign carried here; never INT64_MIN
  std::int64_t denominator_{1};  // rational only; > 0, gcd(numerator, denominator) == 1
  double value_{0.0};            // nearest double to the value (rational: numerator/denominator)
  double lower_{0.0};            // lower_ <= true value <= upper_, always
  double upper_{0.0};
};

// Exact without a reduction: a denominator of 1 needs no gcd, and every integer of magnitude up
// to 2^53 is a double (its enclosure is that point), what from_rational128 gives.
inline Number Number::integer(std::int64_t value) {
  if (!exact_in_double(value)) return rational(value, 1);
  Number n;
  n.numerator_ = value;
  n.value_ = n.lower_ = n.upper_ = static_cast<double>(value);
  return n;
}

inline const Number& Number::one() {
  static const Number kOne = integer(1);
  return kOne;
}

}  // namespace spar::symbolic
