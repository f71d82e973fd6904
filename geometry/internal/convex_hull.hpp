// A door to CGAL (with self_intersection.hpp): the convex hull of a point set as outward-oriented
// triangles.
// CGAL's headers are slow to compile, so they stay inside convex_hull.cpp; callers see Eigen only.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace spar::geometry::internal {

// Triangles of the hull, each as three indices into `points`, counter-clockwise seen from outside.
// Precondition: the points span three dimensions (callers check; CGAL's output for a flat set is
// a degenerate polygon mesh, which the caller rejects before it gets here).
[[nodiscard]] std::vector<std::array<int, 3>> convex_hull_triangles(
    const std::vector<Eigen::Vector3d>& points);

}  // namespace spar::geometry::internal
