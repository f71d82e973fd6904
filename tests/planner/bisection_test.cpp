// Phase 2's one bisection (planner/uncertainty/internal/bisection.hpp): the guided search gives
// the plain bisection's answer for every monotone predicate whatever it is told, within three
// times the bisection's probes, and in three probes when told the answer.
#include "spar/planner/uncertainty/internal/bisection.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace spar::planner::internal {
namespace {

// A predicate that holds up to `answer` and counts how often it was asked.
struct Monotone {
  double answer;
  int probes{0};
  bool operator()(double x) {
    ++probes;
    return x <= answer;
  }
};

RC_GTEST_PROP(Bisection, TheGuidedSearchGivesTheBisectionsAnswerWhateverItIsTold, ()) {
  // The binary runs few cases (phase 2's end-to-end properties are slow): many searches in each.
  for (int search = 0; search < 200; ++search) {
    const int iterations = *rc::gen::inRange(1, 17);
    // Powers of two: the grid exact in doubles, as the header asks.
    const double hi = *rc::gen::element(0.5, 1.0, 8.0, 1024.0);
    // Answers on the grid, between grid values, at and beyond both ends.
    const double answer = *rc::gen::oneOf(
        rc::gen::map(rc::gen::inRange(-1, (1 << iterations) + 2),
                     [=](int k) { return hi * k / std::ldexp(1.0, iterations); }),
        rc::gen::map(rc::gen::inRange(0, 1'000'001), [=](int k) { return hi * k / 1e6; }));
    if (answer < 0) continue;  // the caller checks that lo holds
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<double> told =
        *rc::gen::nonEmpty(rc::gen::container<std::vector<double>>(rc::gen::oneOf(
            rc::gen::element(nan, inf, -inf, -1.0, 2 * hi, answer),
            rc::gen::map(rc::gen::inRange(0, 1'001), [=](int k) { return hi * k / 1e3; }))));
    Monotone plain{answer}, guided{answer};
    const double expected = largest_holding(0.0, hi, iterations, plain);
    std::size_t next = 0;
    const double got = largest_holding(0.0, hi, iterations, guided, [&](double good, double bad) {
      RC_ASSERT(good < bad);
      return told[next++ % told.size()];
    });
    RC_ASSERT(got == expected);
    RC_ASSERT(guided.probes <= 3 * iterations + 1);
  }
}

TEST(Bisection, ToldTheAnswerTheGuidedSearchProbesTwiceAfterTheTop) {
  for (const double answer : {0.3, 1.486, 2.0, 7.9}) {
    Monotone plain{answer}, guided{answer};
    const double expected = largest_holding(0.0, 8.0, 12, plain);
    EXPECT_EQ(largest_holding(0.0, 8.0, 12, guided, [&](double, double) { return answer; }),
              expected)
        << answer;
    EXPECT_EQ(plain.probes, 13) << answer;
    // hi, the grid value at or below the answer, the one above it.
    EXPECT_EQ(guided.probes, 3) << answer;
  }
}

}  // namespace
}  // namespace spar::planner::internal
