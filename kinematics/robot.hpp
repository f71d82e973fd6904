// RobotModel: a robot arm as data. A serial chain of joints (revolute, prismatic, fixed) from a
// base link to a tip link, with joint limits, the collision geometry of every link that moves with
// the chain, forward kinematics, and an inverse kinematics solver chosen for the chain's geometry.
// The planner, the CLI and Python see only this interface; a robot comes from a URDF file
// (kinematics/urdf.hpp), from a DH table (Puma 560/762, `model: dh`), or by name (robots.hpp).
//
// Frames and joints (as URDF): a joint's child link frame is parent * origin * motion(q), where the
// motion is a rotation by q about `axis` (revolute), a translation by q along it (prismatic) or
// nothing (fixed). Fixed joints are folded into their neighbours, so the model has n = dof()
// moving joints and body frames 0..n: body 0 is the base link, body k the child of moving joint k.
// Every link of the arm is rigidly attached to one body (`RobotLinkInfo::body`, `offset`). Angles
// are radians, lengths metres; a continuous joint has limits (-inf, +inf).
//
// Invariants (checked by the constructor, which throws KinematicsError naming the joint):
//   * joints form one path: joint 0's parent is the base link, joint i's parent is joint i-1's
//     child, the last joint's child is the tip; at least one joint moves;
//   * axes of moving joints are unit vectors (normalised on construction), origins are rigid,
//     lower <= upper for every limit; link names are unique;
//   * an attachment hangs a link off a link of the chain (or an earlier attachment) by a fixed
//     joint; links beyond the tip are not part of the arm (they are the tool's: the scenario's
//     gripper models them).
//
// Inverse kinematics (`inverse`), chosen once per robot (`ik_method`):
//   kPumaClosedForm      a DH table of the Puma type: kinematics/ik.hpp's eight labelled
//                        solutions, unchanged (lun, luf, ldn, ldf, run, ruf, rdn, rdf), limits
//                        checked per solution;
//   kUrClosedForm        six revolute joints with axes 2, 3, 4 parallel and axes 5, 6 meeting
//                        (UR3/5/10 and e-series, any URDF frames): up to eight labelled solutions
//                        l|r shoulder (wrist point on the negative / positive side of the arm's
//                        zero-configuration reach direction), u|d elbow (elbow above / below the
//                        shoulder-wrist line, "above" along axis 1), n|f wrist (q5 on the positive
//                        / negative side of the wrist singularity), in that order, each with its
//                        limit verdict;
//   kRedundantClosedForm seven revolute joints whose first six, with joint 7 held, have a
//                        spherical shoulder (axes 1, 2, 3 meet) and axes 5, 6 meeting (Franka
//                        Panda, KUKA iiwa): q7 is sampled at every multiple of
//                        `redundancy_step` within its limits, and in the middle of each arc of
//                        q7 that keeps the wrist point within reach but holds no such multiple
//                        (a band narrower than the step), the other six in closed form (up
//                        to eight branches l|r u|d n|f each; at the shoulder singularity, axes
//                        1 and 3 aligned, only q1 +- q3 is fixed: q1 = 0, or where that leaves
//                        q3 outside its limits the middle of the splits within both);
//                        labels "run@q7=35deg". Only
//                        solutions within limits are returned, sorted by preference: the
//                        largest limit margin first (the smallest distance of any joint to
//                        the nearer of its limits, as a fraction of that joint's range), ties
//                        by |q7|, then label. When no sample gives one but one is within reach,
//                        the numeric solver runs;
//   kNumeric             any other chain: damped least squares (Levenberg-Marquardt) on the
//                        6-D pose error, a joint at a limit held where its step points
//                        beyond it, from random starts within limits, up to
//                        `numeric_attempts` starts, collecting up to `numeric_solutions`
//                        distinct solutions within limits ("n1", "n2", ... sorted by margin).
//                        Deterministic: the starts come from `random_seed`.
// Every returned solution reproduces the pose to about 1e-12 (closed forms: exactly up to
// rounding; numeric: until the error stops shrinking below 1e-12 m / rad). Angles are reported
// wrapped into (-pi, pi] unless only another 2 pi multiple lies within the joint's limits.
//
// Cost: forward() is one 4x4 product per moving joint; the closed forms take microseconds; a
// redundant arm's inverse takes ~70 samples of its closed form at 5 degrees; the numeric solver
// costs up to numeric_attempts x 100 Jacobian solves when no solution exists.
//
// Example:
//   const RobotModel robot = builtin_robot_model("ur5");             // robots.hpp
//   const std::vector<double> q = {0.1, -1.2, 1.0, -0.5, 1.4, 0.3};
//   const Transform tool0 = robot.forward(q);                        // base_link -> tool0
//   for (const JointSolution& s : robot.inverse(tool0))              // 8, q among them
//     std::cout << s.configuration << ' ' << s.within_limits << '\n';
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spar/geometry/mesh.hpp"
#include "spar/kinematics/dh.hpp"
#include "spar/kinematics/ik.hpp"

