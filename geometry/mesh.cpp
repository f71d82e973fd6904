#include "spar/geometry/mesh.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <numeric>
#include <sstream>
#include <utility>

#include "spar/geometry/internal/convex_hull.hpp"
#include "spar/geometry/internal/edge_index.hpp"
#include "spar/geometry/internal/self_intersection.hpp"

namespace spar::geometry {
namespace {

Eigen::Vector3d triangle_normal(const Mesh& mesh, const std::array<int, 3>& t) {
  const auto& v = mesh.vertices;
  return (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);  // length = twice the area
}

double bounding_diagonal(const std::vector<Eigen::Vector3d>& points) {
  if (points.empty()) return 0;
  Eigen::Vector3d low = points.front(), high = points.front();
  for (const auto& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  return (high - low).norm();
}

// The edge checks of validate_closed_mesh, each reporting the first offence in a fixed order:
// an edge of more than two triangles (two solids touching along it), an edge run twice in one
// direction (inconsistent orientation), an edge run only once (a hole).
void check_edges(const Mesh& mesh, const internal::EdgeIndex& index) {
  const auto& edges = index.edges();
  // Undirected uses: an edge of > 2 triangles; reported at the lowest triangle that has one.
  std::vector<std::pair<std::uint64_t, int>> undirected;
  undirected.reserve(edges.size());
  for (const auto& [key, t] : edges) {
    const int a = internal::EdgeIndex::from(key), b = internal::EdgeIndex::to(key);
    undirected.push_back({internal::EdgeIndex::key(std::min(a, b), std::max(a, b)), t});
  }
  std::sort(undirected.begin(), undirected.end());
  int crowded = -1, crowded_uses = 0;
  std::uint64_t crowded_edge = 0;
  for (std::size_t i = 0, j = 0; i < undirected.size(); i = j) {
    while (j < undirected.size() && undirected[j].first == undirected[i].first) ++j;
    if (j - i > 2 && (crowded < 0 || undirected[i].second < crowded)) {
      crowded = undirected[i].second;  // the lowest triangle of the run (sorted by triangle)
      crowded_uses = static_cast<int>(j - i);
      crowded_edge = undirected[i].first;
    }
  }
  if (crowded >= 0)
    throw GeometryError(mesh.where(crowded) + ": the edge between vertices " +
                        std::to_string(internal::EdgeIndex::from(crowded_edge)) + " and " +
                        std::to_string(internal::EdgeIndex::to(crowded_edge)) + " is shared by " +
                        std::to_string(crowded_uses) +
                        " triangles (a non-manifold edge: two solids touching along an edge "
                        "are not one object)");
  // The same direction twice: reported at the later triangle, the lowest such.
  int twice = -1;
  std::size_t twice_at = 0;
  for (std::size_t i = 1; i < edges.size(); ++i)
    if (edges[i].first == edges[i - 1].first && (twice < 0 || edges[i].second < twice)) {
      twice = edges[i].second;
      twice_at = i;
    }
  if (twice >= 0)
    throw GeometryError(mesh.where(twice) + ": edge between vertices " +
                        std::to_string(internal::EdgeIndex::from(edges[twice_at].first)) + " and " +
                        std::to_string(internal::EdgeIndex::to(edges[twice_at].first)) +
                        " is also used in the same direction at " +
                        mesh.where(edges[twice_at - 1].second) +
                        " (polygons inconsistently oriented, or a non-manifold edge)");
  for (const auto& [key, t] : edges)  // in edge order
    if (index.owner(internal::EdgeIndex::to(key), internal::EdgeIndex::from(key)) < 0)
      throw GeometryError(mesh.where(t) + ": mesh is not closed: the edge between vertices " +
                          std::to_string(internal::EdgeIndex::from(key)) + " and " +
                          std::to_string(internal::EdgeIndex::to(key)) +
                          " belongs to only one polygon");
}

// One object is one connected solid: every triangle reaches every other across shared edges, and
// the triangles around each vertex form one fan (else two solids touch at that vertex). Two cubes
// sharing only a vertex, or lying apart, pass every edge check but are not one object. Called on a
// closed mesh (every directed edge has its opposite).
void check_one_solid(const Mesh& mesh, const internal::EdgeIndex& index) {
  const int count = static_cast<int>(mesh.triangles.size());
  std::vector<int> parent(count);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  for (const auto& [key, t] : index.edges())
    parent[root(t)] =
        root(index.owner(internal::EdgeIndex::to(key), internal::EdgeIndex::from(key)));
  for (int t = 1; t < count; ++t)
    if (root(t) != root(0))
      throw GeometryError(mesh.where(t) +
                          ": the mesh is more than one solid: this polygon is not "
                          "connected to the one at " +
                          mesh.where(0) +
                          " by shared edges (an object is one piece: give each piece as its own "
                          "object)");
  // Around a vertex v, the triangle running (u, v) is followed by the one running (v, u): walk
  // one fan from each vertex's first triangle and compare with all its triangles.
  std::vector<int> triangles_at(mesh.vertices.size(), 0);
  std::vector<int> first_at(mesh.vertices.size(), -1);
  for (int t = 0; t < count; ++t)
    for (const int v : mesh.triangles[t]) {
      ++triangles_at[v];
      if (first_at[v] < 0) first_at[v] = t;
    }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (first_at[v] < 0) continue;
    int t = first_at[v], fan = 0;
    do {
      const auto& tri = mesh.triangles[t];
      const int corner = tri[0] == static_cast<int>(v) ? 0 : tri[1] == static_cast<int>(v) ? 1 : 2;
      const int previous = tri[(corner + 2) % 3];      // t runs (previous, v)
      t = index.owner(static_cast<int>(v), previous);  // the neighbour runs (v, previous)
      ++fan;
    } while (t != first_at[v] && fan <= triangles_at[v]);
    if (fan != triangles_at[v])
      throw GeometryError(mesh.where(first_at[v]) + ": the mesh touches itself at vertex " +
                          std::to_string(v) + ": its polygons there form " +
                          "more than one fan (two solids meeting at a point are not one object)");
  }
}

}  // namespace

std::string Mesh::where(int t) const {
  if (t >= 0 && t < static_cast<int>(triangle_lines.size()) && triangle_lines[t] > 0)
    return source + ":" + std::to_string(triangle_lines[t]);
  return source + " (triangle " + std::to_string(t) + ")";
}

MeshBuilder::MeshBuilder(std::string source) { mesh_.source = std::move(source); }

int MeshBuilder::add_vertex(const Eigen::Vector3d& point) {
  mesh_.vertices.push_back(point);
  return static_cast<int>(mesh_.vertices.size()) - 1;
}

void MeshBuilder::add_polygon(std::span<const int> loop, const std::string& name, int line) {
  const std::string where = line > 0 ? mesh_.source + ":" + std::to_string(line) : mesh_.source;
  if (loop.size() < 3)
    throw GeometryError(where + ": a polygon needs at least 3 vertices, got " +
                        std::to_string(loop.size()));
  for (const int index : loop)
    if (index < 0 || index >= static_cast<int>(mesh_.vertices.size()))
      throw GeometryError(where + ": vertex index " + std::to_string(index) +
                          " is out of range (the file has " +
                          std::to_string(mesh_.vertices.size()) + " vertices)");
  // Newell's normal of the whole loop; every fan triangle must agree with it, else the polygon is
  // not convex (or not planar) and a fan would fold over itself.
  const auto& v = mesh_.vertices;
  Eigen::Vector3d newell = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < loop.size(); ++i)
    newell += v[loop[i]].cross(v[loop[(i + 1) % loop.size()]]);
  // Convex: every corner turns the same way as the whole loop (straight corners are allowed).
  for (std::size_t i = 0; loop.size() > 3 && i < loop.size(); ++i) {
    const Eigen::Vector3d& before = v[loop[(i + loop.size() - 1) % loop.size()]];
    const Eigen::Vector3d& corner = v[loop[i]];
    const Eigen::Vector3d& after = v[loop[(i + 1) % loop.size()]];
    if ((corner - before).cross(after - corner).dot(newell) < -1e-12 * newell.squaredNorm())
      throw GeometryError(where + ": polygon is not convex; split it into convex polygons");
  }
  for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
    const std::array<int, 3> triangle{loop[0], loop[i], loop[i + 1]};
    mesh_.triangles.push_back(triangle);
    mesh_.triangle_names.push_back(name);
    mesh_.triangle_lines.push_back(line);
  }
}

