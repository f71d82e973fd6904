// The features a sensor can observe on an object model: its faces (geometry/object.hpp numbers
// them 1..N, as `spar object` prints them) and its edges, the lines where two faces meet.
//
// Model edges: two planar faces meet along a straight line, so the mesh edges separating faces a
// and b are collinear; each maximal connected run of them is one model edge (a face pair that
// touches along two separate pieces has two). Mesh edges inside a face (between its coplanar
// triangles) are not features. Ids run 1..M per object, ordered by (face_a, face_b, then the
// run's direction and start along the pair's line), so a mesh always gives the same ids. `p0` ->
// `p1` runs along face_a's boundary in its counter-clockwise direction seen from outside. Dihedral:
// the angle between the two outward normals, in (0, pi); `convex` is true for a ridge (the solid's
// interior angle at the edge is below pi, as every edge of a box) and false for a valley (the inner
// corner of a slot). face_edges[f - 1]: the ids of the edges bounding face f, ascending.
//
// Cost: O(T log T) for T triangles.
//
// Example:
//   const ObjectFeatures cube = object_features(ObjectModel("cube", make_box({1, 1, 1})));
//   cube.edges.size();              // 12
//   cube.edges[0].face_a;           // 1 (the faces it separates, a < b)
//   cube.edges[0].dihedral;         // pi / 2
//   cube.face_edges[0].size();      // 4: face 1 is bounded by four edges
#pragma once

#include <Eigen/Core>
#include <vector>

#include "spar/geometry/object.hpp"

namespace spar::sensing {

struct ModelEdge {
  int id{0};                 // 1-based per object
  int face_a{0}, face_b{0};  // the faces it separates (ids), face_a < face_b
  Eigen::Vector3d p0{Eigen::Vector3d::Zero()}, p1{Eigen::Vector3d::Zero()};  // object frame
  double dihedral{0};  // angle between the faces' outward normals, radians
  bool convex{true};   // a ridge (true) or a valley (false)
  [[nodiscard]] double length() const { return (p1 - p0).norm(); }
};

struct ObjectFeatures {
  std::vector<ModelEdge> edges;              // edges[id - 1].id == id
  std::vector<std::vector<int>> face_edges;  // [face id - 1] -> edge ids, ascending
  std::vector<int> triangle_face;            // [mesh triangle] -> face id
};

[[nodiscard]] ObjectFeatures object_features(const geometry::ObjectModel& model);

}  // namespace spar::sensing
