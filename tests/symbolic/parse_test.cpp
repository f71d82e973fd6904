#include "symbolic/parse.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "symbolic/operations.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::symbolic {
namespace {

// Parsing `text` throws SymbolicError whose message contains `fragment`.
void expect_parse_error(const std::string& text, const std::string& fragment) {
  SCOPED_TRACE("parsing '" + text + "'");
  ExprPool pool;
  EXPECT_THROW_MESSAGE(parse(pool, text), fragment);
  EXPECT_THROW(static_cast<void>(parse(pool, text)), SymbolicError);
}

TEST(Parse, PrecedenceAndAssociativity) {
  ExprPool pool;
  const Expr x = pool.variable("x"), y = pool.variable("y"), z = pool.variable("z");
  EXPECT_EQ(parse(pool, "x + y * z"), x + y * z);
  EXPECT_EQ(parse(pool, "-x^2"), -pow(x, 2));
  EXPECT_EQ(parse(pool, "x^y^z"), pow(x, pow(y, z)));
  EXPECT_EQ(parse(pool, "x / y / z"), x / (y * z));
  EXPECT_EQ(parse(pool, "x ** 2"), pow(x, 2));
  EXPECT_EQ(parse(pool, "atan2(y, x) + pow(x, 3) + fabs(z)"), atan2(y, x) + pow(x, 3) + abs(z));
}

TEST(Parse, DecimalLiteralsAreExact) {
  ExprPool pool;
  EXPECT_EQ(parse(pool, "0.1 + 0.2"), pool.constant(Number::rational(3, 10)));
  EXPECT_EQ(parse(pool, "4.27e-05"), pool.constant(Number::rational(427, 10000000)));
}

TEST(Parse, ErrorsNameTheProblemAndColumn) {
  expect_parse_error("sin(x", "expected ')' at column 6");
  expect_parse_error("x + * y", "unexpected '*' at column 5");
  expect_parse_error("", "empty expression");
  expect_parse_error("foo(x)", "unknown function 'foo'");
  expect_parse_error("atan2(x)", "'atan2' takes 2 arguments, got 1");
  expect_parse_error("x $ y", "unexpected character '$'");
  expect_parse_error("x / 0", "division by zero");
  expect_parse_error("x y", "unexpected 'y'");
}

TEST(Parse, DeepNestingFailsCleanly) {
  const std::string deep = std::string(100000, '(') + "x" + std::string(100000, ')');
  expect_parse_error(deep, "nested deeper than");
  const std::string minus = std::string(100000, '-') + "x";
  expect_parse_error(minus, "nested deeper than");
}

TEST(Parse, LongFlatInputParses) {
  std::string text = "x";
  for (int i = 0; i < 100000; ++i) text += " + x*" + std::to_string(i % 7);
  ExprPool pool;
  const Expr e = parse(pool, text);
  // 1 + Σ_{i<100000} (i mod 7) = 1 + 14285·21 + (0+1+2+3+4) = 299996
  EXPECT_EQ(e, pool.variable("x") * 299996);
}

TEST(Print, RoundTripsThroughParse) {
  ExprPool pool;
  for (const char* text :
       {"sin(x)^2 + cos(x)^2", "(1/3)*x - y/2", "-(x*y)/(z*w)", "2^(1/2)*x", "x^y^z",
        "min(y, x) - max(x, y)", "exp(-x)*3 - 4.27e-05", "pi*x", "1/x", "-1/x", "(x+y)^(1/3)",
        "x^-2 + 0.12345678901234567891", "atan2(-y, x - 1)"}) {
    const Expr e = parse(pool, text);
    EXPECT_EQ(parse(pool, to_string(e)), e) << text << " printed as " << to_string(e);
  }
}

TEST(Print, EveryCorpusExpressionRoundTrips) {
  std::ifstream corpus(std::string(SPAR_CORPUS_DIR) + "/fpbench.jsonl");
  ASSERT_TRUE(corpus) << "corpus not found";
  std::string line;
  int count = 0;
  while (std::getline(corpus, line)) {
    const auto start = line.find("\"expr\": \"") + 9;
    const std::string text = line.substr(start, line.find('"', start) - start);
    ExprPool pool;
    const Expr e = parse(pool, text);
    EXPECT_EQ(parse(pool, to_string(e)), e) << text;
    ++count;
  }
  EXPECT_EQ(count, 77);
}

TEST(Print, HugeTreeIsRefusedNotPrinted) {
  ExprPool pool;
  Expr e = pool.variable("x");
  for (int i = 0; i < 60; ++i) e = sin(e) * cos(e);  // 2^60 nodes as a tree
  EXPECT_THROW((void)to_string(e), SymbolicError);
}

}  // namespace
}  // namespace spar::symbolic
