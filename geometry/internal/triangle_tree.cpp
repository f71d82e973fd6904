#include "spar/geometry/internal/triangle_tree.hpp"

#include <algorithm>
#include <numeric>

namespace spar::geometry::internal {

TriangleTree::TriangleTree(const std::vector<Eigen::Vector3d>& vertices,
                           const std::vector<std::array<int, 3>>& triangles) {
  const int count = static_cast<int>(triangles.size());
  low_.resize(count);
  high_.resize(count);
  std::vector<Eigen::Vector3d> centres(count);
  for (int t = 0; t < count; ++t) {
    const auto& tri = triangles[t];
    low_[t] = vertices[tri[0]].cwiseMin(vertices[tri[1]]).cwiseMin(vertices[tri[2]]);
    high_[t] = vertices[tri[0]].cwiseMax(vertices[tri[1]]).cwiseMax(vertices[tri[2]]);
    centres[t] = (low_[t] + high_[t]) / 2;
  }
  // Pad every box by 1e-9 of the mesh's size, so a query that touches a box only within rounding
  // (a ray grazing a face) still reaches the exact test.
  if (count > 0) {
    Eigen::Vector3d all_low = low_[0], all_high = high_[0];
    for (int t = 1; t < count; ++t) {
      all_low = all_low.cwiseMin(low_[t]);
      all_high = all_high.cwiseMax(high_[t]);
    }
    const Eigen::Vector3d pad = Eigen::Vector3d::Constant(1e-9 * (all_high - all_low).norm());
    for (int t = 0; t < count; ++t) {
      low_[t] -= pad;
      high_[t] += pad;
    }
  }
  order_.resize(count);
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(2 * static_cast<std::size_t>(count / kLeafSize + 1));
  if (count > 0) build(0, count, centres);
}

// Splits at the median centre along the longest side of the range's centre box.
int TriangleTree::build(int first, int count, const std::vector<Eigen::Vector3d>& centres) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d low = low_[order_[first]], high = high_[order_[first]];
  Eigen::Vector3d centre_low = centres[order_[first]], centre_high = centre_low;
  for (int i = first; i < first + count; ++i) {
    low = low.cwiseMin(low_[order_[i]]);
    high = high.cwiseMax(high_[order_[i]]);
    centre_low = centre_low.cwiseMin(centres[order_[i]]);
    centre_high = centre_high.cwiseMax(centres[order_[i]]);
  }
  nodes_[index].low = low;
  nodes_[index].high = high;
  nodes_[index].first = first;
  nodes_[index].count = count;
  if (count <= kLeafSize) return index;
  int axis = 0;
  (centre_high - centre_low).maxCoeff(&axis);
  const int half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half,
                   order_.begin() + first + count,
                   [&](int a, int b) { return centres[a][axis] < centres[b][axis]; });
  const int left = build(first, half, centres);
  const int right = build(first + half, count - half, centres);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

template <typename Meets>
bool TriangleTree::search(const Meets& meets, const std::function<bool(int)>& visit) const {
  if (nodes_.empty()) return false;
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    if (!meets(node.low, node.high)) continue;
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const int t = order_[i];
        if (meets(low_[t], high_[t]) && visit(t)) return true;
      }
      continue;
    }
    stack.push_back(node.right);
    stack.push_back(node.left);
  }
  return false;
}

bool TriangleTree::for_each_in_box(const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                                   const std::function<bool(int)>& visit) const {
  return search(
      [&](const Eigen::Vector3d& box_low, const Eigen::Vector3d& box_high) {
        return (box_low.array() <= high.array()).all() && (low.array() <= box_high.array()).all();
      },
      visit);
}

bool TriangleTree::any_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                  const std::function<bool(int)>& visit) const {
  const Eigen::Vector3d direction = q - p;
  // Slab test on the closed box: the parameter range [0, 1] of the segment inside every slab.
  return search(
      [&](const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
        double enter = 0, leave = 1;
        for (int axis = 0; axis < 3; ++axis) {
          if (direction[axis] == 0) {
            if (p[axis] < low[axis] || p[axis] > high[axis]) return false;
            continue;
          }
          double t0 = (low[axis] - p[axis]) / direction[axis];
          double t1 = (high[axis] - p[axis]) / direction[axis];
          if (t0 > t1) std::swap(t0, t1);
          enter = std::max(enter, t0);
          leave = std::min(leave, t1);
          if (enter > leave) return false;
        }
        return true;
      },
      visit);
}

}  // namespace spar::geometry::internal
