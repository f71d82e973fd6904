#include "spar/qr/planner.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include "spar/qr/match_strike.hpp"

namespace spar::qr {
namespace {

Planner match_planner() {
  MatchStrikeModel model = match_strike_model();
  return Planner(model.network, model.controls, model.goals);
}

const Outcome kNoIgnitionNoBreak{false, false, false};
const Outcome kBreakOnStrike{false, true, std::nullopt};
const Outcome kBreakOnStart{true, std::nullopt, std::nullopt};

// Seed, section 7: the first trial neither ignites nor breaks -> increase the digging depth; the
// first break on the strike -> decrease the angle.
TEST(Planner, PaperWorldFirstDeepensThenTurnsTheAngleDown) {
  Planner planner = match_planner();
  SimulatedWorld world = SimulatedWorld::paper_like();
  const RunResult run = run_trials(planner, kSeedStart, world.as_function(), 40);
  ASSERT_GE(run.trials.size(), 2u);
  EXPECT_EQ(run.trials[0].outcome, kNoIgnitionNoBreak);
  ASSERT_TRUE(run.trials[0].plan);
  EXPECT_EQ(run.trials[0].plan->control, kDiggingDepth);
  EXPECT_EQ(run.trials[0].plan->direction, Sign::kPlus);
  const auto strike_break = std::find_if(run.trials.begin(), run.trials.end(), [](const Trial& t) {
    return t.outcome == kBreakOnStrike;
  });
  ASSERT_NE(strike_break, run.trials.end()) << "the paper-like world breaks on the strike";
  ASSERT_TRUE(strike_break->plan);
  EXPECT_EQ(strike_break->plan->control, kAngle);
  EXPECT_EQ(strike_break->plan->direction, Sign::kMinus);
  EXPECT_EQ(run.status, Status::kSuccess);
}

// The no-ignition trial asserts "depth must exceed 8" for every angle and for gaps up to 20.
TEST(Planner, NoIgnitionAssertsADepthLimitVisibleAtLowerGaps) {
  Planner planner = match_planner();
  const Trial& trial = planner.record_and_plan(kSeedStart, kNoIgnitionNoBreak);
  ASSERT_EQ(trial.limits_asserted.size(), 1u);
  const Limit& limit = trial.limits_asserted.front();
  EXPECT_EQ(limit.control, kDiggingDepth);
  EXPECT_EQ(limit.side, Side::kLower);
  EXPECT_DOUBLE_EQ(limit.bound, 8.0);
  EXPECT_EQ(limit.visibility[kAngle], Visibility::kEverywhere);
  EXPECT_EQ(limit.visibility[kJumpingGap], Visibility::kAtMost);
  EXPECT_TRUE(limit.excludes({7.0, -40.0, 15.0}, planner.controls()));
  EXPECT_FALSE(limit.excludes({9.0, 20.0, 20.0}, planner.controls()));
  // The gap is at its physical maximum: at-maximum, so heat can only rise through the force.
  EXPECT_EQ(trial.marks.at_maximum, std::vector<int>{kJumpingGap});
  EXPECT_DOUBLE_EQ(trial.plan->to, 8.0 + 1.5);
}

// Below the maximum gap the velocity is the unmarked cause of heat (force also drives the breaking
// moments, so it resists change): the planner opens the gap first.
TEST(Planner, PrefersTheCauseThatDisturbsNoOtherResult) {
  Planner planner = match_planner();
  const Trial& trial = planner.record_and_plan({8.0, 20.0, 10.0}, kNoIgnitionNoBreak);
  ASSERT_TRUE(trial.plan);
  EXPECT_EQ(trial.plan->control, kJumpingGap);
  EXPECT_EQ(trial.plan->direction, Sign::kPlus);
}

// Breaks on the strike at every angle above -10, on the move to start below: the limits close in
// on the angle until they overlap, then the planner must change another control (the depth, down).
TEST(Planner, OverlappingLimitsForceAnotherControl) {
  Planner planner = match_planner();
  std::vector<double> point{12.0, 20.0, 20.0};
  std::optional<PlannedChange> last;
  for (int n = 0; n < 30; ++n) {
    const Outcome outcome = point[kAngle] > -10 ? kBreakOnStrike : kBreakOnStart;
    const Trial& trial = planner.record_and_plan(point, outcome);
    ASSERT_EQ(trial.status, Status::kContinue) << "trial " << trial.number;
    last = trial.plan;
    if (last->control != kAngle) break;
    point[kAngle] = last->to;
  }
  ASSERT_TRUE(last);
  EXPECT_EQ(last->control, kDiggingDepth);
  EXPECT_EQ(last->direction, Sign::kMinus);
  const Trial& final_trial = planner.history().trials().back();
  EXPECT_EQ(final_trial.marks.at_maximum.size() + final_trial.marks.at_minimum.size(), 3u)
      << "angle blocked both ways and the gap at its maximum";
}

// Nothing ever ignites: once depth and gap are at their maxima, no direction is left, and the
// blocking limits are the physical ones.
TEST(Planner, ReportsNoDirectionLeftWithTheBlockingLimits) {
  Planner planner = match_planner();
  const RunResult run = run_trials(
      planner, {19.0, 0.0, 20.0}, [](const std::vector<double>&) { return kNoIgnitionNoBreak; },
      10);
  ASSERT_EQ(run.status, Status::kNoDirectionLeft);
  ASSERT_EQ(run.trials.size(), 2u);
  const std::vector<Blocking>& blocking = run.trials.back().blocking;
  auto blocked = [&](int control, Sign direction) {
    return std::find_if(blocking.begin(), blocking.end(), [&](const Blocking& b) {
      return b.control == control && b.direction == direction;
    });
  };
  ASSERT_NE(blocked(kDiggingDepth, Sign::kPlus), blocking.end());
  EXPECT_FALSE(blocked(kDiggingDepth, Sign::kPlus)->limit_trial);  // physical
  EXPECT_DOUBLE_EQ(blocked(kDiggingDepth, Sign::kPlus)->at, 20.0);
  ASSERT_NE(blocked(kJumpingGap, Sign::kPlus), blocking.end());
}

// World 95 from (4.5, -1, 9): the first break on the strike comes at a negative angle, where the
// strike offset's sign is unknown; the planner guesses "increase the angle", which is wrong. The
// limit asserted on that guess later leaves no direction, is retracted, and the run succeeds.
TEST(Planner, RetractsAGuessedLimitInsteadOfGivingUp) {
  Planner planner = match_planner();
  SimulatedWorld world = SimulatedWorld::random(95);
  const RunResult run = run_trials(planner, {4.5, -1.0, 9.0}, world.as_function(), 60);
  const auto guessed = std::find_if(run.trials.begin(), run.trials.end(), [](const Trial& t) {
    return !t.limits_asserted.empty() && t.limits_asserted.front().guessed;
  });
  ASSERT_NE(guessed, run.trials.end());
  EXPECT_EQ(guessed->outcome, kBreakOnStrike);
  const auto retracting = std::find_if(run.trials.begin(), run.trials.end(),
                                       [](const Trial& t) { return !t.limits_retracted.empty(); });
  ASSERT_NE(retracting, run.trials.end());
  EXPECT_EQ(run.status, Status::kSuccess);
  for (const Limit& limit : planner.history().limits()) {
    for (int trial : retracting->limits_retracted) EXPECT_NE(limit.trial, trial);
  }
}

TEST(Planner, RejectsAStartOutsideThePhysicalLimits) {
  Planner planner = match_planner();
  try {
    (void)run_trials(
        planner, {8.0, 20.0, 25.0}, [](const std::vector<double>&) { return kNoIgnitionNoBreak; },
        5);
    FAIL() << "expected QrError";
  } catch (const QrError& error) {
    EXPECT_STREQ(error.what(), "the start point lies outside the physical limits of the controls");
  }
}

TEST(Planner, RejectsGoalsThatAreNotThresholds) {
  MatchStrikeModel model = match_strike_model();
  model.goals.push_back({model.network.find("heat"), true});
  EXPECT_THROW(Planner(model.network, model.controls, model.goals), QrError);
}

// A world drawn from a seed and a start on the controls' grids.
struct Scenario {
  std::uint64_t world_seed;
  std::vector<double> start;
};

rc::Gen<Scenario> scenarios() {
  return rc::gen::apply(
      [](std::uint64_t seed, int half_millimetres, int angle, int gap) {
        return Scenario{seed, {2.0 + 0.5 * half_millimetres, double(angle), double(gap)}};
      },
      rc::gen::inRange<std::uint64_t>(0, 1u << 30), rc::gen::inRange(0, 37),
      rc::gen::inRange(-60, 61), rc::gen::inRange(1, 21));
}

// Property: no proposed value lies beyond a physical limit or inside a limit asserted before it.
RC_GTEST_PROP(PlannerProperty, NeverProposesBeyondALimit, ()) {
  const Scenario scenario = *scenarios();
  Planner planner = match_planner();
  SimulatedWorld world = SimulatedWorld::random(scenario.world_seed);
  const RunResult run = run_trials(planner, scenario.start, world.as_function(), 60);
  std::vector<Limit> asserted;
  for (const Trial& trial : run.trials) {
    for (int retracted : trial.limits_retracted) {
      std::erase_if(asserted, [retracted](const Limit& limit) {
        return limit.guessed && limit.trial == retracted;
      });
    }
    for (const Limit& limit : trial.limits_asserted) asserted.push_back(limit);
    if (!trial.plan) continue;
    std::vector<double> next = trial.controls;
    next[trial.plan->control] = trial.plan->to;
    RC_ASSERT(planner.history().within_physical_limits(next));
    for (const Limit& limit : asserted) RC_ASSERT(!limit.excludes(next, planner.controls()));
  }
}

// Property: every run ends in success or in a reported "no direction left" with its blocking
// limits, well within the trial budget.
RC_GTEST_PROP(PlannerProperty, TerminatesWithSuccessOrNoDirectionLeft, ()) {
  const Scenario scenario = *scenarios();
  Planner planner = match_planner();
  SimulatedWorld world = SimulatedWorld::random(scenario.world_seed);
  const RunResult run = run_trials(planner, scenario.start, world.as_function(), 60);
  RC_ASSERT(run.status == Status::kSuccess || run.status == Status::kNoDirectionLeft);
  if (run.status == Status::kNoDirectionLeft) RC_ASSERT(!run.trials.back().blocking.empty());
}

}  // namespace
}  // namespace spar::qr
