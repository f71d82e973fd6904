// Match striking (seeds/000, sections 2 and 7): the network of the seed's Figure 2 as data, a
// simulated world to run trials against, and an SVG of the search like the seed's Figure 8.
//
// Network (controls in capitals, our reading of Figure 2):
//   force     = M+(DIGGING DEPTH)           velocity = M+(JUMPING GAP)
//   heat      = force x velocity            ignition = threshold(heat)              goal: true
//   strike offset = ANGLE + negative(landmark)   (landmark: constant, sign -, number hidden)
//   strike lever  = |strike offset|         strike moment = force x strike lever
//   break on strike = threshold(strike moment)                                      goal: false
//   start lever   = |ANGLE|  (pressing into the box bends nothing when the stick is perpendicular)
//   start moment  = force x start lever     break on move to start = threshold(start moment)
//                                                                                   goal: false
// Goals in priority order: no break on the move to start, no break on the strike, ignition.
// The landmark is the angle at which, during the strike, the resultant of the normal force and the
// friction points along the stick: -atan(mu), negative (the match leans back from the motion).
//
// Simulated world: force = 0.5 N/mm * depth, velocity = 0.05 m/s per mm of gap, heat = mu F v,
// moments = F * stick length * sin(lever). Hidden per world: mu (hence the landmark), the breaking
// moment, the ignition heat, and the trial-to-trial variation of both (each trial uses a new
// match). If the match breaks on the move to start, the strike does not happen (its results are not
// observed); if it breaks on the strike, ignition is not observed.
//
// Example:
//   MatchStrikeModel model = match_strike_model();
//   SimulatedWorld world = SimulatedWorld::random(7);
//   Planner planner(model.network, model.controls, model.goals);
//   RunResult run = run_trials(planner, kSeedStart, world.as_function(), 60);
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "spar/qr/planner.hpp"

namespace spar::qr {

// Control order everywhere in this file: digging depth [mm], angle [deg], jumping gap [mm].
enum MatchControl : int { kDiggingDepth = 0, kAngle = 1, kJumpingGap = 2 };
// Goal order: break on the move to start, break on the strike, ignition.
enum MatchGoal : int { kBreakOnStart = 0, kBreakOnStrike = 1, kIgnition = 2 };

struct MatchStrikeModel {
  Network network;
  std::vector<ControlSpec> controls;  // physical limits: depth [2, 20] mm, angle [-60, 60] deg,
                                      // gap [1, 20] mm
  std::vector<Goal> goals;
};
[[nodiscard]] MatchStrikeModel match_strike_model();

// The seed's start: depth 8 mm, angle 20 deg, gap 20 mm.
inline const std::vector<double> kSeedStart{8.0, 20.0, 20.0};

// Parses "depth=8,angle=20,gap=20" (any subset, any order; missing keys keep `defaults`).
// Throws QrError naming the bad token, an unknown key, or a value outside the physical limits.
[[nodiscard]] std::vector<double> parse_match_start(
    const std::string& text, const std::vector<double>& defaults = kSeedStart);

struct WorldParameters {
  double friction{0.5};         // mu; the landmark is -atan(mu)
  double breaking_moment{1.0};  // N mm
  double ignition_heat{1.0};    // W
  double variation{0.0};        // relative standard deviation of both, per match
  double stick_length{30.0};    // mm
  [[nodiscard]] double landmark_degrees() const;
};

class SimulatedWorld {
 public:
  SimulatedWorld(WorldParameters parameters, std::uint64_t seed);
  // A world with hidden parameters drawn from `seed` such that some control values succeed.
  [[nodiscard]] static SimulatedWorld random(std::uint64_t seed);
  // Shaped like the seed's run: at gap 20 mm and angle 20 deg, depths 8-11 mm neither ignite nor
  // break, 12.5 mm breaks on the strike, ignition needs about 14 mm. No variation.
  [[nodiscard]] static SimulatedWorld paper_like();

  // One trial with a new match (draws the match's variation).
  [[nodiscard]] Outcome execute(const std::vector<double>& controls);
  // The outcome for a nominal match (no variation).
  [[nodiscard]] Outcome nominal(const std::vector<double>& controls) const;
  [[nodiscard]] World as_function();
  [[nodiscard]] const WorldParameters& parameters() const { return parameters_; }

 private:
  [[nodiscard]] Outcome outcome(const std::vector<double>& controls, double strength_factor,
                                double ignition_factor) const;

  WorldParameters parameters_;
  std::mt19937_64 random_;
};

}  // namespace spar::qr
