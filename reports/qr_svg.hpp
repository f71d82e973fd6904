// The SVG drawing of a qualitative-reasoning search (qr/, seed 000's match striking): spar's output
// formatting lives in reports/, and qr/ stays free of it (qr computes, reports draws).
//
// The search in the angle (vertical) x digging depth (horizontal) plane: trials numbered and
// coloured by outcome (green: success), arrows for the planned changes, asserted limits as bars
// over the region from which they are visible (grey: no ignition, red: break on strike, blue:
// break on start); each limit carries a <title> naming its trial.
//
// Example:
//   const qr::MatchStrikeModel model = qr::match_strike_model();
//   qr::Planner planner(model.network, model.controls, model.goals);
//   const qr::RunResult run = qr::run_trials(planner, start, world.as_function(), 40);
//   std::ofstream("search.svg") << match_strike_svg(model, run);
#pragma once

#include <string>

#include "spar/qr/match_strike.hpp"

namespace spar::reports {

[[nodiscard]] std::string match_strike_svg(const qr::MatchStrikeModel& model,
                                           const qr::RunResult& run);

}  // namespace spar::reports
