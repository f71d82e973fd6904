#include "spar/kinematics/internal/chain.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

namespace spar::kinematics::internal {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// wrap_angle for the few-turns angles the solvers produce, without a division.
double wrap_small_angle(double angle) {
  if (!(std::abs(angle) < 8.0 * kPi)) return wrap_angle(angle);
  while (angle > kPi) angle -= kTwoPi;
  while (angle <= -kPi) angle += kTwoPi;
  return angle;
}

}  // namespace

Transform chain_forward(std::span<const MovingJoint> joints, const Transform& tip,
                        std::span<const double> q) {
  Transform pose = Transform::Identity();
  for (std::size_t i = 0; i < joints.size(); ++i)
    pose = pose * joints[i].origin * joint_motion(joints[i], q[i]);
  return pose * tip;
}

Jacobian chain_jacobian(std::span<const MovingJoint> joints, const Transform& tip,
                        std::span<const double> q) {
  const Eigen::Index n = static_cast<Eigen::Index>(joints.size());
  Jacobian jacobian(6, n);
  std::vector<Transform> frames(joints.size());
  Transform pose = Transform::Identity();
  for (std::size_t i = 0; i < joints.size(); ++i) {
    pose = pose * joints[i].origin;
    frames[i] = pose;  // joint frame before its motion: the axis is fixed in it
    pose = pose * joint_motion(joints[i], q[i]);
  }
  const Eigen::Vector3d tip_position = (pose * tip).translation();
  for (Eigen::Index i = 0; i < n; ++i) {
    const MovingJoint& joint = joints[static_cast<std::size_t>(i)];
    const Transform& frame = frames[static_cast<std::size_t>(i)];
    const Eigen::Vector3d axis = frame.linear() * joint.axis;
    if (joint.type == JointType::kPrismatic) {
      jacobian.col(i) << axis, Eigen::Vector3d::Zero();
    } else {
      jacobian.col(i) << axis.cross(tip_position - frame.translation()), axis;
    }
  }
  return jacobian;
}

PoseError pose_error(const Transform& target, const Transform& pose) {
  PoseError error;
  const Eigen::AngleAxisd turn(target.linear() * pose.linear().transpose());
  error << target.translation() - pose.translation(), turn.angle() * turn.axis();
  return error;
}

double polish(std::span<const MovingJoint> joints, const Transform& tip, const Transform& target,
              std::vector<double>& q, int iterations) {
  PoseError error = pose_error(target, chain_forward(joints, tip, q));
  double norm = error.norm();
  for (int iteration = 0; iteration < iterations && norm > 0.0; ++iteration) {
    const Jacobian jacobian = chain_jacobian(joints, tip, q);
    const Eigen::VectorXd step =
        jacobian.completeOrthogonalDecomposition().solve(error);  // least squares, minimum norm
    std::vector<double> candidate = q;
    for (std::size_t i = 0; i < q.size(); ++i) candidate[i] += step[static_cast<Eigen::Index>(i)];
    const PoseError candidate_error = pose_error(target, chain_forward(joints, tip, candidate));
    if (!(candidate_error.norm() < norm)) break;
    q = std::move(candidate);
    error = candidate_error;
    norm = error.norm();
  }
  return norm;
}

ZeroGeometry zero_geometry(std::span<const MovingJoint> joints, const Transform& tip) {
  ZeroGeometry geometry;
  Transform pose = Transform::Identity();
  for (const MovingJoint& joint : joints) {
    pose = pose * joint.origin;
    geometry.axis.push_back((pose.linear() * joint.axis).normalized());
    geometry.point.push_back(pose.translation());
  }
  geometry.home = pose * tip;
  return geometry;
}

bool parallel(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance) {
  return a.cross(b).norm() <= tolerance;
}

std::optional<Eigen::Vector3d> line_intersection(const Eigen::Vector3d& point_a,
                                                 const Eigen::Vector3d& axis_a,
                                                 const Eigen::Vector3d& point_b,
                                                 const Eigen::Vector3d& axis_b, double tolerance) {
  // Closest points point_a + s axis_a and point_b + t axis_b (unit axes).
  const double cosine = axis_a.dot(axis_b);
  const double denominator = 1.0 - cosine * cosine;
  if (denominator < 1e-12) return std::nullopt;
  const Eigen::Vector3d between = point_b - point_a;
  const double s = (between.dot(axis_a) - cosine * between.dot(axis_b)) / denominator;
  const double t = (cosine * between.dot(axis_a) - between.dot(axis_b)) / denominator;
  const Eigen::Vector3d on_a = point_a + s * axis_a;
  const Eigen::Vector3d on_b = point_b + t * axis_b;
  if ((on_a - on_b).norm() > tolerance) return std::nullopt;
  return (on_a + on_b) / 2.0;
}

bool choose_representative(double& angle, const JointLimits& limits, double tolerance) {
  const JointLimits widened{limits.lower - tolerance, limits.upper + tolerance};
  angle = wrap_small_angle(angle);
  if (widened.contains(angle)) return true;
  const double candidate = angle + kTwoPi * std::ceil((widened.lower - angle) / kTwoPi);
  if (widened.contains(candidate)) {
    angle = candidate;
    return true;
  }
  return false;
}

bool choose_representatives(std::span<const MovingJoint> joints, std::span<double> q,
                            double tolerance) {
  bool within = true;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].type == JointType::kRevolute) {
      within &= choose_representative(q[i], joints[i].limits, tolerance);
    } else {
      within &=
          q[i] >= joints[i].limits.lower - tolerance && q[i] <= joints[i].limits.upper + tolerance;
    }
  }
  return within;
}

double limit_margin(std::span<const MovingJoint> joints, std::span<const double> q) {
  double margin = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const JointLimits& limits = joints[i].limits;
    const double range = limits.upper - limits.lower;
    if (!std::isfinite(range)) {
      margin = std::min(margin, 0.5);
      continue;
    }
    const double distance = std::min(q[i] - limits.lower, limits.upper - q[i]);
    margin = std::min(margin, range > 0.0 ? distance / range : (distance >= 0.0 ? 0.0 : -1.0));
  }
  return margin;
}

bool same_configuration(std::span<const MovingJoint> joints, std::span<const double> a,
                        std::span<const double> b, double tolerance) {
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const double difference =
        joints[i].type == JointType::kRevolute ? wrap_small_angle(a[i] - b[i]) : a[i] - b[i];
    if (std::abs(difference) > tolerance) return false;
  }
  return true;
}

}  // namespace spar::kinematics::internal
