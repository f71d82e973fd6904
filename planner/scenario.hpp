// Scenario: the work cell and the task, as a plain value read from a YAML file (docs/scenario.md).
//
// A scenario names the robot (a built-in robot, a URDF file or a DH table, its base pose in the
// world, the tool transform from its tip to the gripper frame, the gripper, the manipulator's
// uncertainty), the objects (shape, named features, initial pose, pose uncertainty, whether it is
// fixed), the free places on the table where objects may be put down (each with one or several
// yaws), the sensors, the collision margin, and the goals: SPAR's assembled(held, fixed, mating
// faces, Ta, mating vector) and at(object, place).
//
// Units: inside a Scenario every length is in metres and every angle in radians (REP 103),
// whatever the file said; `units` remembers the file's choice so output can be shown in it.
// World frame: z up, the table top is the plane z = 0. An object's frame is its mesh's frame.
//
// Invariants the loader guarantees (load_scenario throws ScenarioError otherwise, with
// `file:line:col: what is wrong`):
//   * object names are unique identifiers; every name a goal uses is an object;
//   * every face id (features, goals) exists in its object's model;
//   * every pose is rigid; every half-width of an uncertainty is finite and >= 0;
//   * `places` have unique names; the robot is a valid chain (kinematics/robot.hpp) with its IK;
//   * every UncertaintyModel's sigma is > 0 (and finite) where its half-width is > 0 when it is
//     Gaussian, 0 when uniform; every cost is finite and > 0;
//   * every place has at least one yaw, none repeated;
//   * the goals do not contradict each other: no pair assembled twice, no object held in two
//     assemblies or at two places or both held and at a place, no cycle of assemblies, no two
//     objects at one place, no fixed object held or sent to a place it is not at.
//
// Example:
//   const Scenario scenario = load_scenario("examples/peg_block_face_down.yaml");
//   const ObjectSpec& block = scenario.object("block");
//   block.initial_pose.translation();                      // metres, world frame
//   scenario.units.to_file_length(0.0254);                 // 1.0 when the file is in inches
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "spar/geometry/grasps.hpp"
#include "spar/geometry/object.hpp"
#include "spar/kinematics/dh.hpp"
#include "spar/kinematics/robots.hpp"
#include "spar/kinematics/uncertain_pose.hpp"
#include "spar/sensing/camera.hpp"
#include "spar/sensing/sensors.hpp"

namespace spar::planner {

enum class LengthUnit { kMetre, kMillimetre, kInch };
enum class AngleUnit { kRadian, kDegree };

// The units a scenario file was written in; conversions to and from the internal m / rad.
struct Units {
  LengthUnit length{LengthUnit::kMetre};
  AngleUnit angle{AngleUnit::kRadian};