Mesh MeshBuilder::build(double scale, MeshCheck check) && {
  if (scale != 1.0) mesh_ = scale_mesh(std::move(mesh_), scale);
  if (check == MeshCheck::kValidate) validate_closed_mesh(mesh_);
  return std::move(mesh_);
}

std::uint64_t content_digest(const Mesh& mesh) {
  std::uint64_t digest = 0;
  const auto add = [&](std::uint64_t word) {  // splitmix64's step and finalizer, chained
    digest = (digest ^ word) + 0x9e3779b97f4a7c15ULL;
    digest = (digest ^ (digest >> 30)) * 0xbf58476d1ce4e5b9ULL;
    digest = (digest ^ (digest >> 27)) * 0x94d049bb133111ebULL;
    digest ^= digest >> 31;
  };
  add(mesh.vertices.size());
  for (const Eigen::Vector3d& v : mesh.vertices)
    for (int axis = 0; axis < 3; ++axis) add(std::bit_cast<std::uint64_t>(v[axis]));
  add(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    for (const int index : t) add(static_cast<std::uint32_t>(index));
  return digest | 1;  // never 0, which means "not validated"
}

void validate_closed_mesh(Mesh& mesh) {
  if (mesh.validated_digest != 0 && mesh.validated_digest == content_digest(mesh)) return;
  if (mesh.triangles.size() < 4)
    throw GeometryError(mesh.source + ": a closed mesh needs at least 4 triangles, got " +
                        std::to_string(mesh.triangles.size()));
  // Weld vertices at identical positions so soups with repeated vertices still close up: each
  // joins the lowest index at its position (indices sorted by position, then index).
  std::vector<int> weld(mesh.vertices.size());
  {
    std::vector<int> order(mesh.vertices.size());
    std::iota(order.begin(), order.end(), 0);
    const auto position = [&](int i) {
      const auto& p = mesh.vertices[i];
      return std::array<double, 3>{p.x(), p.y(), p.z()};
    };
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return std::pair{position(a), a} < std::pair{position(b), b};
    });
    for (std::size_t k = 0; k < order.size(); ++k)
      weld[order[k]] =
          k > 0 && position(order[k]) == position(order[k - 1]) ? weld[order[k - 1]] : order[k];
  }
  std::vector<Eigen::Vector3d> used;
  for (auto& triangle : mesh.triangles)
    for (int& index : triangle) {
      if (index < 0 || index >= static_cast<int>(mesh.vertices.size()))
        throw GeometryError(mesh.source + ": vertex index " + std::to_string(index) +
                            " out of range");
      index = weld[index];
      used.push_back(mesh.vertices[index]);
    }
  const double scale = bounding_diagonal(used);
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t)
    if (triangle_normal(mesh, mesh.triangles[t]).norm() <= 1e-12 * scale * scale)
      throw GeometryError(mesh.where(t) +
                          ": degenerate triangle (zero area: repeated or collinear"
                          " vertices)");
  const internal::EdgeIndex edges(mesh.triangles);
  check_edges(mesh, edges);
  const double volume = volume_properties(mesh).volume;
  if (std::abs(volume) <= 1e-12 * scale * scale * scale)
    throw GeometryError(mesh.source + ": mesh encloses no volume (all vertices are coplanar)");
  if (const auto crossing = internal::find_self_intersection(mesh.vertices, mesh.triangles))
    throw GeometryError(mesh.where(crossing->first) +
                        ": the mesh intersects itself: this polygon crosses the one at " +
                        mesh.where(crossing->second) +
                        " (volume, centre of mass and faces need a closed surface that does not "
                        "cross itself)");
  check_one_solid(mesh, edges);
  if (volume < 0)  // consistently inward: the same solid, so turn every triangle outward
    for (auto& triangle : mesh.triangles) std::swap(triangle[1], triangle[2]);
  mesh.validated_digest = content_digest(mesh);
}

