#include "spar/kinematics/internal/subproblems.hpp"

#include <algorithm>
#include <cmath>

namespace spar::kinematics::internal {
namespace {

// Below this length a vector's component perpendicular to an axis has no direction.
constexpr double kNoDirection = 1e-12;

}  // namespace

Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

Angle angle_between_about(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                          const Eigen::Vector3d& k) {
  const Eigen::Vector3d p_perpendicular = p - k.dot(p) * k;
  const Eigen::Vector3d q_perpendicular = q - k.dot(q) * k;
  if (p_perpendicular.norm() < kNoDirection || q_perpendicular.norm() < kNoDirection)
    return {.value = 0.0, .degenerate = true};
  return {.value = std::atan2(k.dot(p_perpendicular.cross(q_perpendicular)),
                              p_perpendicular.dot(q_perpendicular)),
          .degenerate = false};
}

Angles solve_projection(const Eigen::Vector3d& h, const Eigen::Vector3d& p,
                        const Eigen::Vector3d& k, double d, double tolerance) {
  // rot(k, θ) p = (k·p) k + cos θ p_perp + sin θ (k × p), so a cos θ + b sin θ = c.
  const Eigen::Vector3d p_perpendicular = p - k.dot(p) * k;
  const double a = h.dot(p_perpendicular);
  const double b = h.dot(k.cross(p));
  const double c = d - k.dot(p) * h.dot(k);
  const double amplitude = std::hypot(a, b);
  Angles angles;
  if (amplitude < kNoDirection * std::max(1.0, h.norm() * p.norm())) {
    // The left side does not depend on θ.
    if (std::abs(c) <= tolerance * std::max(1.0, std::abs(d))) {
      angles.degenerate = true;
      angles.add(0.0);
    }
    return angles;
  }
  const double ratio = c / amplitude;
  if (std::abs(ratio) > 1.0 + tolerance) return angles;
  const double centre = std::atan2(b, a);
  const double half_width = std::acos(std::clamp(ratio, -1.0, 1.0));
  if (half_width < 1e-12 || std::abs(ratio) >= 1.0) {
    angles.tangent = true;
    angles.add(centre + half_width);
    return angles;
  }
  angles.add(centre + half_width);
  angles.add(centre - half_width);
  return angles;
}

Angles solve_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& k,
                      double distance, double tolerance) {
  // |rot p - q|^2 = |p|^2 + |q|^2 - 2 q · rot p.
  return solve_projection(q, p, k, (p.squaredNorm() + q.squaredNorm() - distance * distance) / 2,
                          tolerance);
}

AnglePairs solve_two_rotations(const Eigen::Vector3d& p1, const Eigen::Vector3d& k1,
                               const Eigen::Vector3d& p2, const Eigen::Vector3d& k2,
                               double tolerance) {
  // rot(k2, θ2) p2 keeps its component along k2, so k2 · rot(k1, θ1) p1 = k2 · p2 fixes θ1; then
  // θ2 turns p2 onto rot(k1, θ1) p1.
  AnglePairs pairs;
  const Angles first = solve_projection(k2, p1, k1, k2.dot(p2), tolerance);
  pairs.degenerate = first.degenerate;
  pairs.tangent = first.tangent;
  for (const double theta1 : first) {
    const Angle second = angle_between_about(p2, rotation_about(k1, theta1) * p1, k2);
    pairs.degenerate |= second.degenerate;
    pairs.values[pairs.count++] = {theta1, second.value};
  }
  return pairs;
}

}  // namespace spar::kinematics::internal
