// The one number reader of spar: every option, JSONL record and file that holds a number reads it
// here, so each accepts exactly what spar prints and rejects the same mistakes the same way.
//
// Grammar (the text must be one number and nothing else: no spaces, no trailing characters):
//   number  := [+|-] digits [. digits] [(e|E) [+|-] digits]  |  [+|-] . digits [exponent]
//            | [+|-] (inf | infinity | nan)   (any case; "nan" and "inf" are what spar's JSON
//            prints)
// Every finite double round-trips: format_number prints the shortest text that reads back to the
// same double (subnormals included, e.g. 5e-324). A value beyond the double range ("1e400") or
// nonzero below the smallest subnormal ("1e-400") is an error, never silently inf or 0.
//
// read_number adds the caller's limits: the result is always finite and inside them, else a
// NumberError names the option (or field) and says what is allowed in words ("must be a positive
// number"), never by printing a 309-digit bound.
//
// Example:
//   const double tol = read_number("1e-3", "--tol", NumberLimits::non_negative());   // 0.001
//   read_number("nan", "--max-opening", NumberLimits::positive());
//       // throws "--max-opening: must be a positive number, got 'nan'"
//   const std::uint64_t seed = read_count("42", "--seed", 0, UINT64_MAX);          // 42
//   format_number(2e-9);                                                           // "2e-09"
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "spar/common/error.hpp"

namespace spar {

// A number that is malformed or outside the caller's limits.
class NumberError : public Error {
 public:
  using Error::Error;
};

// The double `text` spells exactly (inf and nan included), or nothing when it is not exactly one
// number or its value is beyond the double range (overflow, or underflow to zero).
[[nodiscard]] std::optional<double> parse_number(std::string_view text);

// The closed (or, with low_exclusive, half-open) interval a value must lie in; always finite.
struct NumberLimits {
  double low{-std::numeric_limits<double>::max()};
  double high{std::numeric_limits<double>::max()};
  bool low_exclusive{false};

  [[nodiscard]] static NumberLimits any() { return {}; }
  [[nodiscard]] static NumberLimits positive() {
    return {0, std::numeric_limits<double>::max(), true};
  }
  [[nodiscard]] static NumberLimits non_negative() {
    return {0, std::numeric_limits<double>::max()};
  }
  [[nodiscard]] bool contains(double value) const;
  // "a positive number", "a number from 0 to 180", "a number > 0 and <= 360", ...
  [[nodiscard]] std::string describe() const;
};

// The finite number `text` spells, inside `limits`; throws NumberError "<what>: ..." otherwise.
[[nodiscard]] double read_number(std::string_view text, std::string_view what,
                                 const NumberLimits& limits = NumberLimits::any());

// A whole number from `low` to `high`: decimal digits with an optional '+' (exact up to 2^64 - 1),
// or any number text with an integer value up to 2^53 ("1e6"). Throws NumberError otherwise.
[[nodiscard]] std::uint64_t read_count(std::string_view text, std::string_view what,
                                       std::uint64_t low, std::uint64_t high);

// The shortest text that parse_number reads back as exactly `value` ("inf", "-inf", "nan" for
// the non-finite ones).
[[nodiscard]] std::string format_number(double value);

}  // namespace spar
