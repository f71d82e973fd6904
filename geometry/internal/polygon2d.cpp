#include "spar/geometry/internal/polygon2d.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace spar::geometry::internal {
namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// The signed distance of `point` from the line of edge i (positive on the polygon's side).
double edge_inset(const Polygon2& convex_polygon, std::size_t i, const Eigen::Vector2d& point) {
  const Eigen::Vector2d a = convex_polygon[i];
  const Eigen::Vector2d edge = convex_polygon[(i + 1) % convex_polygon.size()] - a;
  return cross(edge, point - a) / edge.norm();
}

}  // namespace

PlaneBasis plane_basis(const Eigen::Vector3d& unit_normal) {
  // Pick the world axis least aligned with the normal so the basis is well conditioned.
  Eigen::Index smallest = 0;
  unit_normal.cwiseAbs().minCoeff(&smallest);
  const Eigen::Vector3d axis = Eigen::Vector3d::Unit(smallest);
  const Eigen::Vector3d u = (axis - axis.dot(unit_normal) * unit_normal).normalized();
  return {u, unit_normal.cross(u)};
}

Eigen::Vector2d project(const PlaneBasis& basis, const Eigen::Vector3d& point) {
  return {basis.u.dot(point), basis.v.dot(point)};
}

Polygon2 convex_hull_2d(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  Polygon2 hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && cross(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

Polygon2 clip_convex(const Polygon2& subject, const Polygon2& clip) {
  // A half-plane adds at most one vertex to a convex polygon: two buffers of this size, reused
  // by every pass, seldom grow (rounding may bend a near-degenerate one).
  Polygon2 output, input;
  output.reserve(subject.size() + clip.size());
  input.reserve(subject.size() + clip.size());
  output.assign(subject.begin(), subject.end());
  for (std::size_t e = 0; e < clip.size() && !output.empty(); ++e) {
    const Eigen::Vector2d a = clip[e];
    const Eigen::Vector2d edge = clip[(e + 1) % clip.size()] - a;
    const auto side = [&](const Eigen::Vector2d& p) { return cross(edge, p - a); };
    input.swap(output);
    output.clear();
    for (std::size_t i = 0; i < input.size(); ++i) {
      const Eigen::Vector2d& current = input[i];
      const Eigen::Vector2d& previous = input[(i + input.size() - 1) % input.size()];
      const double s_current = side(current);
      const double s_previous = side(previous);
      if ((s_current >= 0) != (s_previous >= 0)) {
        const double t = s_previous / (s_previous - s_current);
        output.push_back(previous + t * (current - previous));
      }
      if (s_current >= 0) output.push_back(current);
    }
  }
  return output;
}

double signed_area(const Polygon2& polygon) {
  double twice_area = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
    twice_area += cross(polygon[i], polygon[(i + 1) % polygon.size()]);
  return twice_area / 2;
}

Eigen::Vector2d area_centroid(const Polygon2& polygon) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double twice_area = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const auto& p = polygon[i];
    const auto& q = polygon[(i + 1) % polygon.size()];
    const double w = cross(p, q);
    twice_area += w;
    sum += w * (p + q);
  }
  return sum / (3 * twice_area);
}

double inset_distance(const Polygon2& convex_polygon, const Eigen::Vector2d& point) {
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < convex_polygon.size(); ++i)
    smallest = std::min(smallest, edge_inset(convex_polygon, i, point));
  return smallest;
}

InsetTest::InsetTest(const Polygon2& convex_polygon, double distance)
    : distance_(distance),
      low_(Eigen::Vector2d::Constant(-std::numeric_limits<double>::infinity())),
      high_(-low_) {
  const std::size_t n = convex_polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d vector = convex_polygon[(i + 1) % n] - convex_polygon[i];
    edges_.push_back({convex_polygon[i], vector, vector.norm()});
  }
  const auto outward = [&](std::size_t i) -> Eigen::Vector2d {
    return Eigen::Vector2d(edges_[i].vector.y(), -edges_[i].vector.x()) / edges_[i].length;
  };
  const double t = -distance;
  if (n < 3 || !(t >= 0) || !std::isfinite(t)) return;
  for (std::size_t i = 0; i < n; ++i)
    if (!(edges_[i].length > 0) || !(cross(edges_[i].vector, edges_[(i + 1) % n].vector) >= 0))
      return;  // a point edge, a clockwise or reflex corner
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d n1 = outward((i + n - 1) % n), n2 = outward(i);
    const double meet = 1 + n1.dot(n2);
    // 1e-3: meet is then known to ~1e-13 relative, and the corner far inside the padding.
    if (!(meet >= 1e-3)) return;  // too sharp a corner to place its miter accurately
    const Eigen::Vector2d corner = convex_polygon[i] + t * (n1 + n2) / meet;
    low = low.cwiseMin(corner);
    high = high.cwiseMax(corner);
  }
  if (!low.allFinite() || !high.allFinite()) return;
  const double pad = 1e-9 * std::max({low.cwiseAbs().maxCoeff(), high.cwiseAbs().maxCoeff(),
                                      (high - low).maxCoeff()});
  low_ = low.array() - pad;
  high_ = high.array() + pad;
}

bool InsetTest::operator()(const Eigen::Vector2d& point) const {
  if (point.x() < low_.x() || point.x() > high_.x() || point.y() < low_.y() ||
      point.y() > high_.y())
    return false;
  for (const Edge& edge : edges_)
    if (cross(edge.vector, point - edge.start) / edge.length < distance_)
      return false;  // NaN (a point edge): skipped, as by std::min
  return true;
}

}  // namespace spar::geometry::internal
