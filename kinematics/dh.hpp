// Numeric Denavit-Hartenberg chains (standard, distal convention) and forward kinematics.
//
// A revolute joint i contributes the link transform
//     A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i),   theta_i = q_i + offset_i,
// and the chain maps joint angles to the pose of the last frame (the flange) in the base frame:
//     T(q) = A_1 A_2 ... A_n.
// Angles are radians, lengths metres. Poses are rigid transforms (Eigen::Isometry3d); a tool frame
// is composed by the caller (T(q) * tool).
//
// Example:
//   const spar::kinematics::DhChain& robot = spar::kinematics::puma560();
//   const std::vector<double> q = {0, 0.785, 3.14, 0, 0.785, 0};
//   const spar::kinematics::Transform flange = robot.forward(q);
//   Eigen::Vector3d where = flange.translation();
//   bool ok = robot.within_limits(q);  // false: q3 = 3.14 is outside +-135 degrees
#pragma once

#include <Eigen/Geometry>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include "spar/kinematics/error.hpp"

namespace spar::kinematics {

using Transform = Eigen::Isometry3d;

// Closed interval [lower, upper] of joint angles (radians); lower <= upper.
struct JointLimits {
  double lower{0.0};
  double upper{0.0};
  [[nodiscard]] bool contains(double q) const { return q >= lower && q <= upper; }
};

// One revolute joint of a standard-DH chain. theta = q + offset.
struct DhJoint {
  double d{0.0};
  double a{0.0};
  double alpha{0.0};
  double offset{0.0};
  JointLimits limits{};
};

// A serial chain of revolute DH joints. Invariant: at least one joint; cos/sin of every alpha are
// cached (cos_alpha_[i], sin_alpha_[i]) so forward() only evaluates the joint angles' trig.
class DhChain {
 public:
  // Throws KinematicsError on an empty joint list or a joint with lower > upper.
  DhChain(std::string name, std::vector<DhJoint> joints, std::string source = {});

  [[nodiscard]] const std::string& name() const { return name_; }
  // Where the table comes from (citation), shown by the CLI.
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] std::size_t size() const { return joints_.size(); }
  [[nodiscard]] const DhJoint& joint(std::size_t i) const { return joints_.at(i); }
  [[nodiscard]] const std::vector<DhJoint>& joints() const { return joints_; }

  // Pose of the last frame for joint angles q. Throws KinematicsError if q.size() != size().
  [[nodiscard]] Transform forward(std::span<const double> q) const;
  [[nodiscard]] Transform forward(std::initializer_list<double> q) const {
    return forward(std::span<const double>(q.begin(), q.size()));
  }
  // True if every q[i] lies in joint i's limits (no wrapping: the caller picks the representative).
  // Throws KinematicsError if q.size() != size().
  [[nodiscard]] bool within_limits(std::span<const double> q) const;

 private:
  void require_joint_count(std::size_t count) const;

  std::string name_;
  std::string source_;
  std::vector<DhJoint> joints_;
  std::vector<double> cos_alpha_;
  std::vector<double> sin_alpha_;
};

// The standard-DH link transform Rz(theta) Tz(d) Tx(a) Rx(alpha).
[[nodiscard]] Transform dh_link_transform(double theta, double d, double a, double alpha);

// Wraps an angle into (-pi, pi].
[[nodiscard]] double wrap_angle(double angle);

// Builds a pose from 16 numbers of a 4x4 homogeneous matrix in row-major order. Throws
// KinematicsError (naming the defect) unless the last row is [0 0 0 1] and the rotation block is
// orthonormal with determinant +1, each to within `tolerance`.
[[nodiscard]] Transform rigid_transform_from_row_major(std::span<const double> values,
                                                       double tolerance = 1e-6);

}  // namespace spar::kinematics
