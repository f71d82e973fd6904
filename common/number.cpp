#include "spar/common/number.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <system_error>

namespace spar {
namespace {

enum class Reading { kNumber, kNotANumber, kOutOfRange };

struct ReadResult {
  Reading reading{Reading::kNotANumber};
  double value{0};
};

bool equals_ignoring_case(std::string_view text, std::string_view word) {
  return text.size() == word.size() &&
         std::equal(text.begin(), text.end(), word.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == b;
         });
}

// The grammar of number.hpp. from_chars does the decimal conversion (correctly rounded, subnormals
// included); it also takes forms the grammar excludes ("nan(...)", a bare "1e" read as "1"), so
// those are filtered first.
ReadResult read(std::string_view text) {
  std::string_view body = text;
  bool negative = false;
  if (!body.empty() && (body.front() == '+' || body.front() == '-')) {
    negative = body.front() == '-';
    body.remove_prefix(1);
  }
  if (equals_ignoring_case(body, "inf") || equals_ignoring_case(body, "infinity")) {
    return {Reading::kNumber, negative ? -std::numeric_limits<double>::infinity()
                                       : std::numeric_limits<double>::infinity()};
  }
  if (equals_ignoring_case(body, "nan")) {
    return {Reading::kNumber, std::numeric_limits<double>::quiet_NaN()};
  }
  if (body.empty() ||
      !(std::isdigit(static_cast<unsigned char>(body.front())) || body.front() == '.')) {
    return {};
  }
  double value = 0;
  const auto [end, error] =
      std::from_chars(body.data(), body.data() + body.size(), value, std::chars_format::general);
  if (end != body.data() + body.size()) return {};
  if (error == std::errc::result_out_of_range) return {Reading::kOutOfRange, 0};
  if (error != std::errc()) return {};
  return {Reading::kNumber, negative ? -value : value};
}

std::string quoted(std::string_view text) {
  std::string out(1, '\'');  // appended piecewise: GCC 12 warns (-Wrestrict) on "'" + text + "'"
  out.append(text).push_back('\'');
  return out;
}

}  // namespace

std::optional<double> parse_number(std::string_view text) {
  const ReadResult result = read(text);
  if (result.reading != Reading::kNumber) return std::nullopt;
  return result.value;
}

bool NumberLimits::contains(double value) const {
  return std::isfinite(value) && (low_exclusive ? value > low : value >= low) && value <= high;
}

std::string NumberLimits::describe() const {
  constexpr double kMax = std::numeric_limits<double>::max();
  const bool unbounded_low = low == -kMax && !low_exclusive, unbounded_high = high == kMax;
  if (unbounded_low && unbounded_high) return "a finite number";
  if (low == 0 && unbounded_high) return low_exclusive ? "a positive number" : "a number >= 0";
  if (unbounded_high)
    return "a number " + std::string(low_exclusive ? "> " : ">= ") + format_number(low);
  if (unbounded_low) return "a number <= " + format_number(high);
  if (low_exclusive) return "a number > " + format_number(low) + " and <= " + format_number(high);
  return "a number from " + format_number(low) + " to " + format_number(high);
}

double read_number(std::string_view text, std::string_view what, const NumberLimits& limits) {
  const ReadResult result = read(text);
  const std::string prefix = std::string(what) + ": ";
  switch (result.reading) {
    case Reading::kNotANumber:
      throw NumberError(prefix + "expected a number, got " + quoted(text));
    case Reading::kOutOfRange:
      throw NumberError(prefix + quoted(text) +
                        " is outside the range of double precision numbers (magnitude from "
                        "5e-324 to 1.7976931348623157e+308, or 0); must be " +
                        limits.describe());
    case Reading::kNumber:
      break;
  }
  if (!limits.contains(result.value)) {
    throw NumberError(prefix + "must be " + limits.describe() + ", got " + quoted(text));
  }
  return result.value;
}

std::uint64_t read_count(std::string_view text, std::string_view what, std::uint64_t low,
                         std::uint64_t high) {
  const std::string range = "must be a whole number from " + std::to_string(low) + " to " +
                            std::to_string(high) + ", got " + quoted(text);
  const std::string prefix = std::string(what) + ": ";
  std::string_view digits = text;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  std::uint64_t value = 0;
  if (!digits.empty() && std::all_of(digits.begin(), digits.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c)) != 0;
      })) {
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error != std::errc() || end != digits.data() + digits.size()) {
      throw NumberError(prefix + range);  // more than 2^64 - 1
    }
  } else {
    const ReadResult result = read(text);
    if (result.reading == Reading::kNotANumber) {
      throw NumberError(prefix + "expected a whole number, got " + quoted(text));
    }
    constexpr double kExact = 9007199254740992.0;  // 2^53: every whole double below is exact
    if (result.reading == Reading::kOutOfRange || !(result.value >= 0) || result.value > kExact ||
        result.value != std::floor(result.value)) {
      throw NumberError(prefix + range);
    }
    value = static_cast<std::uint64_t>(result.value);
  }
  if (value < low || value > high) throw NumberError(prefix + range);
  return value;
}

std::string format_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  std::array<char, 32> buffer{};
  // 32 characters hold the longest shortest-round-trip form of any double (24).
  char* const end = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value).ptr;
  return std::string(buffer.data(), end);
}

}  // namespace spar
