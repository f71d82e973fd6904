#include "spar/kinematics/dh.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace spar::kinematics {

DhChain::DhChain(std::string name, std::vector<DhJoint> joints, std::string source)
    : name_(std::move(name)), source_(std::move(source)), joints_(std::move(joints)) {
  if (joints_.empty()) throw KinematicsError("DH chain '" + name_ + "' has no joints");
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const DhJoint& joint = joints_[i];
    if (!(joint.limits.lower <= joint.limits.upper)) {
      std::ostringstream message;
      message << "DH chain '" << name_ << "': joint " << i + 1 << " has lower limit "
              << joint.limits.lower << " above upper limit " << joint.limits.upper;
      throw KinematicsError(message.str());
    }
    cos_alpha_.push_back(std::cos(joint.alpha));
    sin_alpha_.push_back(std::sin(joint.alpha));
  }
}

void DhChain::require_joint_count(std::size_t count) const {
  if (count != joints_.size()) {
    throw KinematicsError("robot '" + name_ + "' has " + std::to_string(joints_.size()) +
                          " joints but " + std::to_string(count) + " joint angles were given");
  }
}

Transform DhChain::forward(std::span<const double> q) const {
  require_joint_count(q.size());
  // Accumulate T = A_1 ... A_n as rotation R and translation p; A_i's rotation columns are
  // x = (ct, st, 0), y = (-st ca, ct ca, sa), z = (st sa, -ct sa, ca), its translation (a ct, a st,
  // d).
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const DhJoint& joint = joints_[i];
    const double theta = q[i] + joint.offset;
    const double ct = std::cos(theta);
    const double st = std::sin(theta);
    const double ca = cos_alpha_[i];
    const double sa = sin_alpha_[i];
    const Eigen::Vector3d x = rotation.col(0);
    const Eigen::Vector3d y = rotation.col(1);
    const Eigen::Vector3d z = rotation.col(2);
    position += joint.a * (ct * x + st * y) + joint.d * z;
    const Eigen::Vector3d new_x = ct * x + st * y;
    const Eigen::Vector3d in_plane_y = ct * y - st * x;
    rotation.col(0) = new_x;
    rotation.col(1) = ca * in_plane_y + sa * z;
    rotation.col(2) = ca * z - sa * in_plane_y;
  }
  Transform pose = Transform::Identity();
  pose.linear() = rotation;
  pose.translation() = position;
  return pose;
}

bool DhChain::within_limits(std::span<const double> q) const {
  require_joint_count(q.size());
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (!joints_[i].limits.contains(q[i])) return false;
  }
  return true;
}

Transform dh_link_transform(double theta, double d, double a, double alpha) {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(alpha), sa = std::sin(alpha);
  Transform link = Transform::Identity();
  link.linear() << ct, -st * ca, st * sa,  //
      st, ct * ca, -ct * sa,               //
      0.0, sa, ca;
  link.translation() << a * ct, a * st, d;
  return link;
}

double wrap_angle(double angle) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  double wrapped = std::remainder(angle, two_pi);  // in [-pi, pi]
  if (wrapped <= -std::numbers::pi) wrapped += two_pi;
  return wrapped;
}

Transform rigid_transform_from_row_major(std::span<const double> values, double tolerance) {
  if (values.size() != 16) {
    throw KinematicsError("a pose needs 16 numbers (a 4x4 matrix, row-major), got " +
                          std::to_string(values.size()));
  }
  for (double value : values) {
    if (!std::isfinite(value)) throw KinematicsError("pose matrix contains a non-finite number");
  }
  Eigen::Matrix4d matrix;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col)
      matrix(row, col) = values[static_cast<std::size_t>(4 * row + col)];
  const Eigen::RowVector4d bottom = matrix.row(3);
  if ((bottom - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > tolerance) {
    std::ostringstream message;
    message << "pose matrix is not homogeneous: last row is [" << bottom << "], expected [0 0 0 1]";
    throw KinematicsError(message.str());
  }
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const double orthonormality_error =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality_error > tolerance) {
    std::ostringstream message;
    message << "pose matrix is not rigid: its rotation block is not orthonormal (|R^T R - I| = "
            << orthonormality_error << " > " << tolerance << ")";
    throw KinematicsError(message.str());
  }
  if (rotation.determinant() < 0.0) {
    throw KinematicsError(
        "pose matrix is not rigid: its rotation block is a reflection (det = -1)");
  }
  Transform pose = Transform::Identity();
  pose.linear() = rotation;
  pose.translation() = matrix.topRightCorner<3, 1>();
  return pose;
}

}  // namespace spar::kinematics
