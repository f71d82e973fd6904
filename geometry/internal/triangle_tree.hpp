// A bounding-box tree over a mesh's triangles: the grasp checks ask "which triangles could meet
// this segment / this box?" once per contact point and per grasp, so they cost O(log n + k) each
// instead of a pass over the whole mesh (which made `spar object` quadratic on meshes with many
// graspable face pairs).
//
// Invariants: every node's box contains the boxes of all triangles below it; leaves hold at most
// kLeafSize triangles; `order_` is a permutation of the triangle indices, each node owning one
// contiguous range of it. The tree only prunes: callers run their exact test on every triangle
// it reports, and a triangle it skips cannot meet the query (its box does not).
//
// Example:
//   const TriangleTree tree(mesh.vertices, mesh.triangles);
//   const bool blocked = tree.any_on_segment(p, q, [&](int t) { return hits(p, q, t); });
//   tree.for_each_in_box(low, high, [&](int t) { candidates.push_back(t); return false; });
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <functional>
#include <vector>

namespace spar::geometry::internal {

class TriangleTree {
 public:
  TriangleTree(const std::vector<Eigen::Vector3d>& vertices,
               const std::vector<std::array<int, 3>>& triangles);

  // Calls `visit(t)` for the triangles whose box meets the closed box [low, high] until it
  // returns true; returns whether one did.
  bool for_each_in_box(const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                       const std::function<bool(int)>& visit) const;
  // The same for the triangles whose box meets the oriented box [low, high] of the frame
  // `box_to_tree` (a rigid transform into the tree's frame). Pruning by the oriented box itself,
  // not by the axis-aligned box around it, is what keeps the grasp checks near O(log n + k) on a
  // finely tessellated object: the axis-aligned box of a tilted palm holds much of the mesh.
  bool for_each_in_oriented_box(const Eigen::Isometry3d& box_to_tree, const Eigen::Vector3d& low,
                                const Eigen::Vector3d& high,
                                const std::function<bool(int)>& visit) const;
  // The same for the triangles whose box meets the segment p-q.
  bool any_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                      const std::function<bool(int)>& visit) const;
  // Whether the segment p-q meets triangle t's box: the test any_on_segment() reports t by (a
  // node's test passes whenever a box inside it passes: the slab arithmetic is monotone), so a
  // caller that gathered t with for_each_in_box() around many segments can test each segment
  // against its own gathered triangles and get what any_on_segment() would.
  bool segment_meets_box_of(const Eigen::Vector3d& p, const Eigen::Vector3d& q, int t) const;

 private:
  static constexpr int kLeafSize = 4;
  struct Node {
    Eigen::Vector3d low, high;  // contains every triangle of order_[first, first + count)
    int first{0}, count{0};     // a leaf's triangles
    int left{-1}, right{-1};    // children (both -1 for a leaf)
  };
  int build(int first, int count, const std::vector<Eigen::Vector3d>& centres);
  template <typename Meets>
  bool search(const Meets& meets, const std::function<bool(int)>& visit) const;

  std::vector<Eigen::Vector3d> low_, high_;  // per triangle
  std::vector<int> order_;
  std::vector<Node> nodes_;  // nodes_[0] is the root (when there is a triangle)
};

}  // namespace spar::geometry::internal