  [[nodiscard]] double metres_per_length_unit() const;  // 1, 0.001, 0.0254
  [[nodiscard]] double radians_per_angle_unit() const;  // 1, pi / 180
  [[nodiscard]] double to_file_length(double metres) const {
    return metres / metres_per_length_unit();
  }
  [[nodiscard]] double to_file_angle(double radians) const {
    return radians / radians_per_angle_unit();
  }
  [[nodiscard]] std::string_view length_name() const;  // "m", "mm", "in"
  [[nodiscard]] std::string_view angle_name() const;   // "rad", "deg"
};

// Where something was declared in a scenario file, for messages about it after loading.
struct SourceLocation {
  std::string file;
  int line{0};                            // 1-based; 0 when unknown
  int column{0};                          // 1-based
  [[nodiscard]] std::string str() const;  // "file:line:col"
};

// How the variables of one uncertainty block ({dx, dy, dz, dtheta}) are distributed inside their
// worst-case box, for the probabilistic analysis (planner/uncertainty/probability.hpp) only: the
// half-widths stay the worst-case bound every verdict is about.
//   uniform   the box's own measure (the default);
//   gaussian  N(0, sigma^2) per variable, truncated to the box (e.g. half-width = 3 sigma).
// `cost` weighs each variable's relative tightening in tolerance allocation (default 1).
enum class Distribution { kUniform, kGaussian };
[[nodiscard]] const char* to_string(Distribution distribution);  // "uniform", "gaussian"
struct UncertaintyModel {
  Distribution distribution{Distribution::kUniform};
  kinematics::PoseUncertainty sigma{};  // m, rad; all 0 when uniform
  kinematics::PoseUncertainty cost{1.0, 1.0, 1.0, 1.0};
};

struct RobotSpec {
  // A built-in name (puma560, puma762, ur5, panda), "dh" for a table given in the file, or
  // "urdf" for a URDF file (`urdf`: its path as written).
  std::string model{"puma560"};
  std::string urdf;
  // The arm: its chain, limits, link geometry and IK (the planner uses nothing else of it).
  kinematics::RobotModel arm{kinematics::builtin_robot_model("puma560")};
  kinematics::Transform base{kinematics::Transform::Identity()};  // robot base frame in the world
  kinematics::Transform tool{kinematics::Transform::Identity()};  // gripper frame in the tip
  geometry::GripperSpec gripper{};
  // Half-angle of the cone about world -z the gripper's approach (z) axis must lie in when it
  // reaches a grasp (SPAR: never reach up through the table).
  double max_tool_tilt{1.0471975511965976};  // 60 degrees
  // SPAR's execution: the gripper comes to a grasp (and leaves it) along a straight line of this
  // length on its approach axis (an insertion: along the mating vector), from a point above.
  double approach_distance{0.1};              // metres
  kinematics::PoseUncertainty uncertainty{};  // Δx_g, Δy_g, Δz_g, Δθ_g of eq. 1
  UncertaintyModel uncertainty_model{};       // how they are distributed (probability only)
  // Half-widths of per-joint errors δq_i (rad or m, one per moving joint of `arm`), or empty:
  // each step then adds the joints' error ΔT(δq) at its IK solution (kinematics/joint_error.hpp).
  // Distributed as `uncertainty_model` says (Gaussian: sigma = half-width / 3).
  std::vector<double> joint_uncertainty{};
};

// One candidate shape of an object whose identity is uncertain (`identity: [block, cube]`).
struct ObjectIdentity {
  std::string name;   // as written: a built-in name or a mesh file
  std::string shape;  // "builtin: block" or "mesh: meshes/part.off"
  geometry::ObjectModel model;
  std::vector<geometry::StablePose> stable_poses;  // of `model`
};

// One way an object may be when its identity or stable pose is uncertain (docs/scenario.md): the
// hypotheses of sense planning (sensing/selection.hpp). Labels: the stable pose ("P3") when only
// the pose is uncertain, the identity ("cube") when only the identity is, else "cube:P3".
struct ObjectHypothesis {
  std::string label;
  int identity{0};  // index into ObjectSpec::identities (0 when the identity is certain)
  std::optional<int> stable_pose;  // index into that identity's stable poses
  kinematics::Transform pose{kinematics::Transform::Identity()};  // object frame in the world
};

struct ObjectSpec {
  std::string name;
  std::string shape;  // as written: "builtin: peg" or "mesh: meshes/part.off"
  geometry::ObjectModel model;
  std::vector<geometry::StablePose> stable_poses;    // of `model`, labels "P1", "P2", ...
  std::map<std::string, std::vector<int>> features;  // named feature -> face ids (ascending)
  kinematics::Transform initial_pose{kinematics::Transform::Identity()};  // object frame in world
  // The stable pose the object initially rests in: given (`pose: {stable: P3, ...}`) or found by
  // classify_orientation for an `xyz/rpy` pose resting on the table; nullopt if neither.
  std::optional<int> initial_stable_pose;     // index into stable_poses
  kinematics::PoseUncertainty uncertainty{};  // Δx_o, Δy_o, Δz_o, Δθ_o of eq. 2
  UncertaintyModel uncertainty_model{};       // how they are distributed (probability only)
  // `fixed: true`: the object never moves (a fixture, a base bolted down): it needs no grasps and
  // the planner never picks it up; it may still be the fixed object of an assembled goal.
  bool fixed{false};
  SourceLocation location;       // of the object's entry
  SourceLocation pose_location;  // of its `pose`
  // `identity: [...]`: the candidate shapes (`model`, `stable_poses` and `shape` are the first
  // one's); empty when the shape is certain.
  std::vector<ObjectIdentity> identities{};
  // More than one when the identity or the stable pose is uncertain (`initial_pose` and
  // `initial_stable_pose` are then the first one's); else empty.
  std::vector<ObjectHypothesis> hypotheses{};
  [[nodiscard]] bool uncertain() const { return hypotheses.size() > 1; }
};

// A free spot on the table where an object may be put down: the object's centre of mass goes
// above (x, y), turned by one of `yaws` about world z (the plan chooses which), resting in
// whichever stable pose the plan chooses. A place holds one object at a time.
struct Place {
  std::string name;
  double x{0.0};
  double y{0.0};
  std::vector<double> yaws{0.0};  // radians, at least one, distinct
  SourceLocation location;
};

// Where an object rests when put down at `place` in the resting orientation `resting` (a stable
// pose's object_to_world), turned by `yaw`: trans(x, y, 0) rotz(yaw) T_stable (the resting pose
// form of docs/scenario.md).
[[nodiscard]] kinematics::Transform place_pose(const Place& place, double yaw,
                                               const kinematics::Transform& resting);

// The collision checks of the plan (geometry/collision.hpp): bodies closer than `margin`
// (metres) count as colliding.
struct CollisionSettings {
  double margin{0.001};
};

// range-scan: sensing an object replaces its pose uncertainty by this residual (fresh variables)
// in each component whose error is not already inside it (planner/uncertainty/propagation.hpp).
// `model` is the scanner as sense planning sees it: on the wrist unless a pose is given.
struct RangeScanSensor {
  kinematics::PoseUncertainty residual{};
  UncertaintyModel residual_model{};  // how the residual is distributed (probability only)
  sensing::SensorModel model{sensing::default_range_scanner()};
};

// Sense planning (`sensing:`): the operations chosen for an uncertain object bring the worst-case
// ambiguity below `ambiguity_threshold` bits, at most `max_operations` of them; wrist sensors look
// at the object from `standoff` metres.
struct SensingSettings {
  double ambiguity_threshold{0.3};
  int max_operations{3};
  double standoff{0.5};
};

// A camera (sensors.cameras, normative; docs/scenario.md): one description read by both PSEIKI's
// `spar vision` and sense planning. Where it is (`mount`: fixed in the world, or carried on the
// wrist with `pose` in the gripper frame), how it images (sensing/camera.hpp: the optical frame,
// +z the viewing direction, +x right, +y down), how noisy its edges are and how often an edge it
// should see is found. `uncertainty` (fixed cameras only): the pose's half-widths as an object's
// (eq. 2: displacement in the world, dtheta about world z through the camera), for a camera on a
// mobile robot whose position is not known exactly; sense planning predicts from the nominal pose.
struct CameraSensor {
  std::string name;
  sensing::Projection projection{sensing::Projection::kPinhole};
  sensing::Intrinsics intrinsics{};  // pixels (orthographic fx, fy: pixels per metre)
  // Fixed: the camera frame in the world; on the wrist: in the gripper frame.
  kinematics::Transform pose{kinematics::Transform::Identity()};
  sensing::Mount mount{sensing::Mount::kFixed};
  double noise_px{0.0};               // standard deviation of an edge end point, pixels
  double detection_probability{1.0};  // in (0, 1]
  kinematics::PoseUncertainty uncertainty{};
  UncertaintyModel uncertainty_model{};
  // Phase 2's camera verification (fixed cameras only): the pose uncertainty an accepted PSEIKI
  // verification leaves on an object the camera sees, as a range-scan's residual (its own pose
  // error included: the user's figure, not derived). Without one the camera only names what
  // PSEIKI must see in a failed step's verification.
  std::optional<kinematics::PoseUncertainty> residual{};
  UncertaintyModel residual_model{};  // how the residual is distributed (probability only)
  SourceLocation location;            // of the camera's entry