namespace spar::kinematics {

namespace internal {
class IkSolver;
}

enum class JointType : std::uint8_t { kRevolute, kPrismatic, kFixed };
[[nodiscard]] std::string_view to_string(JointType type);  // "revolute", "prismatic", "fixed"

// One joint, URDF style.
struct RobotJoint {
  std::string name{};
  JointType type{JointType::kRevolute};
  std::string parent_link{};
  std::string child_link{};
  Transform origin{Transform::Identity()};         // joint frame in the parent link's frame
  Eigen::Vector3d axis{Eigen::Vector3d::UnitZ()};  // in the joint frame; ignored when fixed
  JointLimits limits{};                            // rad or m; ignored when fixed
};

// Collision geometry of a link, in the link's frame (metres).
enum class ShapeKind : std::uint8_t { kMesh, kBox, kCylinder, kSphere };
struct LinkShape {
  ShapeKind kind{ShapeKind::kBox};
  Transform origin{Transform::Identity()};  // the shape's frame in the link's frame
  // kBox: edge lengths x, y, z; kCylinder: (radius, radius, length) about the shape's z axis;
  // kSphere: (radius, radius, radius); kMesh: unused (the mesh is scaled already).
  Eigen::Vector3d size{Eigen::Vector3d::Zero()};
  // kMesh only: a triangle soup in the shape's frame. Immutable and shared between copies of a
  // model (meshes are large; models are copied into scenarios).
  std::shared_ptr<const geometry::Mesh> mesh{};
  std::string where{};  // the description's "file:line" of this shape, for messages
};

struct RobotLink {
  std::string name{};
  std::vector<LinkShape> collision{};
};

// What an importer hands to RobotModel.
struct RobotDescription {
  std::string name{};
  std::string source{};  // a citation or the file it was read from
  std::string base_link{};
  std::string tip_link{};
  std::vector<RobotJoint> chain{};        // base -> tip, in order, fixed joints included
  std::vector<RobotJoint> attachments{};  // fixed joints hanging links off the chain
  std::vector<RobotLink> links{};         // geometry of the links named by chain and attachments
  // A Puma-type DH table this chain was built from: inverse kinematics then uses kinematics/ik.hpp
  // unchanged (the seed experiments' answers). Set by RobotModel::from_dh.
  std::shared_ptr<const DhChain> dh{};
};

// One moving joint of the model, after fixed joints were folded in.
struct MovingJoint {
  std::string name{};
  JointType type{JointType::kRevolute};     // kRevolute or kPrismatic
  Transform origin{Transform::Identity()};  // joint frame in the previous body's frame
  Eigen::Vector3d axis{Eigen::Vector3d::UnitZ()};
  JointLimits limits{};
};

// A link of the arm: rigidly attached to body `body` (0 = base, k = after moving joint k).
struct RobotLinkInfo {
  std::string name{};
  int body{0};
  Transform offset{Transform::Identity()};  // link frame in the body frame
  std::vector<LinkShape> collision{};
};

enum class IkMethod : std::uint8_t {
  kPumaClosedForm,
  kUrClosedForm,
  kRedundantClosedForm,
  kNumeric,
};
// "closed form (Puma)", "closed form (UR)", "closed form over q7 (7 joints)", "numeric (LM)"
[[nodiscard]] std::string_view to_string(IkMethod method);

struct InverseOptions {
  // 7-joint arms: q7 takes every multiple of this step within its limits. > 0.
  double redundancy_step{5.0 * std::numbers::pi / 180.0};
  // 7-joint closed form: q7 at this value only, as one sample of the sweep (that sample's
  // solutions, labels and limit checks; no numeric fallback). Following one branch along a path
  // (its q7 fixed by its label) costs one sample instead of the whole sweep. Other solvers
  // ignore it.
  std::optional<double> redundancy_at{};
  // Numeric solver: random starts, and distinct solutions it collects before it stops.
  int numeric_attempts{64};
  std::size_t numeric_solutions{8};
  std::uint64_t random_seed{1};
};

struct JointSolution {
  std::vector<double> q{};      // dof() values, radians / metres
  std::string configuration{};  // "run", "run@q7=35deg", "n1"
  bool within_limits{false};
  std::uint8_t singularities{kNoSingularity};  // ik.hpp's flags (closed forms)
};

class RobotModel {
 public:
  // Validates the description (see the invariants above) and chooses the IK solver.
  explicit RobotModel(RobotDescription description);
  // A standard-DH chain as a robot: links "link0".."link<n>", joints "joint1".."joint<n>", no
  // collision geometry. Puma-type tables keep kinematics/ik.hpp's solver.
  [[nodiscard]] static RobotModel from_dh(const DhChain& chain);

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::string& base_link() const { return base_link_; }
  [[nodiscard]] const std::string& tip_link() const { return tip_link_; }
  [[nodiscard]] std::size_t dof() const { return joints_.size(); }
  [[nodiscard]] const std::vector<MovingJoint>& joints() const { return joints_; }
  [[nodiscard]] const std::vector<RobotLinkInfo>& links() const { return links_; }
  // The tip frame in the last body's frame.
  [[nodiscard]] const Transform& tip_offset() const { return tip_offset_; }
  [[nodiscard]] IkMethod ik_method() const { return ik_method_; }

