// Small planar helpers shared by the stable-pose and grasp code: 2D convex hulls, convex clipping,
// areas, centroids and distances to a convex polygon's boundary. Polygons are counter-clockwise
// vertex lists without a repeated closing vertex.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace spar::geometry::internal {

using Polygon2 = std::vector<Eigen::Vector2d>;

// An orthonormal pair (u, v) with u × v = normal, so (u, v, normal) is right-handed and a polygon
// that is counter-clockwise seen from the side `normal` points to stays counter-clockwise in (u,
// v).
struct PlaneBasis {
  Eigen::Vector3d u;
  Eigen::Vector3d v;
};
[[nodiscard]] PlaneBasis plane_basis(const Eigen::Vector3d& unit_normal);
[[nodiscard]] Eigen::Vector2d project(const PlaneBasis& basis, const Eigen::Vector3d& point);

// Andrew's monotone chain; collinear points on the boundary are dropped.
[[nodiscard]] Polygon2 convex_hull_2d(std::vector<Eigen::Vector2d> points);
// Sutherland–Hodgman: the part of `subject` inside the convex, counter-clockwise `clip`.
[[nodiscard]] Polygon2 clip_convex(const Polygon2& subject, const Polygon2& clip);
[[nodiscard]] double signed_area(const Polygon2& polygon);
[[nodiscard]] Eigen::Vector2d area_centroid(const Polygon2& polygon);
// Smallest signed distance from `point` to the lines of the convex polygon's edges: positive
// inside, negative outside (then its magnitude is a lower bound of the true distance).
[[nodiscard]] double inset_distance(const Polygon2& convex_polygon, const Eigen::Vector2d& point);
// inset_distance(convex_polygon, point) >= distance, from the same per-edge values, stopping at
// the first edge below it.
[[nodiscard]] bool inset_at_least(const Polygon2& convex_polygon, const Eigen::Vector2d& point,
                                  double distance);

}  // namespace spar::geometry::internal