  // The camera as sense planning's simulated sensor (sensing/sensors.hpp).
  [[nodiscard]] sensing::SensorModel sensor_model() const;
};

// SPAR's assembled(held, fixed, [held faces, fixed faces], Ta, mating vector).
struct AssembledGoal {
  std::string held;              // the object the robot holds and moves
  std::string fixed;             // the object that stays on the table
  std::vector<int> held_faces;   // mating faces of `held` (ids, ascending)
  std::vector<int> fixed_faces;  // mating faces of `fixed`
  // Ta: the held object's frame in the fixed object's frame once assembled.
  kinematics::Transform relative{kinematics::Transform::Identity()};
  // Direction of the mating motion in the fixed object's frame (unit length).
  Eigen::Vector3d mating_vector{0.0, 0.0, -1.0};
  // Largest admissible error of the insertion: offset perpendicular to the mating vector
  // (metres) and misalignment (radians) between the held and the fixed mating features.
  double clearance{0.0};
  double angular_clearance{0.0};
  SourceLocation location;
};

// at(object, place): the object ends resting at the place (any stable pose, any of its yaws).
struct AtGoal {
  std::string object;
  std::string place;
  SourceLocation location;
};

using Goal = std::variant<AssembledGoal, AtGoal>;
// "assembled(peg, block)", "at(block, left)".
[[nodiscard]] std::string describe(const Goal& goal);
[[nodiscard]] const SourceLocation& location(const Goal& goal);

struct Scenario {
  std::string name;            // `name:` or the file's stem
  std::string description;     // optional free text
  std::filesystem::path path;  // the file it was read from ("" if parsed from text)
  Units units{};
  RobotSpec robot{};
  std::vector<ObjectSpec> objects;  // in file order
  std::vector<Place> places;        // in file order
  std::optional<RangeScanSensor> range_scan;
  CollisionSettings collision{};
  std::vector<CameraSensor> cameras;  // sensors.cameras, in file order, unique names
  SensingSettings sensing{};
  geometry::GraspQuantization grasping{};  // how grasps are quantized (SPAR's grasp labels)
  std::vector<Goal> goals;                 // in file order
  // "file:line:col: ..." for what loads but looks wrong (a mesh whose size is implausible in the
  // file's length unit); the CLI prints them on stderr, Python issues them as warnings.
  std::vector<std::string> warnings;