VolumeProperties volume_properties(const Mesh& mesh) {
  if (mesh.triangles.empty()) return {};
  const Eigen::Vector3d origin = mesh.vertices[mesh.triangles.front()[0]];
  double six_volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]] - origin;
    const Eigen::Vector3d b = mesh.vertices[t[1]] - origin;
    const Eigen::Vector3d c = mesh.vertices[t[2]] - origin;
    const double w = a.dot(b.cross(c));  // six times the signed tetrahedron (origin, a, b, c)
    six_volume += w;
    moment += w * (a + b + c) / 4;
  }
  VolumeProperties properties;
  properties.volume = six_volume / 6;
  properties.centroid = six_volume != 0 ? Eigen::Vector3d(origin + moment / six_volume) : origin;
  return properties;
}

Mesh scale_mesh(Mesh mesh, double factor) {
  if (!(factor > 0 && std::isfinite(factor)))
    throw GeometryError(mesh.source + ": scale factor must be finite and > 0, got " +
                        std::to_string(factor));
  for (Eigen::Vector3d& vertex : mesh.vertices) vertex *= factor;
  return mesh;
}

Mesh make_box(const Eigen::Vector3d& size) {
  if ((size.array() <= 0).any()) throw GeometryError("make_box: every side must be positive");
  return RectilinearSolid({0, size.x()}, {0, size.y()}, {0, size.z()}).to_mesh("<box>");
}

