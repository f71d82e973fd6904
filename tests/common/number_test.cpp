#include "spar/common/number.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

namespace spar {
namespace {

// The message of the NumberError `call` throws ("" and a test failure if it throws none).
std::string error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const NumberError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a NumberError";
  return "";
}

TEST(ParseNumber, ReadsWhatSparPrints) {
  EXPECT_EQ(parse_number("0.1"), 0.1);
  EXPECT_EQ(parse_number("+2.5e3"), 2500.0);
  EXPECT_EQ(parse_number("-.5"), -0.5);
  EXPECT_EQ(parse_number("5."), 5.0);
  EXPECT_EQ(parse_number("1e-310"), 1e-310);  // subnormal: refused by std::stod
  EXPECT_EQ(parse_number("4.9406564584124654e-324"), std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(parse_number("inf"), std::numeric_limits<double>::infinity());
  EXPECT_EQ(parse_number("-Infinity"), -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(*parse_number("nan")));
}

TEST(ParseNumber, RejectsAnythingButOneNumber) {
  for (const char* text : {"", " 1", "1 ", "1e", "e5", "1x", "0x10", "nan(1)", "--1", "+-1", "1,5",
                           "infinit", ".", "+"}) {
    EXPECT_EQ(parse_number(text), std::nullopt) << text;
  }
}

TEST(ParseNumber, OverflowAndUnderflowAreNotNumbers) {
  EXPECT_EQ(parse_number("1e400"), std::nullopt);
  EXPECT_EQ(parse_number("-1e400"), std::nullopt);
  EXPECT_EQ(parse_number("1e-400"), std::nullopt);
}

// Every finite double printed by format_number reads back to the same bits.
RC_GTEST_PROP(FormatNumber, RoundTripsEveryFiniteDouble, (std::uint64_t bits)) {
  const double value = std::bit_cast<double>(bits);
  RC_PRE(std::isfinite(value));
  const std::optional<double> back = parse_number(format_number(value));
  RC_ASSERT(back.has_value());
  RC_ASSERT(std::bit_cast<std::uint64_t>(*back) == bits);
}

TEST(FormatNumber, NamesNonFiniteValuesAsParseNumberReadsThem) {
  EXPECT_EQ(format_number(2e-9), "2e-09");
  EXPECT_EQ(format_number(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(format_number(-std::numeric_limits<double>::infinity()), "-inf");
  EXPECT_EQ(format_number(std::numeric_limits<double>::quiet_NaN()), "nan");
}

TEST(ReadNumber, AcceptsNumbersInsideTheLimits) {
  EXPECT_EQ(read_number("1e-3", "--tol", NumberLimits::non_negative()), 1e-3);
  EXPECT_EQ(read_number("0", "--tol", NumberLimits::non_negative()), 0.0);
  EXPECT_EQ(read_number("180", "--max-tilt-deg", {0, 180}), 180.0);
  EXPECT_EQ(read_number("-1e-310", "lower bound"), -1e-310);
}

TEST(ReadNumber, SaysWhatIsAllowedInWords) {
  EXPECT_EQ(error_of([] { (void)read_number("0", "--budget", NumberLimits::positive()); }),
            "--budget: must be a positive number, got '0'");
  EXPECT_EQ(error_of([] { (void)read_number("nan", "--max-opening", NumberLimits::positive()); }),
            "--max-opening: must be a positive number, got 'nan'");
  EXPECT_EQ(error_of([] { (void)read_number("-1", "--tol", NumberLimits::non_negative()); }),
            "--tol: must be a number >= 0, got '-1'");
  EXPECT_EQ(error_of([] {
              (void)read_number("200", "--max-tilt-deg", {0, 180});
            }),
            "--max-tilt-deg: must be a number from 0 to 180, got '200'");
  EXPECT_EQ(error_of([] {
              (void)read_number("0", "--approach-step", {0, 360, true});
            }),
            "--approach-step: must be a number > 0 and <= 360, got '0'");
  EXPECT_EQ(error_of([] { (void)read_number("inf", "x"); }),
            "x: must be a finite number, got 'inf'");
  EXPECT_EQ(error_of([] { (void)read_number("abc", "--q"); }), "--q: expected a number, got 'abc'");
}

TEST(ReadNumber, NeverPrintsTheLargestDoubleInFull) {
  const std::string message =
      error_of([] { (void)read_number("1e400", "--widen", NumberLimits::positive()); });
  EXPECT_NE(message.find("'1e400' is outside the range of double precision numbers"),
            std::string::npos)
      << message;
  EXPECT_LT(message.size(), 200u) << message;
}

TEST(ReadCount, ReadsWholeNumbersUpToTwoToTheSixtyFour) {
  EXPECT_EQ(read_count("18446744073709551615", "--seed", 0, UINT64_MAX), UINT64_MAX);
  EXPECT_EQ(read_count("+7", "--budget", 1, 1000), 7u);
  EXPECT_EQ(read_count("1e6", "--max-evals", 1, 1'000'000'000), 1'000'000u);
}

TEST(ReadCount, RejectsNegativeFractionalAndTooLarge) {
  EXPECT_EQ(error_of([] { (void)read_count("-1", "--seed", 0, UINT64_MAX); }),
            "--seed: must be a whole number from 0 to 18446744073709551615, got '-1'");
  EXPECT_EQ(error_of([] { (void)read_count("18446744073709551616", "--seed", 0, UINT64_MAX); }),
            "--seed: must be a whole number from 0 to 18446744073709551615, got "
            "'18446744073709551616'");
  EXPECT_EQ(error_of([] { (void)read_count("2.5", "--positions", 1, 20); }),
            "--positions: must be a whole number from 1 to 20, got '2.5'");
  EXPECT_EQ(error_of([] { (void)read_count("0", "--budget", 1, 1000); }),
            "--budget: must be a whole number from 1 to 1000, got '0'");
  EXPECT_EQ(error_of([] { (void)read_count("many", "--budget", 1, 1000); }),
            "--budget: expected a whole number, got 'many'");
}

}  // namespace
}  // namespace spar
