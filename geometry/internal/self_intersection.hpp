// Does a closed triangle mesh cross itself? CGAL's box intersection finds the pairs of triangles
// whose bounding boxes meet (O(n log n) for a mesh of well-shaped triangles) and its exact
// predicates decide each pair, so the answer is exact for the given double coordinates.
//
// Triangles that share a vertex or an edge touch there by construction; they count as crossing
// only if they meet elsewhere: for a shared edge, when the two lie in one plane on the same side of
// it (folded onto each other); for a shared vertex, when the edge opposite it in either triangle
// meets the other triangle (the test CGAL's Polygon_mesh_processing uses).
//
// Like convex_hull.cpp, this translation unit keeps CGAL's headers to itself.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <utility>
#include <vector>

namespace spar::geometry::internal {

// The first pair of triangles (indices into `triangles`, first < second, lexicographically
// smallest) that cross, or nothing. Precondition:
// vertices are welded (equal positions have equal indices) and no triangle is degenerate.
[[nodiscard]] std::optional<std::pair<int, int>> find_self_intersection(
    const std::vector<Eigen::Vector3d>& vertices, const std::vector<std::array<int, 3>>& triangles);

}  // namespace spar::geometry::internal