  // Throws KinematicsError unless q.size() == dof() and every value is finite.
  [[nodiscard]] Transform forward(std::span<const double> q) const;
  // Body frames 0..n in the base frame.
  [[nodiscard]] std::vector<Transform> body_poses(std::span<const double> q) const;
  // Each of links() in the base frame.
  [[nodiscard]] std::vector<Transform> link_poses(std::span<const double> q) const;
  // True if every q[i] lies within joint i's limits widened by `tolerance`.
  [[nodiscard]] bool within_limits(std::span<const double> q, double tolerance = 1e-9) const;
  // 1-based indices of the joints outside their limits (widened by `tolerance`).
  [[nodiscard]] std::vector<int> joints_out_of_limits(std::span<const double> q,
                                                      double tolerance = 1e-9) const;

  // Every solution for the tip pose (base frame), in the solver's order (above). Empty when the
  // pose is out of reach. Throws KinematicsError for a bad redundancy_step only.
  [[nodiscard]] std::vector<JointSolution> inverse(const Transform& tip_pose,
                                                   const InverseOptions& options = {}) const;
  // The numeric solver (kNumeric above) whatever the chain: for chains near a closed form's
  // geometry but not on it, and to compare the two.
  [[nodiscard]] std::vector<JointSolution> inverse_numeric(
      const Transform& tip_pose, const InverseOptions& options = {}) const;

 private:
  void require_joint_values(std::span<const double> q) const;

  std::string name_, source_, base_link_, tip_link_;
  std::vector<MovingJoint> joints_{};
  Transform tip_offset_{Transform::Identity()};
  std::vector<RobotLinkInfo> links_{};
  IkMethod ik_method_{IkMethod::kNumeric};
  // Immutable, shared by copies of the model (it holds only numbers derived from the chain).
  std::shared_ptr<const internal::IkSolver> ik_{};
};

// The motion of one joint: rotation by q about `axis` or translation by q along it.
[[nodiscard]] Transform joint_motion(const MovingJoint& joint, double q);

}  // namespace spar::kinematics