  // Throws ScenarioError naming the known objects when there is none called `name`.
  [[nodiscard]] const ObjectSpec& object(std::string_view name) const;
  // Index into `places`, or -1.
  [[nodiscard]] int place_index(std::string_view name) const;
  // The same for cameras.
  [[nodiscard]] const CameraSensor& camera(std::string_view name) const;
  // The scenario with hypothesis `hypothesis` of object `name` taken as the truth: its identity's
  // shape and stable poses, its pose; the object is certain in the result (one plan branch).
  // Throws ScenarioError for an unknown object or hypothesis.
  [[nodiscard]] Scenario resolved(std::string_view name, std::size_t hypothesis) const;
};

// The index of the place's yaw at which `object` initially rests there (its initial pose is
// place_pose for its initial stable pose, within 1e-7 m and rad), or nullopt.
[[nodiscard]] std::optional<std::size_t> resting_yaw(const ObjectSpec& object, const Place& place);

// Reads and validates a scenario file; mesh paths are relative to the file's folder.
[[nodiscard]] Scenario load_scenario(const std::filesystem::path& path);
// The same from text: `source` names it in messages, `base_dir` resolves mesh paths.
[[nodiscard]] Scenario parse_scenario(std::string_view text, const std::string& source,
                                      const std::filesystem::path& base_dir);

}  // namespace spar::planner