std::vector<Eigen::Vector2d> regular_polygon(double radius, int sides) {
  if (sides < 3 || radius <= 0)
    throw GeometryError("regular_polygon: needs at least 3 sides and a positive radius");
  std::vector<Eigen::Vector2d> polygon;
  for (int k = 0; k < sides; ++k) {
    // Offset by half a step so the polygon has flats (parallel faces) facing the axes.
    const double angle = 2 * std::numbers::pi * (k + 0.5) / sides;
    polygon.emplace_back(radius * std::cos(angle), radius * std::sin(angle));
  }
  return polygon;
}

namespace {

// Adds the walls and far cap of `polygon` x [z0, z0 + height]; `base` holds the base ring's
// vertex indices (same order as polygon).
void add_prism_walls(MeshBuilder& builder, const std::vector<int>& base,
                     const std::vector<Eigen::Vector2d>& polygon, double z0, double height,
                     const std::string& prefix) {
  const int n = static_cast<int>(polygon.size());
  std::vector<int> top;
  for (const auto& p : polygon) top.push_back(builder.add_vertex({p.x(), p.y(), z0 + height}));
  for (int k = 0; k < n; ++k) {
    const std::array<int, 4> quad{base[k], base[(k + 1) % n], top[(k + 1) % n], top[k]};
    builder.add_polygon(quad, prefix + "side " + std::to_string(k + 1));
  }
  builder.add_polygon(top, prefix.empty() ? "top" : prefix + "end");
}

}  // namespace

Mesh make_prism(const std::vector<Eigen::Vector2d>& polygon, double height) {
  if (height <= 0) throw GeometryError("make_prism: height must be positive");
  MeshBuilder builder("<prism>");
  std::vector<int> base;
  for (const auto& p : polygon) base.push_back(builder.add_vertex({p.x(), p.y(), 0}));
  const std::vector<int> bottom(base.rbegin(), base.rend());  // seen from below
  builder.add_polygon(bottom, "bottom");
  add_prism_walls(builder, base, polygon, 0, height, "");
  return std::move(builder).build();
}

Mesh make_convex_hull(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 4) throw GeometryError("convex hull: needs at least 4 points");
  Eigen::MatrixXd centered(3, points.size());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) centered.col(i) = points[i] - mean;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centered);
  const auto singular = svd.singularValues();
  if (singular(2) <= 1e-9 * singular(0))
    throw GeometryError("convex hull: the points are coplanar (or collinear): no solid");
  Mesh mesh;
  mesh.source = "<convex hull>";
  mesh.vertices = points;
  mesh.triangles = internal::convex_hull_triangles(points);
  mesh.triangle_names.assign(mesh.triangles.size(), "");
  mesh.triangle_lines.assign(mesh.triangles.size(), 0);
  validate_closed_mesh(mesh);
  return mesh;
}

RectilinearSolid::RectilinearSolid(std::vector<double> xs, std::vector<double> ys,
                                   std::vector<double> zs)
    : coordinates_{std::move(xs), std::move(ys), std::move(zs)} {
  for (const auto& axis : coordinates_) {
    if (axis.size() < 2) throw GeometryError("RectilinearSolid: each axis needs 2 coordinates");
    if (!std::is_sorted(axis.begin(), axis.end(), std::less_equal<>()))
      throw GeometryError("RectilinearSolid: coordinates must strictly increase");
  }
  filled_.assign(
      (coordinates_[0].size() - 1) * (coordinates_[1].size() - 1) * (coordinates_[2].size() - 1),
      1);
}

bool RectilinearSolid::filled(int i, int j, int k) const {
  const int nx = static_cast<int>(coordinates_[0].size()) - 1;
  const int ny = static_cast<int>(coordinates_[1].size()) - 1;
  const int nz = static_cast<int>(coordinates_[2].size()) - 1;
  if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return false;
  return filled_[(k * ny + j) * nx + i] != 0;
}

