// The one function table (symbolic/functions.hpp): for every entry, the parser, the tape in
// doubles and in intervals, the symbolic derivative and the gradient evaluator's partials agree,
// so a function added to the table is checked everywhere it is generated.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "spar/bounds/internal/gradient.hpp"
#include "spar/bounds/interval.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds {
namespace {

using symbolic::Expr;

TEST(FunctionTable, EveryFunctionAgreesAcrossParserTapesAndDerivatives) {
  int checked = 0;
  for (const symbolic::Op op : symbolic::kFunctionOps) {
    symbolic::ExprPool pool;
    const std::string name(symbolic::function_name(op));
    SCOPED_TRACE(name);
    const bool binary = symbolic::is_binary_function(op);
    EXPECT_NE(binary, symbolic::is_unary_function(op));
    const Expr f = symbolic::parse(pool, name + (binary ? "(x, y)" : "(x)"));
    ASSERT_EQ(f.op(), op);
    const std::vector<Expr> inputs{pool.variable("x"), pool.variable("y")};
    const double point[] = {0.3, 0.7};  // inside every domain, no ties for min / max
    const double value = symbolic::evaluate(f, {{"x", point[0]}, {"y", point[1]}});
    ASSERT_TRUE(std::isfinite(value));

    const symbolic::Tape tape = symbolic::Tape::compile(std::span<const Expr>(&f, 1), inputs);
    internal::GradientEvaluator<double> real(tape);
    double gradient[2];
    EXPECT_DOUBLE_EQ(real.value_and_gradient(point, gradient), value);
    internal::GradientEvaluator<Interval> interval(tape);
    const Interval box[] = {Interval{point[0]}, Interval{point[1]}};
    Interval interval_gradient[2];
    const Interval enclosure = interval.value_and_gradient(box, interval_gradient);
    EXPECT_TRUE(enclosure.contains(value)) << enclosure.lo << ' ' << enclosure.hi;
    for (int i = 0; i < 2; ++i) {
      const double symbolic_partial = symbolic::evaluate(symbolic::differentiate(f, inputs[i]),
                                                         {{"x", point[0]}, {"y", point[1]}});
      EXPECT_NEAR(gradient[i], symbolic_partial, 1e-12 * (1 + std::fabs(symbolic_partial)))
          << "d/d" << inputs[i].name();
      EXPECT_TRUE(interval_gradient[i].contains(gradient[i])) << "d/d" << inputs[i].name();
    }
    ++checked;
  }
  EXPECT_EQ(checked, 13);  // sin cos tan sqrt exp log abs atan asin acos atan2 min max
}

// The reverse pass passes a sum's, a difference's and a negation's adjoint on without a product
// (their partials are exactly +-1): in doubles equal to the symbolic derivative, in intervals
// enclosing it over a box.
TEST(FunctionTable, ReversePassOfSumsDifferencesAndNegations) {
  symbolic::ExprPool pool;
  const std::vector<Expr> inputs{pool.variable("x"), pool.variable("y")};
  const Expr f = symbolic::parse(pool, "-x + sin(x) * y - cos(y) - x * x * y + exp(x) - y * y");
  const symbolic::Tape tape = symbolic::Tape::compile(std::span<const Expr>(&f, 1), inputs);
  const auto count = [&](symbolic::TapeOp op) {
    return std::ranges::count_if(tape.instructions(),
                                 [&](const symbolic::Instruction& in) { return in.op == op; });
  };
  ASSERT_GT(count(symbolic::TapeOp::kAdd), 0);
  ASSERT_GT(count(symbolic::TapeOp::kSub), 0);
  ASSERT_GT(count(symbolic::TapeOp::kNeg), 0);
  internal::GradientEvaluator<double> real(tape);
  internal::GradientEvaluator<Interval> interval(tape);
  const Interval box[] = {Interval{-0.5, 0.8}, Interval{0.1, 0.9}};
  Interval enclosure[2];
  (void)interval.value_and_gradient(box, enclosure);
  for (const auto& point : {std::array{0.3, 0.7}, std::array{-0.5, 0.1}, std::array{0.8, 0.9}}) {
    double gradient[2];
    (void)real.value_and_gradient(point, gradient);
    for (int i = 0; i < 2; ++i) {
      const double symbolic_partial = symbolic::evaluate(symbolic::differentiate(f, inputs[i]),
                                                         {{"x", point[0]}, {"y", point[1]}});
      EXPECT_NEAR(gradient[i], symbolic_partial, 1e-12) << "d/d" << inputs[i].name();
      EXPECT_TRUE(enclosure[i].contains(gradient[i])) << "d/d" << inputs[i].name();
    }
  }
}

}  // namespace
}  // namespace spar::bounds
