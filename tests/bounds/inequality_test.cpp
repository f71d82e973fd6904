// decide(): the verdict table for every relation, strict and non-strict, at and around the
// boundary, plus the cases that must never be "satisfied" (possibly undefined, infeasible) and
// never "violated" (no witness).
#include "spar/bounds/inequality.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "spar/symbolic/expr.hpp"

namespace spar::bounds {
namespace {

// lo = 1 <= inner_lo = 2 <= inner_hi = 3 <= hi = 4, witnesses at x = 0 and x = 1.
BoundResult one_to_four() {
  BoundResult r;
  r.lo = 1;
  r.inner_lo = 2;
  r.inner_hi = 3;
  r.hi = 4;
  r.argmin = {0.0};
  r.argmax = {1.0};
  r.argmin_value = Interval{1.9, 2.0};  // f(argmin) <= 2
  r.argmax_value = Interval{3.0, 3.1};  // f(argmax) >= 3
  return r;
}

struct VerdictRow {
  Relation relation;
  double threshold;
  Verdict expected;
};

TEST(Decide, VerdictTableOverEveryRelationAndBoundary) {
  symbolic::ExprPool pool;
  const BoundResult r = one_to_four();
  const VerdictRow rows[] = {
      // f < t: proved iff hi < t; violated iff the attained inner_hi >= t.
      {Relation::kLess, 4.5, Verdict::kSatisfied},
      {Relation::kLess, 4.0, Verdict::kUndecided},  // hi = t: strict needs strict proof
      {Relation::kLess, 3.5, Verdict::kUndecided},
      {Relation::kLess, 3.0, Verdict::kViolated},  // f(argmax) >= 3 is not < 3
      {Relation::kLess, 0.0, Verdict::kViolated},
      // f <= t: proved iff hi <= t; violated iff inner_hi > t.
      {Relation::kLessEqual, 4.0, Verdict::kSatisfied},
      {Relation::kLessEqual, 3.5, Verdict::kUndecided},
      {Relation::kLessEqual, 3.0, Verdict::kUndecided},  // f(argmax) may be exactly 3
      {Relation::kLessEqual, 2.9, Verdict::kViolated},
      // f > t: proved iff lo > t; violated iff the attained inner_lo <= t.
      {Relation::kGreater, 0.5, Verdict::kSatisfied},
      {Relation::kGreater, 1.0, Verdict::kUndecided},  // lo = t: strict needs strict proof
      {Relation::kGreater, 1.5, Verdict::kUndecided},
      {Relation::kGreater, 2.0, Verdict::kViolated},
      {Relation::kGreater, 5.0, Verdict::kViolated},
      // f >= t: proved iff lo >= t; violated iff inner_lo < t.
      {Relation::kGreaterEqual, 1.0, Verdict::kSatisfied},
      {Relation::kGreaterEqual, 1.5, Verdict::kUndecided},
      {Relation::kGreaterEqual, 2.0, Verdict::kUndecided},  // f(argmin) may be exactly 2
      {Relation::kGreaterEqual, 2.1, Verdict::kViolated},
  };
  for (const VerdictRow& row : rows) {
    const Inequality q{"q", pool.variable("x"), row.relation, row.threshold};
    EXPECT_EQ(decide(q, r), row.expected)
        << "f " << to_string(row.relation) << ' ' << row.threshold << ": got "
        << to_string(decide(q, r)) << ", expected " << to_string(row.expected);
  }
}

using symbolic::Expr;

TEST(Decide, PossiblyUndefinedIsNeverSatisfiedButCanBeViolated) {
  symbolic::ExprPool pool;
  BoundResult r = one_to_four();
  r.possibly_undefined = true;
  const Expr x = pool.variable("x");
  EXPECT_EQ(decide({"q", x, Relation::kLess, 10}, r), Verdict::kUndecided);
  EXPECT_EQ(decide({"q", x, Relation::kGreaterEqual, -10}, r), Verdict::kUndecided);
  // The witness is a point where f is defined and attains the value: still a violation.
  EXPECT_EQ(decide({"q", x, Relation::kLess, 0}, r), Verdict::kViolated);
}

TEST(Decide, InfeasibleResultProvesNothing) {
  symbolic::ExprPool pool;
  BoundResult r;
  r.lo = std::numeric_limits<double>::infinity();
  r.hi = -r.lo;
  r.inner_lo = r.lo;
  r.inner_hi = r.hi;
  r.status = BoundStatus::kInfeasible;
  for (Relation relation :
       {Relation::kLess, Relation::kLessEqual, Relation::kGreater, Relation::kGreaterEqual}) {
    EXPECT_EQ(decide({"q", pool.variable("x"), relation, 0}, r), Verdict::kUndecided)
        << to_string(relation);
  }
}

TEST(Decide, ViolationsAreReadFromTheRigorousWitnessValues) {
  // f is constant within rounding: the witness enclosures cross, the inner bounds are averaged
  // to 2.5, but only the enclosures decide: f(argmax) >= 2 and f(argmin) <= 3 exactly.
  symbolic::ExprPool pool;
  BoundResult r = one_to_four();
  r.argmin_value = Interval{2.0, 3.0};
  r.argmax_value = Interval{2.0, 3.0};
  r.inner_lo = r.inner_hi = 2.5;
  const Expr x = pool.variable("x");
  EXPECT_EQ(decide({"q", x, Relation::kLessEqual, 2.4}, r), Verdict::kUndecided);
  EXPECT_EQ(decide({"q", x, Relation::kLessEqual, 1.9}, r), Verdict::kViolated);
  EXPECT_EQ(decide({"q", x, Relation::kGreaterEqual, 2.6}, r), Verdict::kUndecided);
  EXPECT_EQ(decide({"q", x, Relation::kGreaterEqual, 3.1}, r), Verdict::kViolated);
}

TEST(Decide, NoWitnessMeansNoViolation) {
  symbolic::ExprPool pool;
  BoundResult r = one_to_four();
  r.argmin.clear();
  r.argmax.clear();
  r.argmin_value = r.argmax_value = Interval::empty();
  EXPECT_EQ(decide({"q", pool.variable("x"), Relation::kLess, 0}, r), Verdict::kUndecided);
  EXPECT_EQ(decide({"q", pool.variable("x"), Relation::kGreater, 5}, r), Verdict::kUndecided);
}

TEST(Decide, WitnessIsArgmaxForUpperAndArgminForLowerRelations) {
  symbolic::ExprPool pool;
  const BoundResult r = one_to_four();
  const Expr x = pool.variable("x");
  EXPECT_EQ(witness({"q", x, Relation::kLess, 0}, r), r.argmax);
  EXPECT_EQ(witness({"q", x, Relation::kLessEqual, 0}, r), r.argmax);
  EXPECT_EQ(witness({"q", x, Relation::kGreater, 0}, r), r.argmin);
  EXPECT_EQ(witness({"q", x, Relation::kGreaterEqual, 0}, r), r.argmin);
}

TEST(Decide, NamesOfVerdictsAndRelations) {
  EXPECT_STREQ(to_string(Verdict::kSatisfied), "satisfied");
  EXPECT_STREQ(to_string(Verdict::kViolated), "violated");
  EXPECT_STREQ(to_string(Verdict::kUndecided), "undecided");
  EXPECT_STREQ(to_string(Relation::kLess), "<");
  EXPECT_STREQ(to_string(Relation::kGreaterEqual), ">=");
}

}  // namespace
}  // namespace spar::bounds
