// reports/internal/silhouette.hpp on the built-in objects' meshes turned every way: the outline
// covers the projection (Boost's union of the projected triangles used to lose parts of it) and
// lies within the hull of the projected corners.
#include "spar/reports/internal/silhouette.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "spar/geometry/builtin_objects.hpp"

namespace spar::reports::internal {
namespace {

// Outer rings count positive, holes negative (the header's turning).
double area(const std::vector<Ring>& rings) {
  double sum = 0;
  for (const Ring& ring : rings)
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const auto& p = ring[i];
      const auto& q = ring[(i + 1) % ring.size()];
      sum += 0.5 * (p[0] * q[1] - q[0] * p[1]);
    }
  return sum;
}

// Corners of `ring` within 1e-9 of the line through their neighbours (flat for the silhouette,
// whose tolerance is 1e-7 of the drawing's size, on any drawing larger than 1 cm).
std::size_t flat_corners(const Ring& ring) {
  std::size_t flat = 0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const auto& a = ring[(i + ring.size() - 1) % ring.size()];
    const auto& b = ring[i];
    const auto& c = ring[(i + 1) % ring.size()];
    const double along_x = c[0] - a[0], along_y = c[1] - a[1];
    const double length = std::hypot(along_x, along_y);
    flat += length == 0 ||
            std::fabs(along_x * (b[1] - a[1]) - along_y * (b[0] - a[0])) <= 1e-9 * length;
  }
  return flat;
}

// The mesh's faces turned, seen from above (x, y): every face, or those whose outward normal
// points up.
std::vector<Polygon2> from_above(const geometry::Mesh& mesh, const Eigen::Matrix3d& turn,
                                 bool facing_only) {
  std::vector<Polygon2> faces;
  for (const auto& triangle : mesh.triangles) {
    const Eigen::Vector3d a = turn * mesh.vertices[triangle[0]],
                          b = turn * mesh.vertices[triangle[1]],
                          c = turn * mesh.vertices[triangle[2]];
    if (facing_only && !((b - a).cross(c - a).z() > 0)) continue;
    faces.push_back({a.head<2>(), b.head<2>(), c.head<2>()});
  }
  return faces;
}

// The projection's area counted on a grid: a grid point is covered when some face (turned either
// way) holds it. Robust where a union is not; `cells` per side of the bounding square.
double covered_area(const std::vector<Polygon2>& faces, int cells) {
  Eigen::Vector2d low = Eigen::Vector2d::Constant(HUGE_VAL), high = -low;
  for (const Polygon2& face : faces)
    for (const Eigen::Vector2d& p : face) low = low.cwiseMin(p), high = high.cwiseMax(p);
  const Eigen::Vector2d step = (high - low) / cells;
  const auto inside = [](const Polygon2& t, const Eigen::Vector2d& p) {
    double sign = 0;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2d e = t[(i + 1) % 3] - t[i], d = p - t[i];
      const double cross = e.x() * d.y() - e.y() * d.x();
      if (cross * sign < 0) return false;
      if (cross != 0) sign = cross;
    }
    return true;
  };
  int covered = 0;
  for (int i = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j) {
      const Eigen::Vector2d p = low + step.cwiseProduct(Eigen::Vector2d(i + 0.5, j + 0.5));
      covered +=
          std::any_of(faces.begin(), faces.end(), [&](const Polygon2& t) { return inside(t, p); });
    }
  return covered * step.x() * step.y();
}

// The area of the convex hull of the faces' corners (Andrew's monotone chain).
double hull_area(const std::vector<Polygon2>& faces) {
  std::vector<Eigen::Vector2d> points;
  for (const Polygon2& face : faces) points.insert(points.end(), face.begin(), face.end());
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  const auto turn = [](const auto& o, const auto& a, const auto& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  Ring ring;
  for (const Eigen::Vector2d& p : hull) ring.push_back({p.x(), p.y()});
  return area({ring});
}

RC_GTEST_PROP(Silhouette, OutlineOfATurnedMeshCoversItsProjection, ()) {
  const std::vector<std::string> names = geometry::builtin_object_names();
  const std::string name = *rc::gen::elementOf(names);
  const geometry::Mesh mesh = geometry::builtin_mesh(name);
  // A turn about a random axis; small angles leave faces nearly edge-on.
  const double angle = *rc::gen::inRange(0, 360) * M_PI / 180;
  const int x = *rc::gen::inRange(-4, 5), y = *rc::gen::inRange(-4, 5), z = *rc::gen::inRange(1, 5);
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(angle, Eigen::Vector3d(x, y, z).normalized()).toRotationMatrix();
  const std::vector<Polygon2> faces = from_above(mesh, turn, false);
  const double projection = covered_area(faces, 300);
  const std::vector<Ring> rings = silhouette(faces);
  const double outline = area(rings);
  const double hull = hull_area(faces);
  RC_LOG() << name << " projection " << projection << " outline " << outline << " hull " << hull
           << std::endl;
  RC_ASSERT(outline >= 0.98 * projection);
  RC_ASSERT(outline <= 1.0001 * hull);
  for (const Ring& ring : rings) {
    RC_ASSERT(ring.size() >= 3U);
    RC_ASSERT(ring.front() == *std::min_element(ring.begin(), ring.end()));
    RC_ASSERT(flat_corners(ring) == 0);
  }
}

// A spike out and back along one line (Boost's union leaves some where projected triangles meet
// edge to edge) or a point on a straight edge is no corner of an outline. The block's faces
// facing up, turned 156 degrees about (0.1, 0.2, 1.3), left one (found in a 1-degree sweep of the
// built-in objects about three axes; the twelve examples' outlines had 14 such spikes).
TEST(Silhouette, NoSpikesOrStraightCorners) {
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(156 * M_PI / 180, Eigen::Vector3d(0.1, 0.2, 1.3).normalized())
          .toRotationMatrix();
  const std::vector<Ring> rings =
      silhouette(from_above(geometry::builtin_mesh("block"), turn, true));
  ASSERT_FALSE(rings.empty());
  for (const Ring& ring : rings) EXPECT_EQ(flat_corners(ring), 0U);
}

// The property compares areas, and a face missing from a union shows in its area (the block's
// top from above without one of its triangles, which no other face turned up covers).
TEST(Silhouette, AMissingFaceShowsInTheArea) {
  const geometry::Mesh mesh = geometry::builtin_mesh("block");
  std::vector<Polygon2> faces = from_above(mesh, Eigen::Matrix3d::Identity(), true);
  ASSERT_GT(faces.size(), 1U);
  const double whole = area(silhouette(faces));
  faces.pop_back();
  EXPECT_LT(area(silhouette(faces)), whole * (1 - 1e-6));
}

}  // namespace
}  // namespace spar::reports::internal
