// Numeric helpers over a robot's moving joints that the model and its IK solvers share: forward
// kinematics, the geometric Jacobian, the pose error, Newton polishing, the zero-configuration
// screw geometry the closed forms start from, and joint-angle representatives. Not public API.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "spar/kinematics/robot.hpp"

namespace spar::kinematics::internal {

using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;
using PoseError = Eigen::Matrix<double, 6, 1>;

// The tip pose; q.size() == joints.size() (unchecked).
[[nodiscard]] Transform chain_forward(std::span<const MovingJoint> joints, const Transform& tip,
                                      std::span<const double> q);
// Columns [v; w]: the tip origin's velocity and the angular velocity per unit joint rate, base
// frame.
[[nodiscard]] Jacobian chain_jacobian(std::span<const MovingJoint> joints, const Transform& tip,
                                      std::span<const double> q);
// [p_target - p; w] with R_target = exp(w) R: what moves `pose` onto `target`, base frame.
[[nodiscard]] PoseError pose_error(const Transform& target, const Transform& pose);

// Up to `iterations` Gauss-Newton steps (least squares, minimum norm) from q towards the target,
// each kept only if it lowers the error. Returns the final error norm.
double polish(std::span<const MovingJoint> joints, const Transform& tip, const Transform& target,
              std::vector<double>& q, int iterations = 4);

// Moving joint i's axis direction and a point on it (the joint frame's origin), base frame, at
// q = 0, and the tip pose there: the product-of-exponentials form T(q) = e^(xi_1 q1) ...
// e^(xi_n qn) home, in which a revolute joint i turns everything after it by rot(axis_i, q_i)
// about the line through point_i.
struct ZeroGeometry {
  std::vector<Eigen::Vector3d> axis;
  std::vector<Eigen::Vector3d> point;
  Transform home{Transform::Identity()};
};
[[nodiscard]] ZeroGeometry zero_geometry(std::span<const MovingJoint> joints, const Transform& tip);

// The point where the lines (point_a, axis_a) and (point_b, axis_b) meet, if they are not
// parallel and come within `tolerance` metres of each other (the midpoint of the closest points).
[[nodiscard]] std::optional<Eigen::Vector3d> line_intersection(const Eigen::Vector3d& point_a,
                                                               const Eigen::Vector3d& axis_a,
                                                               const Eigen::Vector3d& point_b,
                                                               const Eigen::Vector3d& axis_b,
                                                               double tolerance);
[[nodiscard]] bool parallel(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance);

// Puts the revolute angle into (-pi, pi] if that is within `limits` widened by `tolerance`, else
// the smallest in-limit 2 pi multiple, else leaves it wrapped; returns whether it is within.
bool choose_representative(double& angle, const JointLimits& limits, double tolerance);
// For every joint: revolute angles as above, prismatic values checked as they are. Returns whether
// all are within limits.
bool choose_representatives(std::span<const MovingJoint> joints, std::span<double> q,
                            double tolerance);
// The smallest distance of any joint to the nearer of its limits, as a fraction of its range
// (unlimited joints count 0.5); negative when a joint is outside.
[[nodiscard]] double limit_margin(std::span<const MovingJoint> joints, std::span<const double> q);

// Throws nothing. Angles of a revolute joint differ by a 2 pi multiple only.
[[nodiscard]] bool same_configuration(std::span<const MovingJoint> joints,
                                      std::span<const double> a, std::span<const double> b,
                                      double tolerance);

}  // namespace spar::kinematics::internal
