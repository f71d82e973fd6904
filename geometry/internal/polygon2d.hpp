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

// inset_distance(convex_polygon, point) >= distance for one polygon and distance and many points
// (the grasp search's contact regions ask it of a grid): the same per-edge values, each edge's
// vector and length computed once, stopping at the first edge below `distance`. First, a box no
// passing point lies outside of: for a counter-clockwise convex polygon and distance <= 0, the
// points that pass form the polygon with its edges moved out by -distance, whose corners are the
// vertices moved along their miters (v + t (n1 + n2) / (1 + n1 . n2), n1, n2 the two edges'
// outward unit normals); the box holds them, padded by 1e-9 of their extent against rounding.
// Without a box (every point goes to the edges): a point edge (its NaN value is skipped, as by
// inset_distance's minimum), a clockwise or non-convex polygon, a positive distance, or a corner
// sharper than 1 + n1 . n2 = 1e-3 (under 2.6 degrees inside, a miter over 45 times the distance).
class InsetTest {
 public:
  InsetTest(const Polygon2& convex_polygon, double distance);
  [[nodiscard]] bool operator()(const Eigen::Vector2d& point) const;

 private:
  struct Edge {
    Eigen::Vector2d start, vector;
    double length;
  };
  std::vector<Edge> edges_;
  double distance_;
  Eigen::Vector2d low_, high_;  // the box (infinite without one)
};

}  // namespace spar::geometry::internal
