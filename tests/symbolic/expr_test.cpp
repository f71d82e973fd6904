#include "spar/symbolic/expr.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"

namespace spar::symbolic {
namespace {

TEST(Number, DecimalLiteralsAreExactRationals) {
  const Number tenth = *Number::parse_decimal("0.1");
  EXPECT_TRUE(tenth.is_rational());
  EXPECT_EQ(tenth + tenth + tenth, Number::rational(3, 10));
  // The enclosure contains 1/10 although 0.1 is not a double: lower < value < upper.
  EXPECT_LT(tenth.lower(), tenth.upper());
  EXPECT_LE(tenth.lower(), 0.1);
  EXPECT_GE(tenth.upper(), 0.1);
}

// Number::integer's and negation's shortcuts give exactly what the general rational path gives,
// on both sides of 2^53 (where a double stops holding every integer).
TEST(Number, ShortcutsGiveTheGeneralPathsBits) {
  const auto same = [](const Number& a, const Number& b) {
    return a.is_rational() == b.is_rational() && a.numerator() == b.numerator() &&
           a.denominator() == b.denominator() && a.value() == b.value() && a.lower() == b.lower() &&
           a.upper() == b.upper();
  };
  constexpr std::int64_t kTwo53 = std::int64_t{1} << 53;
  const std::int64_t max = std::numeric_limits<std::int64_t>::max();
  for (const std::int64_t v :
       {std::int64_t{0}, std::int64_t{1}, std::int64_t{-1}, std::int64_t{16}, std::int64_t{-17},
        kTwo53 - 1, kTwo53, kTwo53 + 1, -kTwo53, -kTwo53 - 1, max, -max}) {
    EXPECT_TRUE(same(Number::integer(v), Number::rational(v, 1))) << v;
    EXPECT_TRUE(same(-Number::integer(v), Number::rational(-v, 1))) << v;
  }
  for (const auto& [n, d] : std::vector<std::pair<std::int64_t, std::int64_t>>{
           {1, 3}, {-2, 7}, {5, 4}, {kTwo53 + 1, 3}, {3, kTwo53 + 1}, {-max, 2}, {1, max}}) {
    EXPECT_TRUE(same(-Number::rational(n, d), Number::rational(-n, d))) << n << "/" << d;
  }
}

// Regression: 2^53 + 1 converts to the double 2^53, and the enclosure of the integer 2^53 + 1 was
// the point 2^53 (the exactness test looked at the converted double): a bound over it excluded its
// value. Its enclosure now holds it (2^53 and 2^53 + 2 are the neighbouring doubles).
TEST(Number, AnIntegerPastTwoToThe53IsEnclosed) {
  constexpr std::int64_t kTwo53 = std::int64_t{1} << 53;
  for (const Number& n : {Number::integer(kTwo53 + 1), Number::rational(kTwo53 + 1, 1),
                          *Number::parse_decimal("9007199254740993")}) {
    EXPECT_LE(n.lower(), 0x1p53);
    EXPECT_GE(n.upper(), 0x1p53 + 2);
  }
  const Number half = Number::rational(kTwo53 + 1, 2);  // 2^52 + 1/2, between two doubles
  EXPECT_LE(half.lower(), 0x1p52);
  EXPECT_GE(half.upper(), 0x1p52 + 1);
}

TEST(Number, ExactDyadicRationalHasPointEnclosure) {
  const Number quarter = Number::rational(1, 4);
  EXPECT_EQ(quarter.lower(), 0.25);
  EXPECT_EQ(quarter.upper(), 0.25);
}

TEST(Number, OverflowFallsBackToSoundEnclosure) {
  const Number big = Number::integer(std::int64_t{1} << 62);
  const Number square = big * big;  // 2^124 does not fit in 64 bits
  EXPECT_FALSE(square.is_rational());
  EXPECT_LE(square.lower(), std::ldexp(1.0, 124));
  EXPECT_GE(square.upper(), std::ldexp(1.0, 124));
}

// Regression (corpus record instantaneousCurrent): (2*3.14159265359)^2 overflows 64 bits. The
// enclosure must contain the exact value and survive print and parse unchanged.
TEST(Number, OverflowedConstantRoundTripsThroughText) {
  const Number two_pi = Number::rational(314159265359, 50000000000);
  const Number square = two_pi * two_pi;
  ASSERT_FALSE(square.is_rational());
  const long double exact = 6.28318530718L * 6.28318530718L;
  EXPECT_LE(static_cast<long double>(square.lower()), exact);
  EXPECT_GE(static_cast<long double>(square.upper()), exact);
  EXPECT_EQ(*Number::parse_decimal(square.to_string()), square);
}

// An integer power that overflows is the double nearest within one ulp, enclosed by its two
// neighbours, however large the exponent: 20^85, and (1 + 1e-6)^(1e7) = e^(9.9999950000...) =
// 22026.35566282649397... (square-and-multiply in plain long double would lose 24 bits there).
TEST(Number, OverflowedPowerIsOneUlpEnclosure) {
  const Number big = Number::integer(20).pow(85);
  ASSERT_FALSE(big.is_rational());
  EXPECT_EQ(big.lower(), std::nextafter(big.value(), 0.0));
  EXPECT_EQ(big.upper(), std::nextafter(big.value(), HUGE_VAL));
  const long double exact = std::pow(20.0L, 85);
  EXPECT_LT(static_cast<long double>(big.lower()), exact);
  EXPECT_GT(static_cast<long double>(big.upper()), exact);
  const Number e10 = Number::rational(1000001, 1000000).pow(10000000);
  EXPECT_LT(e10.lower(), 22026.355662826494);
  EXPECT_GT(e10.upper(), 22026.355662826494);
  EXPECT_EQ(e10.upper(), std::nextafter(e10.value(), HUGE_VAL));
  EXPECT_EQ(*Number::parse_decimal(e10.to_string()), e10);
  EXPECT_THROW((void)Number::integer(2).pow(1024), SymbolicError);
}

TEST(Number, TrailingZerosAfterThePointAreWrittenPrecision) {
  EXPECT_TRUE(Number::parse_decimal("2.5")->is_rational());
  EXPECT_TRUE(Number::parse_decimal("1000000000000000000")->is_rational());  // 1e18 exactly
  const Number printed = *Number::parse_decimal("2.5000000000000000");       // 17 digits
  EXPECT_FALSE(printed.is_rational());
  EXPECT_LT(printed.lower(), 2.5);
  EXPECT_GT(printed.upper(), 2.5);
}

TEST(Number, RealArithmeticWidensOutward) {
  const Number a = Number::real(0.1), b = Number::real(0.2);
  const Number sum = a + b;  // 0.1 + 0.2 rounds in double
  EXPECT_LT(sum.lower(), sum.upper());
  EXPECT_LE(sum.lower(), 0.1 + 0.2);
  EXPECT_GE(sum.upper(), 0.1 + 0.2);
}

TEST(Number, NaNAndInfinityAreRejected) {
  EXPECT_THROW((void)Number::real(std::nan("")), SymbolicError);
  EXPECT_THROW((void)Number::real(HUGE_VAL), SymbolicError);
  EXPECT_THROW((void)Number::rational(1, 0), SymbolicError);
  EXPECT_THROW((void)(Number::integer(1) / Number::integer(0)), SymbolicError);
}

TEST(Number, PrintsTerminatingFractionsAsDecimals) {
  EXPECT_EQ(Number::rational(1, 10).to_string(), "0.1");
  EXPECT_EQ(Number::rational(-3, 8).to_string(), "-0.375");
  EXPECT_EQ(Number::rational(1, 3).to_string(), "1/3");
  EXPECT_EQ(Number::integer(-7).to_string(), "-7");
  // Regression (fuzz, "3.413099*6151055^2"): a decimal whose digits pass 64 bits printed as
  // another number (9022289571.153163); it prints as the fraction.
  EXPECT_EQ(Number::rational(5165449232221520579, 40000).to_string(), "5165449232221520579/40000");
  EXPECT_EQ(Number::rational(-5165449232221520579, 40000).to_string(),
            "-5165449232221520579/40000");
}

class ExprTest : public ::testing::Test {
 protected:
  ExprPool pool;
  Expr x = pool.variable("x"), y = pool.variable("y"), z = pool.variable("z");
  // The guard term 0·e (see Domains in expr.hpp).
  Expr guard(Expr e) {
    const Term term[] = {{e, Number()}};
    return pool.sum(Number(), term);
  }
};

TEST_F(ExprTest, StructurallyEqualBuildsShareOneNode) {
  const Expr a = sin(x) * (y + 2) - x / y;
  const Expr b = -(x / y) + (2 + y) * sin(x);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.id(), b.id());
}

TEST_F(ExprTest, CanonicalFormsAtConstruction) {
  EXPECT_EQ(x - x, pool.integer(0));
  EXPECT_EQ(x * 1.0, x);
  EXPECT_EQ(x + 0.0, x);
  EXPECT_EQ(x * x, pow(x, 2));
  EXPECT_EQ(pow(x, 2) / x, x + guard(pow(x, -1)));  // x, where x != 0
  EXPECT_EQ(x + 2 * x, 3 * x);
  EXPECT_EQ(pow(x, 0), pool.integer(1));
  EXPECT_EQ(2 * (x + y), 2 * x + 2 * y);
  EXPECT_EQ((x + y) + z, x + (y + z));
  EXPECT_EQ((x * y) * z, x * (y * z));
  EXPECT_EQ(x * 0.0, pool.integer(0));
}

// Issue 12: a simplification at construction may not make an undefined expression defined. What
// it removes comes back as a guard term 0·t, undefined where t is.
TEST_F(ExprTest, CancellationKeepsTheDomainOfWhatItRemoves) {
  struct Case {
    Expr e;
    double outside, inside;  // a point outside the domain, one inside
    double value_inside;
  };
  const Case cases[] = {
      {log(x) - log(x), -1, 2, 0},       {0 * log(x), -1, 2, 0},
      {sqrt(x) - sqrt(x) + 1, -1, 2, 1}, {x / x, 0, 2, 1},
      {pow(sqrt(x), 2), -1, 2, 2},       {pow(x, 2) * pow(x, -2), 0, 3, 1},
      {pow(log(x), 0), -1, 2, 1},        {pow(pool.integer(1), log(x)), -1, 2, 1},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(to_string(c.e));
    EXPECT_TRUE(c.e.is_partial());
    EXPECT_TRUE(std::isnan(evaluate(c.e, {{"x", c.outside}})));
    EXPECT_DOUBLE_EQ(evaluate(c.e, {{"x", c.inside}}), c.value_inside);
    EXPECT_EQ(parse(pool, to_string(c.e)), c.e);  // the guard prints and reads back
  }
  // Cancelling what is defined everywhere still folds.
  EXPECT_EQ(x - x, pool.integer(0));
  EXPECT_EQ((x + y) * 0.0, pool.integer(0));
  EXPECT_EQ(pow(x, 3) / pow(x, 2), x + guard(pow(x, -1)));
  EXPECT_FALSE((sin(x) - sin(x) + pow(x, 2)).is_partial());
  pool.check_invariants();
}

TEST_F(ExprTest, SumStoresConstantAndSortedTerms) {
  const Expr e = 3 * y + 5 + x;
  ASSERT_EQ(e.op(), Op::kAdd);
  EXPECT_EQ(e.constant(), Number::integer(5));
  ASSERT_EQ(e.operand_count(), 2u);
  EXPECT_LT(e.operand(0).id(), e.operand(1).id());
  EXPECT_EQ(e.factor(e.operand(0) == y ? 0 : 1), Number::integer(3));
}

TEST_F(ExprTest, ProductStoresCoefficientAndExponents) {
  const Expr e = -2 * x * x * x / y;
  ASSERT_EQ(e.op(), Op::kMul);
  EXPECT_EQ(e.constant(), Number::integer(-2));
  ASSERT_EQ(e.operand_count(), 2u);
  EXPECT_EQ(e.factor(e.operand(0) == x ? 0 : 1), Number::integer(3));
  EXPECT_EQ(e.factor(e.operand(0) == y ? 0 : 1), Number::integer(-1));
}

TEST_F(ExprTest, FunctionsFoldOnlyExactSpecialValues) {
  EXPECT_EQ(sin(pool.integer(0)), pool.integer(0));
  EXPECT_EQ(cos(pool.integer(0)), pool.integer(1));
  EXPECT_EQ(log(pool.integer(1)), pool.integer(0));
  EXPECT_EQ(sqrt(pool.constant(Number::rational(9, 4))), pool.constant(Number::rational(3, 2)));
  EXPECT_EQ(sin(pool.integer(1)).op(), Op::kSin);  // sin(1) is not rounded into a double
  EXPECT_EQ(sqrt(pool.integer(2)).op(), Op::kSqrt);
}

TEST_F(ExprTest, MinMaxAreCommutative) {
  EXPECT_EQ(min(x, y), min(y, x));
  EXPECT_EQ(max(x, x), x);
  EXPECT_EQ(min(pool.integer(2), pool.integer(3)), pool.integer(2));
}

TEST_F(ExprTest, InvalidVariableNamesAreRejected) {
  EXPECT_THROW((void)pool.variable("2x"), SymbolicError);
  EXPECT_THROW((void)pool.variable(""), SymbolicError);
  EXPECT_THROW((void)pool.variable("a b"), SymbolicError);
}

TEST_F(ExprTest, MixingPoolsIsAnError) {
  ExprPool other;
  const Expr w = other.variable("x");
  EXPECT_THROW((void)(x + w), SymbolicError);
}

// Regression: a product whose rational coefficient overflows keeps it as a constant operand, so
// Add and Mul factors stay exact rationals (a checked invariant) and the text re-parses.
TEST_F(ExprTest, OverflowingCoefficientBecomesAConstantOperand) {
  const Expr two_pi_x = pool.constant(Number::rational(314159265359, 50000000000)) * x;
  const Expr square = two_pi_x * two_pi_x;
  ASSERT_EQ(square.op(), Op::kMul);
  EXPECT_TRUE(square.constant().is_one());
  EXPECT_EQ(square.operand_count(), 2u);  // x^2 and the overflowed constant
  const Expr sum = square + y * 3;
  pool.check_invariants();
  EXPECT_EQ(parse(pool, to_string(sum)), sum);
}

TEST_F(ExprTest, LargeSumInAnyOrderIsOneNode) {
  std::vector<Expr> terms;
  for (int i = 0; i < 40; ++i)
    terms.push_back(pool.variable(std::string("v").append(std::to_string(i))) * (i + 1));
  const Expr forward = pool.sum(terms);
  std::mt19937 rng(7);
  std::shuffle(terms.begin(), terms.end(), rng);
  EXPECT_EQ(pool.sum(terms), forward);
  pool.check_invariants();
}

// Regression (bench/planner_bench's k-chain overflowed the stack): a coefficient times a sum
// past the flattening limit went back and forth between product() and sum() without end.
TEST_F(ExprTest, CoefficientTimesASumPastTheFlatteningLimitIsAProduct) {
  std::vector<Expr> terms;
  for (int i = 0; i < 100; ++i) terms.push_back(pool.variable("w" + std::to_string(i)));
  const Expr wide = pool.sum(terms);
  ASSERT_EQ(wide.op(), Op::kAdd);
  const Expr scaled = wide * 3;
  EXPECT_EQ(scaled.op(), Op::kMul);
  EXPECT_EQ(scaled.constant(), Number::integer(3));
  EXPECT_EQ(scaled * pool.constant(Number::rational(1, 3)), wide);
  EXPECT_EQ((wide * 2 + x).op(), Op::kAdd);
  pool.check_invariants();
}

// expr.hpp: flattening stops at 16 operands. A sum of 16 joins its parent's operands (and like
// terms across them merge); a sum of 17 stays one operand.
TEST_F(ExprTest, FlatteningStopsAtSixteenOperands) {
  std::vector<Expr> terms;
  for (int i = 0; i < 17; ++i) terms.push_back(pool.variable("v" + std::to_string(i)));
  const Expr sixteen = pool.sum(std::span(terms).first(16));
  const Expr seventeen = pool.sum(terms);
  EXPECT_EQ((sixteen + x).operand_count(), 17u);
  EXPECT_EQ((sixteen - terms[0]).operand_count(), 15u);
  EXPECT_EQ((seventeen + x).operand_count(), 2u);
  EXPECT_EQ((seventeen - terms[0]).operand_count(), 2u);
  EXPECT_EQ((2 * sixteen).op(), Op::kAdd);  // the coefficient is distributed
  EXPECT_EQ((2 * seventeen).op(), Op::kMul);
  pool.check_invariants();
}

TEST_F(ExprTest, DeepChainBuildsInLinearSpace) {
  Expr chain = x;
  for (int i = 0; i < 100000; ++i) chain = chain * sin(chain) + 1;
  EXPECT_LT(pool.size(), 500000u);
  pool.check_invariants();
}

// A pool starts from the emptied arrays of the thread's last pool (SpareArrays in expr.cpp): what
// it builds must not depend on them, whatever their size, and a pool may die on another thread.
TEST(ExprPoolReuse, PoolsBuiltAfterOthersAreTheSame) {
  const auto build = [](ExprPool& pool, int n) {
    Expr acc = pool.variable("x");
    for (int i = 0; i < n; ++i)
      acc = acc * sin(acc + pool.variable("y" + std::to_string(i % 7))) + i;
    pool.check_invariants();  // ids are positions in the arena: equal ids, equal builds
    return std::tuple{acc.id(), pool.size(), n <= 5 ? to_string(acc) : ""};
  };
  std::map<int, std::tuple<std::uint32_t, std::size_t, std::string>> first;
  for (int n : {3000, 1, 200, 3000, 5, 20000, 2}) {
    ExprPool pool;
    const auto built = build(pool, n);
    const auto [known, inserted] = first.emplace(n, built);
    if (!inserted) {
      EXPECT_EQ(built, known->second) << "n = " << n;
    }
  }
  auto elsewhere = std::make_unique<ExprPool>();
  const auto before = build(*elsewhere, 300);
  std::thread([&] { elsewhere.reset(); }).join();  // its arrays become that thread's spare
  ExprPool again;
  EXPECT_EQ(build(again, 300), before);
}

}  // namespace
}  // namespace spar::symbolic
