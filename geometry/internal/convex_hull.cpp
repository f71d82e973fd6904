// CGAL::convex_hull_3 with the EPICK kernel (exact predicates, so the hull's combinatorics are
// right even for near-coplanar input) into a Surface_mesh; this is the only translation unit that
// includes CGAL.
#include "spar/geometry/internal/convex_hull.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <map>
#include <stdexcept>

namespace spar::geometry::internal {

std::vector<std::array<int, 3>> convex_hull_triangles(const std::vector<Eigen::Vector3d>& points) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = Kernel::Point_3;
  using SurfaceMesh = CGAL::Surface_mesh<Point>;

  std::vector<Point> cgal_points;
  cgal_points.reserve(points.size());
  // Hull vertices are input points, so we map them back to input indices by exact coordinates.
  std::map<std::array<double, 3>, int> index_of;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const Eigen::Vector3d& p = points[i];
    cgal_points.emplace_back(p.x(), p.y(), p.z());
    index_of.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, i);
  }
  SurfaceMesh hull;
  CGAL::convex_hull_3(cgal_points.begin(), cgal_points.end(), hull);

  std::vector<std::array<int, 3>> triangles;
  for (const auto face : hull.faces()) {
    std::array<int, 3> triangle{};
    int corner = 0;
    for (const auto vertex : CGAL::vertices_around_face(hull.halfedge(face), hull)) {
      if (corner == 3) throw std::logic_error("convex_hull_3 produced a non-triangular face");
      const Point& p = hull.point(vertex);
      triangle[corner++] = index_of.at({p.x(), p.y(), p.z()});
    }
    if (corner != 3) throw std::logic_error("convex_hull_3 produced a degenerate face");
    triangles.push_back(triangle);
  }
  return triangles;
}

}  // namespace spar::geometry::internal
