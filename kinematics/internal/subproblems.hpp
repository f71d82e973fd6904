// The Paden-Kahan subproblems that closed-form inverse kinematics of revolute chains reduces to
// (R. Murray, Z. Li, S. Sastry, "A Mathematical Introduction to Robotic Manipulation", 1994, §3.2;
// in the forms of A. Elias and J. Wen, "IK-Geo", 2022). rot(k, θ) is the rotation by θ about the
// unit axis k (right hand). Every function is exact where an exact solution exists and never
// produces NaN: a degenerate case (a vector on the axis) is reported, not divided by.
//
//   SP1  rot(k, θ) p = q                      one θ (p, q with equal axial parts and lengths)
//   SP4  h · rot(k, θ) p = d                  zero, one or two θ (a cos θ + b sin θ = c)
//   SP3  |rot(k, θ) p - q| = distance         via SP4; zero, one or two θ
//   SP2  rot(k1, θ1) p1 = rot(k2, θ2) p2      via SP4 then SP1; zero, one or two pairs
// Not public API: the closed-form solvers of closed_form_ik.cpp use them.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstddef>

namespace spar::kinematics::internal {

// rot(k, angle) for a unit axis k.
[[nodiscard]] Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle);

// Up to two angles. `degenerate`: the equation holds for every angle (the first angle, 0, is a
// representative); `tangent`: the two solutions coincide (a singular configuration), only one is
// listed.
struct Angles {
  std::array<double, 2> values{};
  std::size_t count{0};
  bool degenerate{false};
  bool tangent{false};
  void add(double angle) { values[count++] = angle; }
  [[nodiscard]] const double* begin() const { return values.data(); }
  [[nodiscard]] const double* end() const { return values.data() + count; }
};

// SP1: the angle that turns p's component perpendicular to k onto q's. `degenerate` when either
// perpendicular component is shorter than 1e-12 (the angle is then 0).
struct Angle {
  double value{0.0};
  bool degenerate{false};
};
[[nodiscard]] Angle angle_between_about(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                        const Eigen::Vector3d& k);

// SP4: every θ with h · rot(k, θ) p = d. A right-hand side beyond the reachable range by at most
// `tolerance` (relative to it) is taken as its end: one tangent solution.
[[nodiscard]] Angles solve_projection(const Eigen::Vector3d& h, const Eigen::Vector3d& p,
                                      const Eigen::Vector3d& k, double d, double tolerance = 1e-10);

// SP3: every θ with |rot(k, θ) p - q| = distance.
[[nodiscard]] Angles solve_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                    const Eigen::Vector3d& k, double distance,
                                    double tolerance = 1e-10);

// SP2: the pairs (θ1, θ2) with rot(k1, θ1) p1 = rot(k2, θ2) p2 (|p1| = |p2| for a solution).
struct AnglePairs {
  std::array<std::array<double, 2>, 2> values{};
  std::size_t count{0};
  bool degenerate{false};
  bool tangent{false};
};
[[nodiscard]] AnglePairs solve_two_rotations(const Eigen::Vector3d& p1, const Eigen::Vector3d& k1,
                                             const Eigen::Vector3d& p2, const Eigen::Vector3d& k2,
                                             double tolerance = 1e-10);

}  // namespace spar::kinematics::internal
