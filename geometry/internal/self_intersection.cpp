#include "spar/geometry/internal/self_intersection.hpp"

#include <CGAL/Bbox_3.h>
#include <CGAL/Box_intersection_d/Box_with_info_d.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>

namespace spar::geometry::internal {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int,
                                                      CGAL::Box_intersection_d::ID_EXPLICIT>;

class PairTest {
 public:
  PairTest(const std::vector<Eigen::Vector3d>& vertices,
           const std::vector<std::array<int, 3>>& triangles)
      : vertices_(vertices), triangles_(triangles) {}

  [[nodiscard]] bool cross(int a, int b) const {
    const std::array<int, 3>& s = triangles_[a];
    const std::array<int, 3>& t = triangles_[b];
    // Rotate both so their shared vertices come first, in s's order.
    std::array<int, 3> s_rot = s, t_rot = t;
    int shared = 0;
    for (int i = 0; i < 3; ++i) {
      const auto at = std::find(t.begin(), t.end(), s[i]);
      if (at == t.end()) continue;
      std::swap(s_rot[shared], s_rot[i]);
      std::swap(t_rot[shared], t_rot[at - t.begin()]);
      ++shared;
    }
    if (shared == 0) return CGAL::do_intersect(triangle(s), triangle(t));
    if (shared == 1) {
      return CGAL::do_intersect(Segment(point(s_rot[1]), point(s_rot[2])), triangle(t)) ||
             CGAL::do_intersect(Segment(point(t_rot[1]), point(t_rot[2])), triangle(s));
    }
    if (shared == 2) {
      const Point& p = point(s_rot[0]);
      const Point& q = point(s_rot[1]);
      return CGAL::coplanar(p, q, point(s_rot[2]), point(t_rot[2])) &&
             CGAL::coplanar_orientation(p, q, point(s_rot[2]), point(t_rot[2])) == CGAL::POSITIVE;
    }
    return true;  // the same three vertices twice
  }

 private:
  [[nodiscard]] Point point(int v) const {
    const Eigen::Vector3d& p = vertices_[v];
    return {p.x(), p.y(), p.z()};
  }
  [[nodiscard]] Triangle triangle(const std::array<int, 3>& t) const {
    return {point(t[0]), point(t[1]), point(t[2])};
  }

  const std::vector<Eigen::Vector3d>& vertices_;
  const std::vector<std::array<int, 3>>& triangles_;
};

}  // namespace

std::optional<std::pair<int, int>> find_self_intersection(
    const std::vector<Eigen::Vector3d>& vertices,
    const std::vector<std::array<int, 3>>& triangles) {
  std::vector<Box> boxes;
  boxes.reserve(triangles.size());
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    CGAL::Bbox_3 bounds;
    for (const int v : triangles[t]) {
      const Eigen::Vector3d& p = vertices[v];
      bounds += CGAL::Bbox_3(p.x(), p.y(), p.z(), p.x(), p.y(), p.z());
    }
    boxes.emplace_back(bounds, t);
  }
  const PairTest test(vertices, triangles);
  // Every crossing pair is visited and the first by index kept, so the answer does not depend on
  // the order CGAL reports pairs in.
  std::optional<std::pair<int, int>> first;
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& a, const Box& b) {
    const std::pair<int, int> pair{std::min(a.info(), b.info()), std::max(a.info(), b.info())};
    if ((!first || pair < *first) && test.cross(pair.first, pair.second)) first = pair;
  });
  return first;
}

}  // namespace spar::geometry::internal
