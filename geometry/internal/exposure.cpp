#include "spar/geometry/internal/exposure.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace spar::geometry::internal {
namespace {

// Möller–Trumbore: does the segment from p to q cross the triangle (a, b, c) strictly inside
// the segment (beyond `slack` of parameter at either end)?
bool segment_hits_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                           const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                           const Eigen::Vector3d& c, double slack) {
  const Eigen::Vector3d direction = q - p, ab = b - a, ac = c - a;
  const Eigen::Vector3d h = direction.cross(ac);
  const double det = ab.dot(h);
  if (std::abs(det) < 1e-300) return false;
  const Eigen::Vector3d s = p - a;
  const double u = s.dot(h) / det;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d k = s.cross(ab);
  const double v = direction.dot(k) / det;
  if (v < 0 || u + v > 1) return false;
  const double t = ac.dot(k) / det;
  return t > slack && t < 1 - slack;
}

}  // namespace

Exposure::Exposure(const ObjectModel& object, const TriangleTree& tree,
                   const std::array<Eigen::Vector3d, 4>& corners, const Eigen::Vector3d& normal)
    : mesh_(&object.mesh()),
      tree_(&tree),
      normal_(normal),
      reach_(1e3 * (object.tolerance() / 1e-9)) {  // 1e3 diagonals: well past the object
  low_ = high_ = corners[0];
  for (const Eigen::Vector3d& c : corners) {
    low_ = low_.cwiseMin(c);
    high_ = high_.cwiseMax(c);
  }
  // Padded by far more than the rounding of a ray's end: every gathered ray lies inside.
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(1e-9 * reach_);
  low_ -= pad;
  high_ += pad;
  const Eigen::Vector3d far_low = (low_ + reach_ * normal_).cwiseMin(high_ + reach_ * normal_);
  const Eigen::Vector3d far_high = (low_ + reach_ * normal_).cwiseMax(high_ + reach_ * normal_);
  rays_low_ = low_.cwiseMin(far_low);
  rays_high_ = high_.cwiseMax(far_high);
  gathered_ = !tree.for_each_in_box(rays_low_, rays_high_, [&](int t) {
    blockers_.push_back(t);
    return blockers_.size() > kMaxBlockers;  // stop: the tree per point is cheaper
  });
}

bool Exposure::operator()(const Eigen::Vector3d& point) {
  const Eigen::Vector3d far = point + reach_ * normal_;
  const auto blocks = [&](int t) {
    const auto& tri = mesh_->triangles[t];
    return segment_hits_triangle(point, far, mesh_->vertices[tri[0]], mesh_->vertices[tri[1]],
                                 mesh_->vertices[tri[2]], kSlack);
  };
  const auto counts = [&](int t) {
    return tree_->segment_meets_box_of(point, far, t) && blocks(t);
  };
  if (last_blocker_ >= 0 && counts(last_blocker_)) return false;
  const bool in_region =
      (point.array() >= low_.array()).all() && (point.array() <= high_.array()).all();
  if (!gathered_ || !in_region)
    return !tree_->any_on_segment(point, far, [&](int t) {
      if (!blocks(t)) return false;
      last_blocker_ = t;
      return true;
    });
  const auto blocker = std::find_if(blockers_.begin(), blockers_.end(), counts);
  if (blocker == blockers_.end()) return true;
  last_blocker_ = *blocker;
  return false;
}

std::vector<char> Exposure::surely_blocked(const Eigen::Vector3d& origin,
                                           const Eigen::Vector3d& u_step,
                                           const Eigen::Vector3d& v_step, int n) const {
  std::vector<char> blocked(static_cast<std::size_t>(n) * n, 0);
  const double uu = u_step.squaredNorm(), vv = v_step.squaredNorm();
  if (!(uu > 0) || !(vv > 0)) return blocked;
  std::vector<int> crossed = blockers_;  // every triangle a ray of the region may cross
  if (!gathered_) {
    crossed.clear();
    (void)tree_->for_each_in_box(rays_low_, rays_high_, [&](int t) {
      crossed.push_back(t);
      return false;
    });
  }
  constexpr double kMargin = 1e-6;
  const double near = (kSlack + kMargin) * reach_, far = (1 - kSlack - kMargin) * reach_;
  const double shortest = 1e-3 * reach_ / 1e3;  // 1e-3 diagonals
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
  };
  for (const int t : crossed) {
    const auto& tri = mesh_->triangles[t];
    const Eigen::Vector3d& a = mesh_->vertices[tri[0]];
    const Eigen::Vector3d& b = mesh_->vertices[tri[1]];
    const Eigen::Vector3d& c = mesh_->vertices[tri[2]];
    const Eigen::Vector3d facing = (b - a).cross(c - a);
    // Tiny, or nearly along the rays: rounding could matter.
    if (!(std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) > shortest) ||
        !(std::abs(facing.dot(normal_)) >= 1e-3 * facing.norm()) || !(facing.norm() > 0))
      continue;
    std::array<Eigen::Vector2d, 3> corner;  // lattice units
    double depth_low = std::numeric_limits<double>::infinity(), depth_high = -depth_low;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = mesh_->vertices[tri[k]] - origin;
      corner[k] = {d.dot(u_step) / uu, d.dot(v_step) / vv};
      depth_low = std::min(depth_low, d.dot(normal_));
      depth_high = std::max(depth_high, d.dot(normal_));
    }
    // Out of reach, or a shadow too thin (or too vast) to measure in lattice units.
    const double twice_area = cross(corner[1] - corner[0], corner[2] - corner[0]);
    if (!(depth_low > near && depth_high < far) || !(std::abs(twice_area) > 0) ||
        !std::isfinite(twice_area))
      continue;
    const auto index_range = [&](int axis) {  // lattice indices within the corners' box
      double low = std::numeric_limits<double>::infinity(), high = -low;
      for (const Eigen::Vector2d& p : corner) {
        low = std::min(low, p[axis]);
        high = std::max(high, p[axis]);
      }
      // Clamped before the cast: a far triangle's lattice coordinates may be huge.
      return std::pair(static_cast<int>(std::clamp(std::ceil(low - 0.5), 0.0, 1.0 * n)),
                       static_cast<int>(std::clamp(std::floor(high - 0.5), -1.0, n - 1.0)));
    };
    const auto [i_low, i_high] = index_range(0);
    const auto [j_low, j_high] = index_range(1);
    for (int i = i_low; i <= i_high; ++i)
      for (int j = j_low; j <= j_high; ++j) {
        const Eigen::Vector2d q(i + 0.5, j + 0.5);
        bool inside = true;  // every barycentric coordinate at least the margin
        for (int k = 0; k < 3 && inside; ++k)
          inside = cross(corner[(k + 1) % 3] - q, corner[(k + 2) % 3] - q) / twice_area >= kMargin;
        if (inside) blocked[static_cast<std::size_t>(i) * n + j] = 1;
      }
  }
  return blocked;
}

}  // namespace spar::geometry::internal
