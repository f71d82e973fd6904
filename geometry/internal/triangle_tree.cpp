#include "spar/geometry/internal/triangle_tree.hpp"

#include <algorithm>
#include <cmath>
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

bool TriangleTree::for_each_in_oriented_box(const Eigen::Isometry3d& box_to_tree,
                                            const Eigen::Vector3d& low, const Eigen::Vector3d& high,
                                            const std::function<bool(int)>& visit) const {
  // Separating axes (Gottschalk's OBB test): the three axes of the tree's frame, the box's three
  // and their nine cross products. Two convex boxes are disjoint iff one of them separates them;
  // a rounding error can only make a test say "meets" where the boxes are disjoint by less than
  // about 1e-15 of their size, which the exact test then settles (the boxes are padded anyway).
  const Eigen::Matrix3d axes = box_to_tree.linear();  // columns: the box's axes
  const Eigen::Vector3d centre = box_to_tree * ((low + high) / 2);
  const Eigen::Vector3d half = (high - low) / 2;
  const Eigen::Matrix3d magnitude = axes.cwiseAbs();
  return search(
      [&](const Eigen::Vector3d& node_low, const Eigen::Vector3d& node_high) {
        const Eigen::Vector3d extent = (node_high - node_low) / 2;
        const Eigen::Vector3d offset = centre - (node_low + node_high) / 2;  // tree frame
        for (int i = 0; i < 3; ++i)                                          // the tree's axes
          if (std::abs(offset[i]) > extent[i] + magnitude.row(i).dot(half)) return false;
        const Eigen::Vector3d local = axes.transpose() * offset;  // in the box's axes
        for (int j = 0; j < 3; ++j)                               // the box's axes
          if (std::abs(local[j]) > half[j] + magnitude.col(j).dot(extent)) return false;
        for (int i = 0; i < 3; ++i)  // e_i x a_j
          for (int j = 0; j < 3; ++j) {
            const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            const double distance = std::abs(offset[i2] * axes(i1, j) - offset[i1] * axes(i2, j));
            const double reach = extent[i1] * magnitude(i2, j) + extent[i2] * magnitude(i1, j) +
                                 half[j1] * magnitude(i, j2) + half[j2] * magnitude(i, j1);
            if (distance > reach) return false;
          }
        return true;
      },
      visit);
}

namespace {

// Slab test on the closed box: whether the segment p + s·direction, s in [0, 1], meets it.
bool segment_meets_box(const Eigen::Vector3d& p, const Eigen::Vector3d& direction,
                       const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
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
}

}  // namespace

bool TriangleTree::any_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                  const std::function<bool(int)>& visit) const {
  const Eigen::Vector3d direction = q - p;
  return search(
      [&](const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
        return segment_meets_box(p, direction, low, high);
      },
      visit);
}

bool TriangleTree::segment_meets_box_of(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                                        int t) const {
  return segment_meets_box(p, q - p, low_[t], high_[t]);
}

}  // namespace spar::geometry::internal
