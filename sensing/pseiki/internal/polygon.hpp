// Plane polygons for PSEIKI's face level, on Boost.Geometry: the convex hull of a face's edge end
// points (the region a face covers in an image or the expected scene) and the area two regions
// share (the face-level incompatibility, survey section 4: "the overlap between them normalized by
// the average area of the two faces").
//
// A Polygon is a convex polygon's corners, counter-clockwise in (u, v) pixels; fewer than three
// corners (all points on one line) has area 0 and overlaps nothing.
//
// Example:
//   const Polygon square = convex_hull({{0, 0}, {2, 0}, {2, 2}, {0, 2}, {1, 1}});   // 4 corners
//   area(square);                                                                 // 4
//   overlap_area(square, convex_hull({{1, 1}, {3, 1}, {3, 3}, {1, 3}}));          // 1
#pragma once

#include <Eigen/Core>
#include <vector>

namespace spar::sensing::pseiki::internal {

using Polygon = std::vector<Eigen::Vector2d>;

[[nodiscard]] Polygon convex_hull(const std::vector<Eigen::Vector2d>& points);
[[nodiscard]] double area(const Polygon& polygon);
[[nodiscard]] double overlap_area(const Polygon& a, const Polygon& b);

}  // namespace spar::sensing::pseiki::internal
