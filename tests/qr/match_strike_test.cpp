#include "spar/qr/match_strike.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

namespace spar::qr {
namespace {

TEST(MatchStart, ParsesKeysInAnyOrderAndKeepsDefaults) {
  EXPECT_EQ(parse_match_start("gap=12,depth=9.5"), (std::vector<double>{9.5, 20.0, 12.0}));
  EXPECT_EQ(parse_match_start("depth=8,angle=-20,gap=20"), (std::vector<double>{8, -20, 20}));
}

void expect_start_error(const std::string& text, const std::string& message) {
  try {
    (void)parse_match_start(text);
    FAIL() << "expected QrError for " << text;
  } catch (const QrError& error) {
    EXPECT_EQ(error.what(), message);
  }
}

TEST(MatchStart, BadStringsGiveClearErrors) {
  expect_start_error("depth8", "bad --start token 'depth8': expected key=value, e.g. depth=8");
  expect_start_error("speed=3", "bad --start key 'speed': expected depth, angle or gap");
  expect_start_error("depth=8mm", "bad --start value '8mm' for depth: expected a number");
  expect_start_error("angle=", "bad --start value '' for angle: expected a number");
  expect_start_error("gap=25", "--start gap=25 is outside the physical limits [1, 20] mm");
}

TEST(SimulatedWorld, PaperLikeWorldBehavesLikeTheSeedsRun) {
  const SimulatedWorld world = SimulatedWorld::paper_like();
  const Outcome nothing{false, false, false};
  EXPECT_EQ(world.nominal({8, 20, 20}), nothing);
  EXPECT_EQ(world.nominal({11, 20, 20}), nothing);
  EXPECT_EQ(world.nominal({12.5, 20, 20}), (Outcome{false, true, std::nullopt}));
  EXPECT_EQ(world.nominal({14, 10, 20}), (Outcome{false, false, true}));
  EXPECT_EQ(world.nominal({14, -50, 20}), (Outcome{true, std::nullopt, std::nullopt}));
  EXPECT_NEAR(world.parameters().landmark_degrees(), -25.0, 1e-9);
}

// Property: every random world has a region that succeeds at the maximum gap, so a planner that
// fails on it has itself to blame.
RC_GTEST_PROP(SimulatedWorldProperty, RandomWorldsAreSolvable, (std::uint64_t seed)) {
  const SimulatedWorld world = SimulatedWorld::random(seed);
  bool solvable = false;
  for (double depth = 2; depth <= 20 && !solvable; depth += 0.5) {
    for (double angle = -60; angle <= 60 && !solvable; angle += 1) {
      solvable = world.nominal({depth, angle, 20}) == Outcome{false, false, true};
    }
  }
  RC_ASSERT(solvable);
}

}  // namespace
}  // namespace spar::qr
