// reports/qr_svg.hpp: the match-striking search drawn as SVG from qr's data.
#include "spar/reports/qr_svg.hpp"

#include <gtest/gtest.h>

namespace spar::reports {
namespace {

TEST(MatchStrikeSvg, DrawsEveryTrialAndEveryLimitInThePlane) {
  const qr::MatchStrikeModel model = qr::match_strike_model();
  qr::Planner planner(model.network, model.controls, model.goals);
  qr::SimulatedWorld world = qr::SimulatedWorld::paper_like();
  const qr::RunResult run = qr::run_trials(planner, qr::kSeedStart, world.as_function(), 40);
  const std::string svg = match_strike_svg(model, run);
  ASSERT_EQ(svg.rfind("<svg", 0), 0u);
  auto count = [&svg](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = svg.find(what); at != std::string::npos; at = svg.find(what, at + 1)) ++n;
    return n;
  };
  std::size_t plane_limits = 0;
  for (const qr::Trial& trial : run.trials) {
    for (const qr::Limit& limit : trial.limits_asserted)
      plane_limits += limit.control != qr::kJumpingGap;
  }
  EXPECT_EQ(count("<circle"), run.trials.size());
  EXPECT_EQ(count("<title>limit from trial"), plane_limits);
  EXPECT_GT(plane_limits, 0u);
}

}  // namespace
}  // namespace spar::reports
