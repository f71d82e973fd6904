// Exposure: can a finger reach a point of a face from outside? The ray from the point along the
// face's outward normal must leave the object without crossing it (rules out faces inside holes
// and faces the object hides). The grasp search (grasps.cpp) asks this for both contacts of every
// candidate contact position.
//
// One Exposure answers for the points of one region of a face plane (the quadrilateral
// `corners`) along one normal, rays `reach` long (1e3 of the object's diagonals: well past it).
// A triangle blocks a ray when the ray meets its box and then crosses it (Möller–Trumbore)
// strictly between kSlack of its length from either end (hits at the start are the face itself
// or its neighbours' edges) -- exactly what TriangleTree's walk per ray decides.
//
// Invariants and how it stays fast:
//   - the triangles that could block any ray of the region are gathered once (their boxes meet
//     the box that holds every ray); a point of the region then tests only them, the triangle
//     that blocked the last ray first. The answer does not depend on that order. A point outside
//     the region, or a region whose rays pass more than kMaxBlockers triangles, walks the tree.
//   - surely_blocked() settles a whole lattice of points at once: a point inside the shadow
//     (along the normal) of a triangle that every ray from the shadow crosses well between its
//     ends is blocked; "well" is a margin far above rounding (below), so operator() would say
//     false for it too. It never marks a point operator() calls exposed (a property test checks
//     it on every face of the block and of random turned stepped solids).
// Cost: gathering O(log n + k); operator() O(k) or a tree walk; surely_blocked O(k) triangles
// plus a few 2-D tests per lattice point in each one's shadow.
//
// Example:
//   const TriangleTree tree(object.mesh().vertices, object.mesh().triangles);
//   Exposure exposed(object, tree, region_corners, face.normal);
//   const bool reachable = exposed(point_on_face);             // casts one ray
//   const std::vector<char> hidden = exposed.surely_blocked(origin, u_step, v_step, 41);
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "spar/geometry/internal/triangle_tree.hpp"
#include "spar/geometry/object.hpp"

namespace spar::geometry::internal {

class Exposure {
 public:
  static constexpr std::size_t kMaxBlockers = 64;
  static constexpr double kSlack = 1e-9;  // of a ray's length: hits nearer its ends do not count

  // `object` and `tree` (over the object's mesh) must outlive the Exposure.
  Exposure(const ObjectModel& object, const TriangleTree& tree,
           const std::array<Eigen::Vector3d, 4>& corners, const Eigen::Vector3d& normal);

  // Does the ray from `point` along the normal leave the object uncrossed? Not const: it
  // remembers the last blocker (one Exposure per region, on one thread).
  bool operator()(const Eigen::Vector3d& point);

  // Which points of the n x n lattice origin + (i + 1/2) u_step + (j + 1/2) v_step (index
  // i n + j; u_step and v_step at right angles to each other and to the normal) surely get
  // false from operator(), without casting their rays. The margins: barycentric coordinates (the
  // same in any affine frame, so computed in lattice units) of at least 1e-6; depths along the
  // normal at least 1e-6 of the reach past the slack at either end (a depth inside the triangle
  // lies between its corners'); a triangle at least 1e-3 from parallel to the rays and longer
  // than 1e-3 diagonals. Points near a triangle's edge are left to operator().
  [[nodiscard]] std::vector<char> surely_blocked(const Eigen::Vector3d& origin,
                                                 const Eigen::Vector3d& u_step,
                                                 const Eigen::Vector3d& v_step, int n) const;

 private:
  const Mesh* mesh_;
  const TriangleTree* tree_;
  Eigen::Vector3d normal_;
  double reach_;
  Eigen::Vector3d low_, high_;            // the region's box, padded
  Eigen::Vector3d rays_low_, rays_high_;  // a box holding every ray from the region
  std::vector<int> blockers_;             // the triangles a ray from the region may cross
  bool gathered_{false};                  // blockers_ holds them all
  int last_blocker_{-1};                  // the triangle that blocked the last blocked ray
};

}  // namespace spar::geometry::internal
