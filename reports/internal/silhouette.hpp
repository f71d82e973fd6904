// The silhouette of a body seen along an axis (reports/ only): the union of its faces projected
// onto a plane, as rings. Boost.Geometry computes the union (cascaded: pairs of pieces, then pairs
// of those, so n faces cost about n log n ring operations); faces seen edge-on are skipped, and
// collinear points and spikes (out and back along one line) are dropped from the result.
//
// Invariants: every ring is closed implicitly (the last point is not repeated), outer rings run
// counter-clockwise and holes clockwise (x right, y up), each starts at its lowest corner (least x,
// then least y: the rings do not depend on where Boost starts them), and no ring has fewer than 3
// points.
// Corners are snapped to a grid of 1e-9 drawing sizes first (Boost's union is far more reliable
// on it). A union Boost.Geometry cannot form (degenerate input it refuses), or one that misses a
// piece (no point of the union near the piece's centroid), falls back to the convex hull of every
// point, which contains the silhouette.
//
// Example:
//   std::vector<Polygon2> faces = {{{0, 0}, {1, 0}, {0, 1}}, {{1, 0}, {1, 1}, {0, 1}}};
//   const std::vector<Ring> rings = silhouette(faces);   // one ring: the unit square
#pragma once

#include <Eigen/Core>
#include <vector>

#include "spar/reports/model.hpp"

namespace spar::reports::internal {

// A convex polygon (a projected triangle or box face), either orientation.
using Polygon2 = std::vector<Eigen::Vector2d>;

[[nodiscard]] std::vector<Ring> silhouette(const std::vector<Polygon2>& pieces);

}  // namespace spar::reports::internal
