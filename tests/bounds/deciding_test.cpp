// BoundOptions::decide (the gradient's corner, branch and bound, NLopt only where those leave the
// verdict open) against the full bound, and BoundProblem::width_shares (phase 2's blame).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "random_expression.hpp"
#include "spar/bounds/bound.hpp"
#include "spar/bounds/inequality.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds {
namespace {

using symbolic::Expr;
using symbolic::ExprPool;

// Property: deciding `f rel t` never contradicts the full bound (where both decide, they agree),
// a satisfied verdict holds at random points of the box, and a violated one has a witness in
// the box where the inequality is false.
// A random inequality over a random box of x and y with deciding's options (a few budgets), and
// the full bound of its expression; a case the full bound finds infeasible or unbounded is
// discarded (RC_PRE).
struct DecidingCase {
  Expr f;
  Box box;
  BoundResult full;
  Inequality inequality;
  BoundOptions options;
};
DecidingCase random_deciding_case(ExprPool& pool) {
  DecidingCase c;
  c.f = testing::random_expression(pool);
  for (const char* name : {"x", "y"}) {
    const double lo = *rc::gen::inRange(-3000, 3000) / 1000.0;
    const double width = std::pow(10.0, *rc::gen::inRange(-600, 200) / 100.0);
    c.box.add(pool.variable(name), lo, lo + width);
  }
  c.full = bound(c.f, c.box, {.max_box_evaluations = 2000});
  RC_PRE(c.full.status != BoundStatus::kInfeasible && c.full.status != BoundStatus::kUnbounded);
  // Thresholds across the attained range and just outside the bound.
  const double at = *rc::gen::inRange(-2, 13) / 10.0;
  const double threshold = c.full.lo + at * (c.full.hi - c.full.lo);
  const Relation relation = *rc::gen::element(Relation::kLess, Relation::kLessEqual,
                                              Relation::kGreater, Relation::kGreaterEqual);
  c.inequality = {"q", c.f, relation, threshold};
  c.options.max_box_evaluations = *rc::gen::element<std::size_t>(8, 60, 2000);
  c.options.decide = DecisionTarget{relation, threshold};
  return c;
}

RC_GTEST_PROP(Deciding, AgreesWithTheFullBoundAndHoldsAtRandomPoints, ()) {
  ExprPool pool;
  const auto [f, box, full, inequality, options] = random_deciding_case(pool);
  const Relation relation = inequality.relation;
  const double threshold = inequality.threshold;
  const BoundResult decided = bound(f, box, options);
  const Verdict quick = decide(inequality, decided), reference = decide(inequality, full);
  RC_TAG(to_string(quick));
  if (quick != Verdict::kUndecided && reference != Verdict::kUndecided)
    RC_ASSERT(quick == reference);
  const symbolic::Tape tape = symbolic::Tape::compile(std::array{f}, box.variables);
  symbolic::TapeEvaluator<Interval> evaluator(tape);
  if (quick == Verdict::kSatisfied) {
    for (int k = 0; k < 16; ++k) {
      Interval p[2], out[1];
      for (int i = 0; i < 2; ++i) {
        const Interval range = box.ranges[i];
        p[i] = Interval{
            std::min(range.hi, range.lo + range.width() * (*rc::gen::inRange(0, 1001) / 1000.0))};
      }
      evaluator.evaluate(p, out);
      if (out[0].is_empty() || out[0].possibly_undefined) continue;
      // The enclosure of f at the point must allow the inequality to hold.
      const bool may_hold = upper_limit(relation) ? out[0].lo <= threshold : out[0].hi >= threshold;
      RC_ASSERT(may_hold);
    }
  }
  if (quick == Verdict::kViolated) {
    const std::vector<double> point = witness(inequality, decided);
    RC_ASSERT(point.size() == 2u);
    Interval p[2] = {Interval{point[0]}, Interval{point[1]}}, out[1];
    for (int i = 0; i < 2; ++i) RC_ASSERT(box.ranges[i].contains(point[i]));
    evaluator.evaluate(p, out);
    // f's value there (within out) breaks the inequality: out cannot lie wholly on its right side.
    const bool may_break = upper_limit(relation) ? out[0].hi >= threshold : out[0].lo <= threshold;
    RC_ASSERT(may_break);
  }
}

// Property: BoundOptions::stop_at_witness gives deciding's verdict; where it stopped (a witness
// broke the target before any box) the verdict is violated, no box was evaluated, and the bound
// still holds every value deciding attained; where it did not stop, the result is deciding's.
RC_GTEST_PROP(Deciding, StoppingAtAWitnessKeepsTheVerdictAndASoundBound, ()) {
  ExprPool pool;
  auto [f, box, full, inequality, options] = random_deciding_case(pool);
  const BoundResult deciding = bound(f, box, options);
  options.stop_at_witness = true;
  const BoundResult stopping = bound(f, box, options);
  RC_TAG(stopping.stopped_at_witness ? "stopped" : "went on");
  RC_ASSERT(decide(inequality, stopping) == decide(inequality, deciding));
  RC_ASSERT(!deciding.stopped_at_witness);
  if (stopping.stopped_at_witness) {
    RC_ASSERT(decide(inequality, stopping) == Verdict::kViolated);
    RC_ASSERT(stopping.evaluations == 0u);
    if (deciding.has_inner_range()) {
      RC_ASSERT(stopping.lo <= deciding.inner_lo);
      RC_ASSERT(stopping.hi >= deciding.inner_hi);
    }
  } else {
    RC_ASSERT(stopping.lo == deciding.lo);
    RC_ASSERT(stopping.hi == deciding.hi);
    RC_ASSERT(stopping.evaluations == deciding.evaluations);
    RC_ASSERT(witness(inequality, stopping) == witness(inequality, deciding));
  }
}

// f = sum x_i + 0.8 sum x_i x_(i+1) over [-1, 1]^12 (not monotone in any x_i there, so no face
// reduction) exceeds 20.5 only near the all-ones corner, where it takes its maximum 20.8: no
// midpoint reaches it and 2^12 corners are not tried at all; before the gradient's corner, branch
// and bound spent a quarter of its budget and NLopt's global search ran before the violation was
// found. The corner the centre's gradient points to is that corner: violated after the root box.
TEST(Deciding, TheGradientsCornerFindsAViolationNearACornerAtOnce) {
  ExprPool pool;
  Box box;
  std::vector<Expr> x, terms;
  for (int i = 0; i < 12; ++i) {
    x.push_back(pool.variable("x" + std::to_string(i)));
    box.add(x.back(), -1.0, 1.0);
    terms.push_back(x.back());
  }
  for (int i = 0; i + 1 < 12; ++i)
    terms.push_back(pool.product(std::array{pool.constant(0.8), x[i], x[i + 1]}));
  const Expr f = pool.sum(terms);
  const Inequality inequality{"q", f, Relation::kLessEqual, 20.5};
  BoundOptions options{.max_box_evaluations = 2000};
  options.decide = DecisionTarget{inequality.relation, inequality.threshold};
  const BoundResult decided = bound(f, box, options);
  EXPECT_EQ(decide(inequality, decided), Verdict::kViolated);
  EXPECT_LE(decided.evaluations, 1u);
  EXPECT_EQ(witness(inequality, decided), std::vector<double>(12, 1.0));
  // Asked to stop there: no box at all, the same witness, the natural enclosure [-20.8, 20.8]
  // (each product's enclosure [-0.8, 0.8] summed) as the bound.
  options.stop_at_witness = true;
  const BoundResult stopped = bound(f, box, options);
  EXPECT_TRUE(stopped.stopped_at_witness);
  EXPECT_EQ(stopped.evaluations, 0u);
  EXPECT_EQ(witness(inequality, stopped), std::vector<double>(12, 1.0));
  EXPECT_NEAR(stopped.hi, 20.8, 1e-12);
  EXPECT_NEAR(stopped.lo, -20.8, 1e-12);
}

TEST(WidthShares, AnAffineFunctionSharesItsWidthByCoefficientTimesWidth) {
  ExprPool pool;
  const Expr x = pool.variable("x"), y = pool.variable("y");
  BoundProblem problem(symbolic::parse(pool, "3*x + y + 1"), std::vector{x, y});
  const std::vector<Interval> box{{-1, 1}, {-2, 2}};
  const std::vector<double> shares = problem.width_shares(box, std::vector{0.0, 0.0});
  ASSERT_EQ(shares.size(), 2u);
  EXPECT_NEAR(shares[0], 0.6, 1e-12);  // 3 x width 2 of 10
  EXPECT_NEAR(shares[1], 0.4, 1e-12);
}

// Pinning either factor of x·y at 0 removes its whole width: first order over the box, each term
// G_i·(X_i - 0) is as wide as the other, so each gets half.
TEST(WidthShares, AProductAtZeroSharesEvenly) {
  ExprPool pool;
  const Expr x = pool.variable("x"), y = pool.variable("y");
  BoundProblem problem(x * y, std::vector{x, y});
  const std::vector<double> shares =
      problem.width_shares(std::vector<Interval>{{-1, 1}, {-2, 2}}, std::vector{0.0, 0.0});
  EXPECT_NEAR(shares[0], 0.5, 1e-12);
  EXPECT_NEAR(shares[1], 0.5, 1e-12);
}

// sqrt's gradient has no finite enclosure at 0: the natural extension stands in (pinning x at 0
// leaves only y's width).
TEST(WidthShares, WithoutAFiniteGradientTheNaturalExtensionStandsIn) {
  ExprPool pool;
  const Expr x = pool.variable("x"), y = pool.variable("y");
  BoundProblem problem(symbolic::parse(pool, "sqrt(x) + y"), std::vector{x, y});
  const std::vector<double> shares =
      problem.width_shares(std::vector<Interval>{{0, 4}, {-1, 1}}, std::vector{0.0, 0.0});
  EXPECT_NEAR(shares[0], 0.5, 1e-12);  // width 4 -> 2
  EXPECT_NEAR(shares[1], 0.5, 1e-12);  // width 4 -> 2
}

TEST(WidthShares, AConstantOrAZeroWidthBoxGivesNoShares) {
  ExprPool pool;
  const Expr x = pool.variable("x");
  BoundProblem problem(x * x, std::vector{x});
  EXPECT_EQ(problem.width_shares(std::vector<Interval>{{0, 0}}, std::vector{0.0}),
            std::vector<double>{0.0});
}

TEST(WidthShares, RefusesAPinOutsideItsRangeOrAWrongCount) {
  ExprPool pool;
  const Expr x = pool.variable("x");
  BoundProblem problem(x * x, std::vector{x});
  EXPECT_THROW((void)problem.width_shares(std::vector<Interval>{{1, 2}}, std::vector{0.0}),
               BoundsError);
  EXPECT_THROW((void)problem.width_shares(std::vector<Interval>{{-1, 2}}, std::vector<double>{}),
               BoundsError);
}

}  // namespace
}  // namespace spar::bounds
