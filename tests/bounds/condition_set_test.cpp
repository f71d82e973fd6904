// BoundProblem (a compiled, reusable bound) and ConditionSet (many inequalities, one tape, natural
// pass first, escalation of the rest): same answers as the free bound(), whatever the order of
// calls, and the natural pass decides what it can without escalating.
#include "spar/bounds/condition_set.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "random_expression.hpp"
#include "spar/symbolic/parse.hpp"

namespace spar::bounds {
namespace {

using symbolic::Expr;
using symbolic::ExprPool;
using symbolic::parse;

// Every field, exactly: a reused problem must give the fresh answer bit for bit.
::testing::AssertionResult same_result(const BoundResult& a, const BoundResult& b) {
  const auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  if (same(a.lo, b.lo) && same(a.hi, b.hi) && same(a.inner_lo, b.inner_lo) &&
      same(a.inner_hi, b.inner_hi) && a.argmin == b.argmin && a.argmax == b.argmax &&
      a.status == b.status && a.possibly_undefined == b.possibly_undefined &&
      a.evaluations == b.evaluations) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "[" << a.lo << ", " << a.hi << "] inner [" << a.inner_lo << ", " << a.inner_hi << "] "
         << to_string(a.status) << ' ' << a.evaluations << " evaluations vs [" << b.lo << ", "
         << b.hi << "] inner [" << b.inner_lo << ", " << b.inner_hi << "] " << to_string(b.status)
         << ' ' << b.evaluations << " evaluations";
}

Box box_of(const std::vector<Expr>& variables, const std::vector<Interval>& ranges) {
  Box box;
  for (std::size_t i = 0; i < variables.size(); ++i) {
    box.add(variables[i], ranges[i].lo, ranges[i].hi);
  }
  return box;
}

TEST(ConditionSet, NaturalPassDecidesWhatItCanWithoutEscalating) {
  ExprPool pool;
  const Expr x = pool.variable("x");
  ConditionSet set({{"positive", parse(pool, "x^2 + 1"), Relation::kGreater, 0.0},
                    {"centre fails", parse(pool, "x + 1"), Relation::kLess, 0.5},
                    {"needs bisection", parse(pool, "x - x^2"), Relation::kLessEqual, 0.26}},
                   {x});
  const std::vector<Interval> box{{0.0, 1.0}};
  const std::vector<ConditionCheck> checks = set.check(box);
  ASSERT_EQ(checks.size(), 3u);
  // [1, 2] > 0 by the natural extension alone.
  EXPECT_EQ(checks[0].verdict, Verdict::kSatisfied);
  EXPECT_FALSE(checks[0].escalated);
  EXPECT_EQ(checks[0].bound.evaluations, 1u);
  // x + 1 = 1.5 at the centre: violated there, final without escalation.
  EXPECT_EQ(checks[1].verdict, Verdict::kViolated);
  EXPECT_FALSE(checks[1].escalated);
  EXPECT_EQ(checks[1].witness, std::vector<double>{0.5});
  // x - x^2 naturally encloses [-1, 1] and is 0.25 at the centre: undecided until bounded
  // (max 0.25 at x = 0.5).
  EXPECT_EQ(checks[2].verdict, Verdict::kSatisfied);
  EXPECT_TRUE(checks[2].escalated);
  EXPECT_LE(checks[2].bound.hi, 0.26);
  EXPECT_GE(checks[2].bound.hi, 0.25);
}

TEST(ConditionSet, EscalatingViolationsFindsTheWorstWitness) {
  ExprPool pool;
  const Expr x = pool.variable("x");
  ConditionSet set({{"below", parse(pool, "x + 1"), Relation::kLess, 0.5}}, {x});
  const std::vector<Interval> box{{0.0, 1.0}};
  const ConditionCheck check = set.check(box, {}, Escalation::kNotSatisfied)[0];
  EXPECT_EQ(check.verdict, Verdict::kViolated);
  EXPECT_TRUE(check.escalated);
  EXPECT_EQ(check.witness, std::vector<double>{1.0});  // x + 1 is largest at x = 1
  EXPECT_GE(check.bound.inner_hi, 2.0);
}

TEST(ConditionSet, ExpressionsShareOneTape) {
  // Checking a set equals checking each inequality alone, over the same box.
  ExprPool pool;
  const std::vector<Expr> variables{pool.variable("a"), pool.variable("t")};
  const Expr shared = parse(pool, "a*cos(t) + sin(t)");
  const std::vector<Inequality> inequalities{
      {"upper", shared, Relation::kLess, 1.5},
      {"lower", shared * 2 - 1, Relation::kGreaterEqual, -2.0},
      {"product", shared * shared, Relation::kLessEqual, 0.3}};
  ConditionSet set(inequalities, variables);
  const std::vector<Interval> ranges{{0.5, 1.0}, {-0.3, 0.4}};
  const std::vector<ConditionCheck> checks = set.check(ranges);
  for (std::size_t k = 0; k < inequalities.size(); ++k) {
    ConditionSet alone({inequalities[k]}, variables);
    const ConditionCheck single = alone.check(ranges)[0];
    EXPECT_EQ(checks[k].verdict, single.verdict) << inequalities[k].name;
    EXPECT_TRUE(same_result(checks[k].bound, single.bound)) << inequalities[k].name;
  }
}

TEST(ConditionSet, RejectsMalformedInputWithMessages) {
  ExprPool pool;
  const Expr x = pool.variable("x");
  const auto message = [](auto&& make) -> std::string {
    try {
      make();
    } catch (const BoundsError& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message([&] {
              ConditionSet({{"q", parse(pool, "x + y"), Relation::kLess, 0}}, {x});
            }),
            "unknown variable 'y' in inequality 'q': give it a range");
  EXPECT_EQ(message([&] {
              ConditionSet({{"q", x, Relation::kLess, std::nan("")}}, {x});
            }),
            "inequality 'q': the threshold must be a finite number");
  EXPECT_EQ(message([&] {
              ConditionSet({{"q", Expr{}, Relation::kLess, 0}}, {x});
            }),
            "inequality 'q' has no expression");
  EXPECT_EQ(message([&] {
              ConditionSet({{"q", x, Relation::kLess, 0}}, {x, x});
            }),
            "variable 'x' is in the box twice");
  ConditionSet set({{"q", x, Relation::kLess, 0}}, {x});
  EXPECT_EQ(message([&] { (void)set.check(std::vector<Interval>{}); }), "expected 1 ranges, got 0");
  EXPECT_EQ(message([&] {
              (void)set.check(std::vector<Interval>{{2e-9, 1e-9}});
            }),
            "range of 'x' is empty: lower bound 2e-09 > upper bound 1e-09");
  EXPECT_EQ(message([&] {
              (void)set.check(std::vector<Interval>{{0, std::numeric_limits<double>::infinity()}});
            }),
            "range of 'x' must be finite");
}

// Options for the properties: a box budget small enough to be quick.
constexpr BoundOptions kPropertyOptions{.tolerance = 1e-3, .max_box_evaluations = 4000};

Relation random_relation() {
  constexpr Relation relations[] = {Relation::kLess, Relation::kLessEqual, Relation::kGreater,
                                    Relation::kGreaterEqual};
  return relations[*rc::gen::inRange(0, 4)];
}

std::vector<Interval> random_ranges(std::size_t count) {
  std::vector<Interval> ranges;
  for (std::size_t i = 0; i < count; ++i) {
    const double lo = *rc::gen::inRange(-3000, 3000) / 1000.0;
    ranges.push_back({lo, lo + *rc::gen::inRange(0, 3000) / 1000.0});
  }
  return ranges;
}

// Property: every verdict of a ConditionSet equals decide() on the free bound() of that
// inequality alone (the natural pass only short-cuts answers bound() agrees with).
RC_GTEST_PROP(ConditionSet, VerdictsEqualIndividualBoundVerdicts, ()) {
  ExprPool pool;
  const std::vector<Expr> variables{pool.variable("x"), pool.variable("y")};
  std::vector<Inequality> inequalities;
  const int count = *rc::gen::inRange(1, 4);
  for (int k = 0; k < count; ++k) {
    const Expr f = testing::random_expression(pool);
    inequalities.push_back(
        {"q" + std::to_string(k), f, random_relation(), *rc::gen::inRange(-2000, 2000) / 1000.0});
  }
  const std::vector<Interval> ranges = random_ranges(variables.size());
  ConditionSet set(inequalities, variables);
  const std::vector<ConditionCheck> checks = set.check(ranges, kPropertyOptions);
  RC_ASSERT(checks.size() == inequalities.size());
  const Box box = box_of(variables, ranges);
  for (std::size_t k = 0; k < inequalities.size(); ++k) {
    const BoundResult alone = bound(inequalities[k].expression, box, kPropertyOptions);
    RC_ASSERT(checks[k].verdict == decide(inequalities[k], alone));
    if (checks[k].escalated) RC_ASSERT(same_result(checks[k].bound, alone));
  }
  RC_TAG(to_string(checks[0].verdict), checks[0].escalated ? "escalated" : "natural");
}

// Property: decide_all() gives what deciding every inequality would (a fresh set's check() with
// Escalation::kDecide and the quick budget, then each one still undecided decided alone with the
// full budget), on sets where inequalities share expressions (the two sides of a bound) and
// whatever the set was asked before; it gives up exactly when at least `give_up_after` are not
// satisfied. The thresholds lie just outside each expression's tight range over the box, so many
// proofs need the full budget and some fail.
RC_GTEST_PROP(ConditionSet, DecideAllEqualsDecidingEachAndGivesUpOnCount, ()) {
  ExprPool pool;
  const std::vector<Expr> variables{pool.variable("x"), pool.variable("y")};
  const std::vector<Interval> ranges = random_ranges(variables.size());
  const Box box = box_of(variables, ranges);
  std::vector<Inequality> inequalities;
  const int count = *rc::gen::inRange(1, 4);
  for (int k = 0; k < count; ++k) {
    // Dependent occurrences of x and y: the natural enclosure is loose, branch and bound needed.
    const double a = *rc::gen::inRange(-20, 20) / 10.0, b = *rc::gen::inRange(-20, 20) / 10.0;
    const Expr f = parse(pool, std::to_string(a) + "*x*(1 - y) + x*y + sin(x + " +
                                   std::to_string(b) + "*y) - x^2*y");
    const BoundResult tight = bound(f, box, {.tolerance = 1e-9, .max_box_evaluations = 2000});
    const double margin = (tight.hi - tight.lo) * *rc::gen::element(-1e-3, 1e-6, 1e-5, 1e-4);
    if (!std::isfinite(margin)) continue;
    inequalities.push_back({"above", f, Relation::kLessEqual, tight.hi + margin});
    inequalities.push_back({"below", f, Relation::kGreaterEqual, tight.lo - margin});
  }
  RC_PRE(!inequalities.empty());
  const BoundOptions quick{.tolerance = 1e-2, .max_box_evaluations = 4};
  const BoundOptions full{.tolerance = 1e-3, .max_box_evaluations = 400};
  ConditionSet fresh(inequalities, variables);
  std::vector<ConditionCheck> expected = fresh.check(ranges, quick, Escalation::kDecide);
  std::size_t not_satisfied = 0;
  bool full_proved = false;
  for (std::size_t k = 0; k < inequalities.size(); ++k) {
    if (expected[k].verdict == Verdict::kUndecided) {
      BoundOptions deciding = full;
      deciding.decide = DecisionTarget{inequalities[k].relation, inequalities[k].threshold};
      expected[k].bound =
          BoundProblem(inequalities[k].expression, variables).bound(ranges, deciding);
      expected[k].verdict = decide(inequalities[k], expected[k].bound);
      full_proved |= expected[k].verdict == Verdict::kSatisfied;
    }
    not_satisfied += expected[k].verdict != Verdict::kSatisfied;
  }
  ConditionSet reused(inequalities, variables);
  (void)reused.check(random_ranges(variables.size()), full, Escalation::kNotSatisfied);
  const auto give_up_after =
      static_cast<std::size_t>(*rc::gen::inRange(1, static_cast<int>(inequalities.size()) + 2));
  const std::optional<std::vector<ConditionCheck>> checks =
      reused.decide_all(ranges, quick, full, give_up_after);
  RC_ASSERT(checks.has_value() == (not_satisfied < give_up_after));
  if (checks) {
    for (std::size_t k = 0; k < inequalities.size(); ++k) {
      RC_ASSERT((*checks)[k].verdict == expected[k].verdict);
      RC_ASSERT(same_result((*checks)[k].bound, expected[k].bound));
    }
  }
  RC_TAG(checks ? "decided" : "gave up", full_proved ? "the full budget proved one" : "");
}

// Property: one BoundProblem over a sequence of boxes (with repeats, so cached rewrites are hit)
// gives exactly the fresh bound() of each box, and so does a ConditionSet reused over them.
RC_GTEST_PROP(BoundProblem, ReuseOverManyBoxesEqualsFreshProblems, ()) {
  ExprPool pool;
  const std::vector<Expr> variables{pool.variable("x"), pool.variable("y")};
  const Expr f = testing::random_expression(pool);
  // A small budget, so the staged effort often reaches SMP's rewrite.
  const BoundOptions options{.tolerance = 1e-6, .max_box_evaluations = 400};
  std::vector<std::vector<Interval>> boxes;
  for (int i = 0; i < 3; ++i) boxes.push_back(random_ranges(variables.size()));
  BoundProblem problem(f, variables);
  ConditionSet set({{"q", f, Relation::kLessEqual, 0.0}}, variables);
  for (int call = 0; call < 6; ++call) {
    const std::vector<Interval>& ranges = boxes[*rc::gen::inRange(0, 3)];
    const BoundResult fresh = bound(f, box_of(variables, ranges), options);
    RC_ASSERT(same_result(problem.bound(ranges, options), fresh));
    const ConditionCheck check = set.check(ranges, options)[0];
    if (check.escalated) RC_ASSERT(same_result(check.bound, fresh));
  }
}

TEST(BoundProblem, RepeatedCallsAreIdentical) {
  // Four trigonometric variables at --tol 0: the case whose inner bounds used to vary run to run.
  ExprPool pool;
  const std::vector<Expr> variables{pool.variable("a"), pool.variable("b"), pool.variable("c"),
                                    pool.variable("d")};
  const Expr f = parse(pool, "sin(a)*cos(b) + cos(c)*sin(d) - sin(a + d)*cos(b - c)");
  const std::vector<Interval> ranges(4, Interval{-2.0, 2.0});
  const BoundOptions options{.tolerance = 0.0, .max_box_evaluations = 20'000};
  BoundProblem problem(f, variables);
  const BoundResult first = problem.bound(ranges, options);
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(same_result(problem.bound(ranges, options), first));
  EXPECT_TRUE(same_result(bound(f, box_of(variables, ranges), options), first));
}

TEST(BoundProblem, ConstrainedGlobalSearchIsDeterministic) {
  // With constraints the global inner search is the original DIRECT-L (no random numbers): two
  // problems, and two calls of one, agree bit for bit.
  ExprPool pool;
  const std::vector<Expr> variables{pool.variable("x"), pool.variable("y")};
  const Expr f = parse(pool, "x*y - sin(3*x) + y^2");
  const Constraint constraints[] = {{parse(pool, "x^2 + y^2 - 1"), Relation::kLessEqual}};
  const std::vector<Interval> ranges{{-1.5, 1.5}, {-1.5, 1.5}};
  BoundProblem one(f, variables, constraints), other(f, variables, constraints);
  const BoundResult first = one.bound(ranges);
  EXPECT_FALSE(first.argmax.empty());
  EXPECT_TRUE(same_result(one.bound(ranges), first));
  EXPECT_TRUE(same_result(other.bound(ranges), first));
}

TEST(BoundProblem, RejectsWrongRangesWithMessages) {
  ExprPool pool;
  const Expr x = pool.variable("x");
  BoundProblem problem(x * x, std::vector{x});
  try {
    (void)problem.bound(std::vector<Interval>{{0, 1}, {0, 1}});
    ADD_FAILURE() << "expected BoundsError";
  } catch (const BoundsError& error) {
    EXPECT_STREQ(error.what(), "expected 1 ranges, got 2");
  }
  try {
    (void)BoundProblem(x + pool.variable("y"), std::vector{x});
    ADD_FAILURE() << "expected BoundsError";
  } catch (const BoundsError& error) {
    EXPECT_STREQ(error.what(), "unknown variable 'y' in the expression: give it a range");
  }
}

}  // namespace
}  // namespace spar::bounds
