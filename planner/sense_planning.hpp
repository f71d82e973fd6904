// Sense planning for a scenario (the survey's section 3 on SPAR's work cell): for every object
// whose identity or stable pose is uncertain (docs/scenario.md: `identity: [...]`,
// `pose: {stable: [P3, P5], ...}`), the sensing operations that disambiguate its hypotheses,
// chosen by minimax ambiguity (sensing/selection.hpp) among the scenario's sensors: the range
// scanner (`sensors.range_scan`, on the wrist unless it has a pose) and the cameras
// (`sensors.cameras`, fixed or on the wrist). Wrist viewpoints are those the robot reaches: an
// in-limit inverse kinematics branch for the gripper frame that puts the sensor there (the
// sensor's `pose` is its frame in the gripper's) whose links, and the open gripper, clear the
// objects where they start (an uncertain one as its first hypothesis: the other hypotheses'
// poses and shapes are not obstacles yet) and the table (WorldModel::still_branch: the check
// steps use, at one pose); the robot's max_tool_tilt applies to looking as to grasping.
//
// The world of each hypothesis is the scenario's objects at their initial poses, the uncertain
// object as the hypothesis has it, and any other uncertain object as its first hypothesis.
// Match tolerances combine each sensor's noise with the object's pose uncertainty (its `dx, dy,
// dz, dtheta`: hypotheses.hpp's match_tolerances). The prior is vacuous over the object's
// identities, refined to its hypotheses (identity x stable pose; evidence.hpp's refine): the
// frame grows from "which object" to "which object in which pose" as the survey describes.
//
// Cost: per uncertain object, one aspect computation per identity (aspects.hpp) and, per
// candidate operation, one render per hypothesis.
//
// Example:
//   const Scenario scenario = load_scenario("examples/sensing_block_pose.yaml");
//   const SensePlan plan = plan_sensing(scenario, WorldModel(scenario));
//   for (const ObjectSensePlan& object : plan.objects)
//     object.selection.sequence;   // the chosen operations, first one first
#pragma once

#include <cstddef>
#include <deque>
#include <string>
#include <vector>

#include "spar/planner/scenario.hpp"
#include "spar/planner/world.hpp"
#include "spar/sensing/aspects.hpp"
#include "spar/sensing/selection.hpp"

namespace spar::planner {

// The scenario's sensors as sense planning uses them, the range scanner first.
[[nodiscard]] std::vector<sensing::SensorModel> scenario_sensors(const Scenario& scenario);

// What the scenes of sense planning point into (models' features, identities' aspects), built
// once; `scenario` and `world` must outlive it.
class SensingContext {
 public:
  SensingContext(const Scenario& scenario, const WorldModel& world);
  // The selection problem of uncertain object `object` (index into the scenario's objects); its
  // worlds point into this context.
  [[nodiscard]] sensing::SelectionProblem problem(std::size_t object) const;
  // The scenario's threshold, standoff and operations, and the robot's reach (referring to this
  // context: it must outlive them).
  [[nodiscard]] sensing::SelectionOptions options() const;
  // The aspects of identity `identity` of object `object` (the object's own shape: identity 0).
  [[nodiscard]] const sensing::AspectSet& aspects(std::size_t object, int identity) const;

 private:
  struct Shape {
    const geometry::ObjectModel* model{nullptr};
    sensing::ObjectFeatures features;
    sensing::AspectSet aspects;  // computed for uncertain objects only
  };
  [[nodiscard]] const Shape& shape(std::size_t object, int identity) const;
  const Scenario& scenario_;
  const WorldModel& world_;
  std::vector<sensing::SensorModel> sensors_;
  std::deque<Shape> shapes_;                        // stable addresses
  std::vector<std::vector<std::size_t>> shape_of_;  // [object][identity] -> index into shapes_
};

struct ObjectSensePlan {
  std::string object;
  std::vector<std::string> hypotheses;   // labels: the frame, in order
  std::vector<std::string> identities;   // the coarse frame (the object's name when certain)
  std::vector<int> hypothesis_identity;  // [hypothesis] -> index into identities
  std::vector<std::string> sensors;      // names; candidates' sensor indices point here
  // [candidate][hypothesis]: the label of the aspect the object shows the candidate ("" if none).
  std::vector<std::vector<std::string>> candidate_aspects;
  std::vector<sensing::AspectSet> identity_aspects;  // [identity]
  std::vector<double> beliefs_before;  // pignistic probabilities of the prior, per hypothesis
  sensing::Selection selection;
  double threshold{0};
};

struct SensePlan {
  std::vector<ObjectSensePlan> objects;  // the uncertain objects, in scenario order
};

// Throws ScenarioError when an uncertain object has no sensor to look at it with.
[[nodiscard]] SensePlan plan_sensing(const Scenario& scenario, const WorldModel& world);

}  // namespace spar::planner
