#include "spar/symbolic/operations.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::symbolic {
namespace {

class OperationsTest : public ::testing::Test {
 protected:
  ExprPool pool;
  Expr x = pool.variable("x"), y = pool.variable("y");
};

TEST_F(OperationsTest, DerivativesOfEveryFunction) {
  EXPECT_EQ(differentiate(sin(x), x), cos(x));
  EXPECT_EQ(differentiate(cos(x), x), -sin(x));
  EXPECT_EQ(differentiate(exp(2 * x), x), 2 * exp(2 * x));
  EXPECT_EQ(differentiate(log(x), x), 1 / x);
  EXPECT_EQ(differentiate(pow(x, 3) * y, x), 3 * pow(x, 2) * y);
  EXPECT_EQ(differentiate(sqrt(x), x), 1 / (2 * sqrt(x)));
  EXPECT_EQ(differentiate(atan(x), x), 1 / (1 + pow(x, 2)));
  EXPECT_EQ(differentiate(x * y, pool.variable("z")), pool.integer(0));
}

TEST_F(OperationsTest, SharedSubexpressionsAreDifferentiatedOnce) {
  Expr e = x;
  for (int i = 0; i < 40; ++i) e = sin(e) * cos(e);  // 2^40 as a tree
  const Expr d = differentiate(e, x);
  EXPECT_LT(dag_size(d), 2000u);
  EXPECT_GT(tree_size(e), 1e12);
}

TEST_F(OperationsTest, SubstituteRebuildsCanonically) {
  const Expr f = x * sin(y) + y;
  EXPECT_EQ(substitute(f, {{y, pool.integer(0)}}), pool.integer(0));
  EXPECT_EQ(substitute(f, {{x, y}}), y * sin(y) + y);
}

TEST_F(OperationsTest, FreeVariablesAreSortedByName) {
  const Expr b = pool.variable("b"), a = pool.variable("a");
  const std::vector<Expr> vars = free_variables(b * sin(a) + x);
  ASSERT_EQ(vars.size(), 3u);
  EXPECT_EQ(vars[0].name(), "a");
  EXPECT_EQ(vars[2].name(), "x");
}

TEST_F(OperationsTest, VariablesMetAreTheFreeVariablesEachOnce) {
  const Expr b = pool.variable("b"), a = pool.variable("a");
  const std::vector<Expr> roots = {b * sin(a) + x, a * x, pool.integer(3)};
  std::vector<Expr> met = variables_met(roots);
  ASSERT_EQ(met.size(), 3u);
  std::sort(met.begin(), met.end(), [](Expr p, Expr q) { return p.name() < q.name(); });
  EXPECT_EQ(met, free_variables(roots));
  EXPECT_TRUE(variables_met(std::vector{pool.integer(3)}).empty());
}

TEST_F(OperationsTest, EvaluateNeedsEveryVariable) {
  EXPECT_DOUBLE_EQ(evaluate(x * y + 1, {{"x", 2}, {"y", 3}}), 7.0);
  try {
    (void)evaluate(x * y, {{"x", 2}});
    ADD_FAILURE() << "no error for a missing variable";
  } catch (const SymbolicError& e) {
    EXPECT_NE(std::string(e.what()).find("'y' has no value"), std::string::npos);
  }
  EXPECT_TRUE(std::isnan(evaluate(log(x), {{"x", -1}})));
}

TEST_F(OperationsTest, JacobianMatchesDifferentiate) {
  const Expr outputs[] = {x * y, sin(x) + y * y};
  const Expr vars[] = {x, y};
  const auto j = jacobian(outputs, vars);
  EXPECT_EQ(j[0][0], y);
  EXPECT_EQ(j[1][1], 2 * y);
}

// A chain 100 000 operations deep: build, evaluate, differentiate, print, compile. Nothing may
// recurse on the C++ stack.
TEST_F(OperationsTest, HundredThousandDeepChainWorks) {
  Expr chain = x;
  for (int i = 0; i < 100000; ++i) chain = sin(chain) + 1;
  const double value = evaluate(chain, {{"x", 0.3}});
  double reference = 0.3;
  for (int i = 0; i < 100000; ++i) reference = std::sin(reference) + 1;
  EXPECT_DOUBLE_EQ(value, reference);
  const Expr d = differentiate(chain, x);
  EXPECT_TRUE(std::isfinite(evaluate(d, {{"x", 0.3}})));
  EXPECT_GT(to_string(chain).size(), 100000u * 6);
  const Expr inputs[] = {x};
  const Tape tape = Tape::compile(std::span<const Expr>(&d, 1), inputs);
  tape.check_invariants();
}

// Each distinct constant gets one slot, shared by every use (found by hash: compiling 100 000
// distinct constants was quadratic). Integer powers of any size compile to exact PowInt steps.
TEST_F(OperationsTest, TapeConstantsAreSharedOncePerValue) {
  std::vector<Expr> terms;
  for (int i = 0; i < 20000; ++i) terms.push_back(sin(x + i % 5000) * (i % 3 + 2));
  const Expr f = pool.sum(terms);
  const Expr inputs[] = {x};
  const Tape tape = Tape::compile(std::span<const Expr>(&f, 1), inputs);
  tape.check_invariants();
  std::vector<double> values;
  for (const Number& n : tape.constants()) values.push_back(n.value());
  std::sort(values.begin(), values.end());
  EXPECT_EQ(std::adjacent_find(values.begin(), values.end()), values.end());  // no duplicates
  EXPECT_LE(tape.constants().size(), 5000u + 10u);
  TapeEvaluator<double> evaluator(tape);
  double in[] = {0.25}, out[1];
  evaluator.evaluate(in, out);
  EXPECT_NEAR(out[0], evaluate(f, {{"x", 0.25}}), 1e-8);
}

TEST_F(OperationsTest, HugeIntegerPowersCompileToExactSteps) {
  const Expr inputs[] = {x};
  for (const std::int64_t n : {std::int64_t{1} << 30, (std::int64_t{1} << 30) + 1,
                               std::int64_t{3000000001}, std::int64_t{1} << 62}) {
    const Expr f = pow(x, n);
    const Tape tape = Tape::compile(std::span<const Expr>(&f, 1), inputs);
    for (const Instruction& in : tape.instructions()) EXPECT_NE(in.op, TapeOp::kPow) << n;
    TapeEvaluator<double> evaluator(tape);
    double point[] = {-1.0}, out[1];
    evaluator.evaluate(point, out);
    EXPECT_EQ(out[0], n % 2 == 0 ? 1.0 : -1.0) << n;  // parity kept: (-1)^n
  }
}

}  // namespace
}  // namespace spar::symbolic
