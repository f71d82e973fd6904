// parse_stl (mesh_io.hpp) on CGAL's STL reader (CGAL::IO::read_STL: ASCII or binary, told apart
// by the `solid` keyword with a fall-back to the other form; identical points welded into one
// vertex). Like convex_hull.cpp, this translation unit keeps CGAL's headers to itself.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/STL.h>

#include <array>
#include <sstream>
#include <vector>

#include "spar/geometry/mesh_io.hpp"

namespace spar::geometry {

namespace {

using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;

// The file's points (identical ones welded) and triangles; throws GeometryError for a file that
// is not STL or has no triangle.
void read_stl(const std::string& bytes, const std::string& source, std::vector<Point>& points,
              std::vector<std::array<int, 3>>& facets) {
  std::istringstream stream(bytes, std::ios::in | std::ios::binary);
  if (!CGAL::IO::read_STL(stream, points, facets))
    throw GeometryError(source + ": not an STL file (CGAL's reader took it for neither ASCII " +
                        "'solid ... facet ... endsolid' nor binary: 80-byte header, count, " +
                        "50 bytes per triangle)");
  if (facets.empty()) throw GeometryError(source + ": the STL file has no triangles");
}

}  // namespace

Mesh parse_stl(const std::string& bytes, const std::string& source) {
  std::vector<Point> points;
  std::vector<std::array<int, 3>> facets;
  read_stl(bytes, source, points, facets);
  MeshBuilder builder(source);
  for (const Point& p : points) builder.add_vertex({p.x(), p.y(), p.z()});
  for (const std::array<int, 3>& facet : facets) builder.add_polygon(facet, "");
  return std::move(builder).build();
}

Mesh parse_stl_soup(const std::string& bytes, const std::string& source) {
  std::vector<Point> points;
  std::vector<std::array<int, 3>> facets;
  read_stl(bytes, source, points, facets);
  Mesh mesh;
  mesh.source = source;
  for (const Point& p : points) mesh.vertices.emplace_back(p.x(), p.y(), p.z());
  for (const std::array<int, 3>& facet : facets)
    if (facet[0] != facet[1] && facet[1] != facet[2] && facet[0] != facet[2])
      mesh.triangles.push_back(facet);
  if (mesh.triangles.empty())
    throw GeometryError(source + ": every triangle of the STL file is degenerate");
  mesh.triangle_names.assign(mesh.triangles.size(), "");
  mesh.triangle_lines.assign(mesh.triangles.size(), 0);
  return mesh;
}

}  // namespace spar::geometry
