// Choosing sensing operations by minimax ambiguity (the survey's section 3). A sensing operation
// is a sensor at a viewpoint. For each candidate operation and each hypothesis h of the current
// set, the features the operation would observe if h were true are predicted (the noise-free
// expectation of h, sensors.hpp), the hypothesis set those features would produce is formed (the
// evidence of hypotheses.hpp combined with the current belief) and its ambiguity measured (the
// entropy of the pignistic probability, evidence.hpp); the operation's score is the maximum over
// h. The operation of least maximum ambiguity is chosen; if that maximum is still at or above
// the threshold, the next operation is chosen the same way from the belief the chosen one leaves
// in its worst case (the h of the maximum), and so on until the worst case is below the threshold,
// no remaining operation lowers the worst-case ambiguity, or `max_operations` are chosen.
//
// Viewpoints (the aspects quantise them, as the survey says): a fixed sensor has one, its own
// pose. A wrist sensor is moved to look at the object's centre from `standoff` away along world
// directions d: the cell centres of an icosphere of level `viewpoint_level` at least
// `min_elevation` above the table. The directions are grouped into viewpoint classes by the
// aspect each hypothesis' object shows toward d (aspects.hpp, d turned into the object's frame);
// a class's representative is its member nearest the class's mean direction that the robot
// reaches (the `reachable` callback, trying the image's up direction as world z, then rolled by
// 90°, 180° and 270° about the view axis); a class no member of which is reached is listed as
// unreachable and never chosen. Labels: "V1", "V2", ... per sensor, in the order of the aspect
// tuples.
//
// Cost per candidate: one render per hypothesis (its expectation) and one weighing per pair of
// hypotheses per scoring; bench/sensing_bench.cpp measures it.
//
// Example:
//   SelectionProblem problem{.hypotheses = worlds, .sensors = {scanner}, .tolerances = {tol},
//                            .prior = MassFunction::vacuous(2)};
//   const Selection chosen = select_operations(problem, SelectionOptions{});
//   chosen.sequence[0].candidate;                   // index into chosen.candidates
//   chosen.candidates[chosen.sequence[0].candidate].viewpoint.label;   // "V7"
#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "spar/sensing/aspects.hpp"
#include "spar/sensing/evidence.hpp"
#include "spar/sensing/hypotheses.hpp"
#include "spar/sensing/scene.hpp"
#include "spar/sensing/sensors.hpp"

namespace spar::sensing {

// The world as it would be under one hypothesis about the target object.
struct HypothesisWorld {
  std::string label;
  Scene scene;                        // every object; the target as this hypothesis has it
  int target{0};                      // the target's index in `scene`
  const AspectSet* aspects{nullptr};  // of the target's model under this hypothesis; not owned
};

struct Viewpoint {
  int sensor{0};      // index into SelectionProblem::sensors
  std::string label;  // a fixed sensor's name, or "V1", "V2", ... for a wrist sensor
  Eigen::Isometry3d sensor_pose{Eigen::Isometry3d::Identity()};  // world
  Eigen::Vector3d direction{Eigen::Vector3d::UnitZ()};  // unit, from the target toward the sensor
  bool reachable{true};
  std::vector<int> aspects;  // per hypothesis: index into its AspectSet, -1 when none
};

struct SelectionOptions {
  double ambiguity_threshold{0.3};  // bits
  int max_operations{3};
  double standoff{0.5};  // m, of wrist viewpoints from the target's centre
  int viewpoint_level{2};
  double min_elevation{10 * std::numbers::pi / 180};
  // Whether the robot can put wrist sensor `sensor` at `sensor_pose` (world); empty: always.
  std::function<bool(int sensor, const Eigen::Isometry3d& sensor_pose)> reachable;
};

struct SelectionProblem {
  std::vector<HypothesisWorld> hypotheses;  // the frame, in order
  std::vector<SensorModel> sensors;
  std::vector<MatchTolerances> tolerances;  // per sensor
  MassFunction prior;                       // over the hypotheses
};

struct CandidateOperation {
  Viewpoint viewpoint;
  std::vector<double> ambiguity;  // predicted from the prior, per true hypothesis (bits)
  double max_ambiguity{0};        // +inf when unreachable
  int worst{-1};                  // the hypothesis of the maximum
};

struct ChosenOperation {
  int candidate{0};  // index into Selection::candidates
  double predicted_max_ambiguity{0};
  int worst{0};
  MassFunction predicted;  // the belief it leaves if `worst` is true
};

struct Selection {
  std::vector<CandidateOperation> candidates;  // scored against the prior
  std::vector<ChosenOperation> sequence;
  double ambiguity_before{0};
  bool resolved{false};  // the last chosen operation's worst case is below the threshold
};

// Every candidate viewpoint of every sensor (reachability resolved).
[[nodiscard]] std::vector<Viewpoint> candidate_viewpoints(const SelectionProblem& problem,
                                                          const SelectionOptions& options);
// SensingError for an ill-formed problem (no hypothesis, a world without aspects, tolerances or
// a prior that does not fit, a bad sensor).
[[nodiscard]] Selection select_operations(const SelectionProblem& problem,
                                          const SelectionOptions& options);

// The expectations of every hypothesis for one sensor at one pose (the frame's order).
[[nodiscard]] std::vector<Expectation> expectations(const SelectionProblem& problem, int sensor,
                                                    const Eigen::Isometry3d& sensor_pose);

}  // namespace spar::sensing