void RectilinearSolid::set_filled(int i, int j, int k, bool value) {
  const int nx = static_cast<int>(coordinates_[0].size()) - 1;
  const int ny = static_cast<int>(coordinates_[1].size()) - 1;
  const int nz = static_cast<int>(coordinates_[2].size()) - 1;
  if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz)
    throw GeometryError("RectilinearSolid: cell index out of range");
  filled_[(k * ny + j) * nx + i] = value ? 1 : 0;
}

void RectilinearSolid::carve(const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  const auto& [xs, ys, zs] = coordinates_;
  for (std::size_t k = 0; k + 1 < zs.size(); ++k)
    for (std::size_t j = 0; j + 1 < ys.size(); ++j)
      for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
        const Eigen::Vector3d centre((xs[i] + xs[i + 1]) / 2, (ys[j] + ys[j + 1]) / 2,
                                     (zs[k] + zs[k + 1]) / 2);
        if ((centre.array() > low.array()).all() && (centre.array() < high.array()).all())
          set_filled(static_cast<int>(i), static_cast<int>(j), static_cast<int>(k), false);
      }
}

Mesh RectilinearSolid::to_mesh(const std::string& source, MeshCheck check) const {
  MeshBuilder builder(source);
  std::map<std::array<int, 3>, int> grid_vertex;
  const auto vertex = [&](std::array<int, 3> g) {
    const auto it = grid_vertex.find(g);
    if (it != grid_vertex.end()) return it->second;
    const int index =
        builder.add_vertex({coordinates_[0][g[0]], coordinates_[1][g[1]], coordinates_[2][g[2]]});
    grid_vertex.emplace(g, index);
    return index;
  };
  static const char* const kNames[3][2] = {{"-x", "+x"}, {"-y", "+y"}, {"-z", "+z"}};
  const int n[3] = {static_cast<int>(coordinates_[0].size()) - 1,
                    static_cast<int>(coordinates_[1].size()) - 1,
                    static_cast<int>(coordinates_[2].size()) - 1};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i) {
            std::array<int, 3> cell{i, j, k};
            std::array<int, 3> neighbour = cell;
            neighbour[axis] += side == 1 ? 1 : -1;
            if (!filled(i, j, k) || filled(neighbour[0], neighbour[1], neighbour[2])) continue;
            // Quad in the plane axis = cell[axis] + side, counter-clockwise in the (b, c) axes
            // that make (axis, b, c) right-handed; reversed on the negative side.
            const int b = (axis + 1) % 3, c = (axis + 2) % 3;
            std::array<int, 3> g = cell;
            g[axis] += side;
            std::array<int, 4> quad{};
            const int offsets[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int q = 0; q < 4; ++q) {
              std::array<int, 3> corner = g;
              corner[b] += offsets[q][0];
              corner[c] += offsets[q][1];
              quad[q] = vertex(corner);
            }
            if (side == 0) std::reverse(quad.begin(), quad.end());
            std::ostringstream name;  // e.g. "+z (z=3)": direction and plane
            name << kNames[axis][side] << " ("
                 << "xyz"[axis] << '=' << coordinates_[axis][g[axis]] << ')';
            builder.add_polygon(quad, name.str());
          }
  return std::move(builder).build(1.0, check);
}

namespace {

// A mesh with its upward faces at top_z taken out, the loop that outlined them (counter-clockwise
// seen from above) and the name of their face.
struct OpenedTop {
  Mesh kept;
  std::vector<int> outline;
  std::string face_name;
};

OpenedTop open_top(const Mesh& mesh, double top_z) {
  const double tolerance = 1e-9 * (1 + std::abs(top_z));
  OpenedTop out{mesh, {}, {}};
  out.kept.triangles.clear();
  out.kept.triangle_names.clear();
  out.kept.triangle_lines.clear();
  std::vector<std::pair<int, int>> removed_edges;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    const Eigen::Vector3d normal = triangle_normal(mesh, tri);
    const bool on_top = normal.z() > 0 && normal.head<2>().norm() <= 1e-9 * normal.norm() &&
                        std::all_of(tri.begin(), tri.end(), [&](int v) {
                          return std::abs(mesh.vertices[v].z() - top_z) <= tolerance;
                        });
    if (!on_top) {
      out.kept.triangles.push_back(tri);
      out.kept.triangle_names.push_back(mesh.triangle_names[t]);
      out.kept.triangle_lines.push_back(mesh.triangle_lines[t]);
      continue;
    }
    if (out.face_name.empty()) out.face_name = mesh.triangle_names[t];
    for (int c = 0; c < 3; ++c) removed_edges.emplace_back(tri[c], tri[(c + 1) % 3]);
  }
  std::map<int, int> next_on_outline;  // directed boundary edges of the removed region
  for (const auto& [a, b] : removed_edges)
    if (std::find(removed_edges.begin(), removed_edges.end(), std::pair{b, a}) ==
        removed_edges.end())
      next_on_outline[a] = b;
  if (next_on_outline.empty())
    throw GeometryError(mesh.source +
                        ": attach_prism found no upward face at z = " + std::to_string(top_z));
  out.outline = {next_on_outline.begin()->first};
  while (true) {
    const int next = next_on_outline.at(out.outline.back());
    if (next == out.outline.front()) break;
    out.outline.push_back(next);
    if (out.outline.size() > next_on_outline.size())
      throw GeometryError(mesh.source + ": attach_prism: the top face outline is not one loop");
  }
  if (out.outline.size() != next_on_outline.size())
    throw GeometryError(mesh.source + ": attach_prism: the top face outline is not one loop");
  return out;
}

