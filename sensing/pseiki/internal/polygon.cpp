#include "spar/sensing/pseiki/internal/polygon.hpp"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

namespace spar::sensing::pseiki::internal {
namespace {

namespace bg = boost::geometry;
using Point = bg::model::d2::point_xy<double>;
// Counter-clockwise, closed (first corner repeated) as Boost.Geometry's model stores it.
using Ring = bg::model::polygon<Point, /*ClockWise=*/false, /*Closed=*/true>;

Ring ring_of(const Polygon& polygon) {
  Ring ring;
  for (const Eigen::Vector2d& p : polygon) bg::append(ring.outer(), Point(p.x(), p.y()));
  if (!polygon.empty()) bg::append(ring.outer(), Point(polygon.front().x(), polygon.front().y()));
  return ring;
}

}  // namespace

Polygon convex_hull(const std::vector<Eigen::Vector2d>& points) {
  bg::model::multi_point<Point> cloud;
  for (const Eigen::Vector2d& p : points) bg::append(cloud, Point(p.x(), p.y()));
  Ring hull;
  bg::convex_hull(cloud, hull);
  Polygon out;
  const auto& corners = hull.outer();
  // Drop the closing corner; a hull of collinear points is degenerate.
  for (std::size_t i = 0; i + 1 < corners.size(); ++i)
    out.emplace_back(corners[i].x(), corners[i].y());
  if (out.size() < 3 || !(bg::area(hull) > 0)) return {};
  return out;
}

double area(const Polygon& polygon) {
  if (polygon.size() < 3) return 0;
  return std::abs(bg::area(ring_of(polygon)));
}

double overlap_area(const Polygon& a, const Polygon& b) {
  if (a.size() < 3 || b.size() < 3) return 0;
  std::vector<Ring> shared;
  bg::intersection(ring_of(a), ring_of(b), shared);
  double total = 0;
  for (const Ring& piece : shared) total += std::abs(bg::area(piece));
  return total;
}

}  // namespace spar::sensing::pseiki::internal
