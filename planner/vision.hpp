// A scenario's camera as PSEIKI sees it (sensing/pseiki/): the scene of the scenario's objects at
// their believed poses, the camera, and how uncertain both are. `spar vision`, Python's
// spar.vision_* and the planner's camera verification start here.
//
// VisionSetup owns the objects' features (model edges); its scene refers to them and to the
// scenario's object models, so the scenario must outlive it. It moves (the features move with
// their storage) but does not copy.
//
// Simulated images (`spar vision simulate`) may change the scene first: `missing` objects are
// left out of the image, and a `swaps` entry {name, other} puts the other object's model where
// `name` is believed to be (its edges' truth then names no edge of the expected scene).
//
// Example:
//   const Scenario scenario = load_scenario("examples/pseiki_sidewalk.yaml");
//   const VisionSetup setup(scenario, "front");
//   const auto result = sensing::pseiki::verify(setup.scene(), setup.camera(),
//                                               setup.uncertainty(), image.edges, setup.options());
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "spar/geometry/grasps.hpp"
#include "spar/planner/scenario.hpp"
#include "spar/sensing/pseiki/matcher.hpp"
#include "spar/sensing/pseiki/simulate.hpp"
#include "spar/sensing/pseiki/vision_json.hpp"

namespace spar::planner {

class VisionSetup {
 public:
  // ScenarioError naming the known cameras when there is none called `camera`, or saying so when
  // it is on the wrist (its pose is in the gripper frame).
  VisionSetup(const Scenario& scenario, std::string_view camera);
  VisionSetup(VisionSetup&&) = default;
  VisionSetup& operator=(VisionSetup&&) = default;
  VisionSetup(const VisionSetup&) = delete;
  VisionSetup& operator=(const VisionSetup&) = delete;

  [[nodiscard]] const CameraSensor& sensor() const { return *sensor_; }
  [[nodiscard]] const sensing::Scene& scene() const { return scene_; }
  [[nodiscard]] const sensing::Camera& camera() const { return camera_; }
  [[nodiscard]] const sensing::pseiki::ExpectationUncertainty& uncertainty() const {
    return uncertainty_;
  }
  // Matching options with the camera's detection probability.
  [[nodiscard]] sensing::pseiki::MatchOptions options() const;
  [[nodiscard]] sensing::pseiki::OutputUnits units() const;
  // The scene index of an object (ScenarioError naming the objects).
  [[nodiscard]] int object_index(std::string_view name) const;

  struct Swap {
    std::string name, other;
  };
  // The scene with `missing` objects left out and `swaps` applied (names checked; a swapped
  // object is called "name~other"), with the uncertainties of the objects it keeps.
  struct ChangedScene {
    sensing::Scene scene;
    sensing::pseiki::ExpectationUncertainty uncertainty;
  };
  [[nodiscard]] ChangedScene changed_scene(const std::vector<std::string>& missing,
                                           const std::vector<Swap>& swaps) const;

 private:
  const Scenario* scenario_;
  const CameraSensor* sensor_;
  std::unique_ptr<std::vector<sensing::ObjectFeatures>> features_;  // [object], stable addresses
  sensing::Scene scene_;
  sensing::Camera camera_;
  sensing::pseiki::ExpectationUncertainty uncertainty_;
};

// What PSEIKI must see to accept the verification of a step (issue 27; the verification step of an
// error, seed 001 fig. 11): the camera, the object, and the object's model edges it expects to see
// (ids as `spar vision render` prints them, "peg/e3"); the interpretation is accepted when the
// scene belief reaches `acceptance`. The scene is rendered as it stands at the step: the object at
// the step's ideal pose, the `occluders` (the other objects where they rest, and the gripper at
// the step's grasp, closed to its width) drawn with it, so an edge they hide (hidden-line removal
// between objects, sensing/render.hpp) is not listed and a camera that sees the object only
// behind them is not chosen. The camera is the fixed one that sees the most of the object's edges
// (ties: the first in file order; a wrist camera's world pose depends on the step, so it is not
// one). nullopt when the scenario has no camera or none sees the object.
//
// `drawing` is that camera's model panel for the reports (the expected scene as it renders it):
// every visible edge of every body, object and occluders, in pixels (u right, v down). The
// gripper's three boxes are the bodies "gripper/palm", "gripper/finger-y", "gripper/finger+y"
// (their edges "gripper/palm/e4"). Not drawn: objects already inserted into another (the planner
// no longer tracks them on their own) and the arm's links.
struct VisionEdge {
  std::string id, object;  // "peg/e3", "peg"
  std::vector<sensing::pseiki::Segment> pieces;
};
struct VisionCheck {
  std::string camera, object;
  std::vector<std::string> edges;
  double acceptance{0};
  int width{0}, height{0};  // the camera's image, pixels
  std::vector<VisionEdge> drawing;
};
struct VisionOccluders {
  std::vector<std::pair<int, kinematics::Transform>> objects;  // scenario index, ideal pose
  const geometry::GripperSpec* gripper{nullptr};               // none: no gripper at the step
  kinematics::Transform gripper_pose{kinematics::Transform::Identity()};  // world
  double opening{0};                                                      // metres
};
[[nodiscard]] std::optional<VisionCheck> vision_check(const Scenario& scenario, int object,
                                                      const kinematics::Transform& pose,
                                                      const VisionOccluders& occluders = {});

// Phase 2's camera verification (a sense step with `sensor: camera`, planner/uncertainty/
// repair.hpp): the fixed cameras with a `residual` (CameraSensor::residual; only `camera` when
// >= 0) that see `object` at `pose` well enough to correct its pose, with the `occluders` drawn:
// at least three of its model edges visible, two of them at least 20 degrees apart in the image
// (their longest visible pieces' directions). In file order; empty when no camera qualifies. Two
// cameras that both qualify may both verify (phase 2 fuses their residuals: an overhead view
// measures x and y, a side view the height).
struct CameraVerification {
  int camera{-1};  // index into Scenario::cameras
  VisionCheck check;
};
[[nodiscard]] std::vector<CameraVerification> verifying_cameras(const Scenario& scenario,
                                                                int object,
                                                                const kinematics::Transform& pose,
                                                                const VisionOccluders& occluders,
                                                                int camera = -1);

}  // namespace spar::planner