// Zips the outer loop (vertex ids, `vertices`) and the prism's base (ids `base` at `polygon`) by
// angle about the polygon's centre: both loops are counter-clockwise seen from above, so each
// step adds one triangle of the ring.
void zip_ring(MeshBuilder& builder, const std::vector<Eigen::Vector3d>& vertices,
              const std::vector<int>& outer, const std::vector<int>& base,
              const std::vector<Eigen::Vector2d>& polygon, const std::string& ring_name) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& p : polygon) centre += p;
  centre /= static_cast<double>(polygon.size());
  const auto angle = [&](const Eigen::Vector2d& p) {
    return std::atan2(p.y() - centre.y(), p.x() - centre.x());
  };
  const double start = angle(polygon.front());
  const auto unwrap = [&](double a) {
    double d = std::fmod(a - start, 2 * std::numbers::pi);
    if (d < 0) d += 2 * std::numbers::pi;
    return start + d;
  };
  const int m = static_cast<int>(outer.size());
  const int n = static_cast<int>(polygon.size());
  int first_outer = 0;
  for (int j = 1; j < m; ++j)
    if (unwrap(angle(vertices[outer[j]].head<2>())) <
        unwrap(angle(vertices[outer[first_outer]].head<2>())))
      first_outer = j;
  const auto outer_vertex = [&](int j) { return outer[(first_outer + j) % m]; };
  const auto outer_angle = [&](int j) {
    return unwrap(angle(vertices[outer_vertex(j % m)].head<2>())) +
           (j >= m ? 2 * std::numbers::pi : 0);
  };
  const auto inner_angle = [&](int k) {
    return k >= n ? start + 2 * std::numbers::pi : unwrap(angle(polygon[k]));
  };
  for (int a = 0, b = 0; a < m || b < n;) {
    if (a < m && (b == n || outer_angle(a + 1) <= inner_angle(b + 1))) {
      const std::array<int, 3> tri{outer_vertex(a), outer_vertex(a + 1), base[b % n]};
      builder.add_polygon(tri, ring_name);
      ++a;
    } else {
      const std::array<int, 3> tri{base[b % n], outer_vertex(a), base[(b + 1) % n]};
      builder.add_polygon(tri, ring_name);
      ++b;
    }
  }
}

}  // namespace

void attach_prism(Mesh& mesh, double top_z, const std::vector<Eigen::Vector2d>& polygon,
                  double height, const std::string& name, MeshCheck check) {
  // Take out the upward triangles at top_z; their outline is the ring's outer loop.
  const OpenedTop top = open_top(mesh, top_z);
  MeshBuilder builder(mesh.source);
  for (const auto& p : top.kept.vertices) builder.add_vertex(p);
  for (std::size_t t = 0; t < top.kept.triangles.size(); ++t)  // first: face ids keep their order
    builder.add_polygon(top.kept.triangles[t], top.kept.triangle_names[t],
                        top.kept.triangle_lines[t]);
  std::vector<int> base;
  for (const auto& p : polygon) base.push_back(builder.add_vertex({p.x(), p.y(), top_z}));
  zip_ring(builder, top.kept.vertices, top.outline, base, polygon, top.face_name);
  add_prism_walls(builder, base, polygon, top_z, height, name + " ");
  Mesh result = std::move(builder).build(1.0, check);
  result.source = mesh.source;
  mesh = std::move(result);
}

}  // namespace spar::geometry
