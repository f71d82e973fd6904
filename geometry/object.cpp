#include "spar/geometry/object.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "spar/common/deadline.hpp"
#include "spar/geometry/internal/convex_hull.hpp"
#include "spar/geometry/internal/edge_index.hpp"
#include "spar/geometry/internal/polygon2d.hpp"
#include "spar/geometry/internal/triangle_tree.hpp"

namespace spar::geometry {
namespace {

constexpr double kParallelCosine = 1 - 1e-9;  // unit normals this close are the same direction

Eigen::Vector3d scaled_normal(const Mesh& mesh, const std::array<int, 3>& t) {
  const auto& v = mesh.vertices;
  return (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
}

// Faces bucketed by their unit normal on a grid of cells wider than the angle kParallelCosine
// allows (acos(1 - 1e-9) = 4.5e-5 rad), so every face whose normal is parallel to n lies in n's
// cell or a neighbouring one: near(n) returns those (and a few more), in ascending index order.
// It turns the all-pairs searches for parallel faces into linear ones.
class NormalIndex {
 public:
  explicit NormalIndex(const std::vector<Face>& faces) {
    for (int i = 0; i < static_cast<int>(faces.size()); ++i)
      cells_[key(cell_of(faces[i].normal))].push_back(i);
  }

  // A cell is wider than twice the difference parallel normals can have per axis, so per axis
  // only the neighbour on the side of the cell's nearer boundary can hold one: 8 cells, not 27.
  [[nodiscard]] std::vector<int> near(const Eigen::Vector3d& normal) const {
    const std::array<std::int64_t, 3> centre = cell_of(normal);
    std::array<std::int64_t, 3> side{};
    for (int axis = 0; axis < 3; ++axis)
      side[axis] = normal[axis] / kCell - static_cast<double>(centre[axis]) < 0.5 ? -1 : 1;
    std::vector<int> found;
    for (int corner = 0; corner < 8; ++corner) {
      const auto it = cells_.find(
          key({centre[0] + ((corner & 1) ? side[0] : 0), centre[1] + ((corner & 2) ? side[1] : 0),
               centre[2] + ((corner & 4) ? side[2] : 0)}));
      if (it != cells_.end()) found.insert(found.end(), it->second.begin(), it->second.end());
    }
    std::sort(found.begin(), found.end());
    return found;
  }

 private:
  // > 2 x 4.5e-5: parallel normals differ by less than half a cell per axis.
  static constexpr double kCell = 1e-4;
  static std::array<std::int64_t, 3> cell_of(const Eigen::Vector3d& normal) {
    return {static_cast<std::int64_t>(std::floor(normal.x() / kCell)),
            static_cast<std::int64_t>(std::floor(normal.y() / kCell)),
            static_cast<std::int64_t>(std::floor(normal.z() / kCell))};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& cell) {
    // Cells run from -10^4 to 10^4 per axis (unit normals): offset by 2^14, 16 bits each.
    std::uint64_t packed = 0;
    for (const std::int64_t c : cell) packed = packed << 16 | static_cast<std::uint64_t>(c + 16384);
    return packed;
  }
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

std::vector<Face> merge_faces(const Mesh& mesh, double tolerance) {
  const int count = static_cast<int>(mesh.triangles.size());
  std::vector<Eigen::Vector3d> unit(count);
  for (int t = 0; t < count; ++t) unit[t] = scaled_normal(mesh, mesh.triangles[t]).normalized();
  std::vector<int> parent(count);
  std::iota(parent.begin(), parent.end(), 0);
  const internal::EdgeIndex edges(mesh.triangles);  // a closed mesh: every edge has its opposite
  for (const auto& [edge, t] : edges.edges()) {
    const int other = edges.owner(internal::EdgeIndex::to(edge), internal::EdgeIndex::from(edge));
    const auto& near = mesh.vertices[mesh.triangles[t][0]];
    // The other triangle's normal at an angle, but also all its corners in this plane.
    bool coplanar = unit[t].dot(unit[other]) > kParallelCosine;
    for (const int v : mesh.triangles[other])
      coplanar = coplanar && std::abs(unit[t].dot(mesh.vertices[v] - near)) <= tolerance;
    if (coplanar) parent[find_root(parent, t)] = find_root(parent, other);
  }
  std::vector<int> face_of_root(count, -1);  // in order of first triangle, which gives the ids
  std::vector<Face> faces;
  for (int t = 0; t < count; ++t) {
    int& face_index = face_of_root[find_root(parent, t)];
    if (face_index < 0) {
      face_index = static_cast<int>(faces.size());
      faces.emplace_back();
      faces.back().id = static_cast<int>(faces.size());
      faces.back().normal = Eigen::Vector3d::Zero();
      faces.back().centroid = Eigen::Vector3d::Zero();
    }
    Face& face = faces[face_index];
    if (face.name.empty()) face.name = mesh.triangle_names[t];
    face.triangles.push_back(t);
    const Eigen::Vector3d n = scaled_normal(mesh, mesh.triangles[t]);
    const double area = n.norm() / 2;
    face.normal += n;
    face.area += area;
    const auto& tri = mesh.triangles[t];
    face.centroid +=
        area * (mesh.vertices[tri[0]] + mesh.vertices[tri[1]] + mesh.vertices[tri[2]]) / 3;
  }
  for (Face& face : faces) {
    face.normal.normalize();
    face.centroid /= face.area;
    face.offset = face.normal.dot(face.centroid);
  }
  return faces;
}

namespace {

// The vertices some triangle uses.
std::vector<Eigen::Vector3d> used_vertices(const Mesh& mesh) {
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& t : mesh.triangles)
    for (const int v : t) used[v] = 1;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v]) points.push_back(mesh.vertices[v]);
  return points;
}

// A hull facet's plane and the corners of its triangles.
struct PlaneGroup {
  HullFacet facet;
  std::vector<Eigen::Vector3d> corners;
};

// The hull's triangles grouped by plane: on a convex hull the triangles of one plane are one
// edge-connected facet, so each facet grows from its first triangle (the seed, in CGAL's order)
// across shared edges to every triangle with the seed's outward normal and all three corners on
// the seed's plane. Comparing with the seed, not the neighbour, keeps a finely tessellated
// curved surface from chaining into one facet. Linear in the hull size.
std::vector<PlaneGroup> hull_planes(const std::vector<std::array<int, 3>>& hull,
                                    const std::vector<Eigen::Vector3d>& points, double tolerance) {
  const int hull_size = static_cast<int>(hull.size());
  std::unordered_map<std::uint64_t, int> edge_triangle;  // directed edge (a, b) -> triangle
  edge_triangle.reserve(3 * hull.size());
  const auto edge_key = [](int a, int b) {
    return static_cast<std::uint64_t>(a) << 32 | static_cast<std::uint32_t>(b);
  };
  for (int t = 0; t < hull_size; ++t)
    for (int c = 0; c < 3; ++c) edge_triangle[edge_key(hull[t][c], hull[t][(c + 1) % 3])] = t;
  std::vector<PlaneGroup> groups;
  std::vector<char> assigned(hull.size(), 0);
  std::vector<int> frontier;
  for (int seed = 0; seed < hull_size; ++seed) {
    const auto& t = hull[seed];
    const Eigen::Vector3d n = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
    // A sliver CGAL kept for exactness starts no facet; a facet around it takes it in below.
    if (assigned[seed] || n.norm() == 0) continue;
    const Eigen::Vector3d unit = n.normalized();
    PlaneGroup group{{unit, unit.dot(points[t[0]]), {}, 0, 0, {}}, {}};
    const auto in_facet = [&](int u) {
      const auto& tri = hull[u];
      const Eigen::Vector3d m =
          (points[tri[1]] - points[tri[0]]).cross(points[tri[2]] - points[tri[0]]);
      return (m.norm() == 0 || unit.dot(m.normalized()) > kParallelCosine) &&
             std::all_of(tri.begin(), tri.end(), [&](int v) {
               return std::abs(unit.dot(points[v]) - group.facet.offset) <= 10 * tolerance;
             });
    };
    assigned[seed] = 1;
    frontier.assign(1, seed);
    while (!frontier.empty()) {
      const int current = frontier.back();
      frontier.pop_back();
      for (int c = 0; c < 3; ++c) {
        group.corners.push_back(points[hull[current][c]]);
        const auto across =
            edge_triangle.find(edge_key(hull[current][(c + 1) % 3], hull[current][c]));
        if (across == edge_triangle.end()) continue;
        const int neighbour = across->second;
        if (!assigned[neighbour] && in_facet(neighbour)) {
          assigned[neighbour] = 1;
          frontier.push_back(neighbour);
        }
      }
    }
    groups.push_back(std::move(group));
  }
  return groups;
}

}  // namespace

std::vector<HullFacet> compute_hull_facets(const Mesh& mesh, const std::vector<Face>& faces,
                                           const Eigen::Vector3d& com, double tolerance) {
  const std::vector<Eigen::Vector3d> points = used_vertices(mesh);
  const std::vector<PlaneGroup> groups =
      hull_planes(internal::convex_hull_triangles(points), points, tolerance);
  const NormalIndex face_normals(faces);
  std::vector<HullFacet> facets;
  for (const PlaneGroup& group : groups) {
    // The facet's outline (the 2-D hull of its corners), where the centre of mass lies from it,
    // and the faces that rest on the table with it.
    HullFacet facet = group.facet;
    const internal::PlaneBasis basis = internal::plane_basis(facet.normal);
    std::vector<Eigen::Vector2d> flat;
    for (const auto& p : group.corners) flat.push_back(internal::project(basis, p));
    const internal::Polygon2 polygon = internal::convex_hull_2d(flat);
    for (const auto& q : polygon)
      facet.polygon.push_back(basis.u * q.x() + basis.v * q.y() + facet.normal * facet.offset);
    facet.com_inset = internal::inset_distance(polygon, internal::project(basis, com));
    facet.com_height = facet.offset - facet.normal.dot(com);
    for (const int index : face_normals.near(facet.normal)) {
      const Face& face = faces[index];
      if (face.normal.dot(facet.normal) > kParallelCosine &&
          std::abs(face.offset - facet.offset) <= 10 * tolerance)
        facet.table_faces.push_back(face.id);
    }
    std::sort(facet.table_faces.begin(), facet.table_faces.end());
    facets.push_back(std::move(facet));
  }
  return facets;
}

// Common region of faces a and b seen along a's normal, as convex pieces in the mid-plane. Only
// triangle pairs whose projected boxes meet can overlap, so b's projected triangles go into a
// TriangleTree (flat, z = 0) and each of a's triangles is clipped against the ones it finds, in
// ascending order: the same pieces in the same order as clipping every pair, in O(n log n + k)
// instead of O(|a| |b|) (a finely tessellated box's opposite faces made this quadratic).
FacePair make_pair(const Mesh& mesh, const Face& a, const Face& b, double tolerance) {
  FacePair pair;
  pair.face_a = a.id;
  pair.face_b = b.id;
  pair.width = a.offset + b.offset;
  const double mid_offset = (a.offset - b.offset) / 2;
  const internal::PlaneBasis basis = internal::plane_basis(a.normal);
  const auto flat_triangle = [&](int t, bool reverse) {
    internal::Polygon2 polygon;
    for (const int v : mesh.triangles[t])
      polygon.push_back(internal::project(basis, mesh.vertices[v]));
    if (reverse) std::reverse(polygon.begin(), polygon.end());
    return polygon;
  };
  std::vector<internal::Polygon2> flat_b;
  std::vector<Eigen::Vector3d> corners;
  std::vector<std::array<int, 3>> flat_triangles;
  for (const int tb : b.triangles) {
    flat_b.push_back(flat_triangle(tb, true));
    const int first = static_cast<int>(corners.size());
    for (const auto& q : flat_b.back()) corners.emplace_back(q.x(), q.y(), 0);
    flat_triangles.push_back({first, first + 1, first + 2});
  }
  const internal::TriangleTree tree(corners, flat_triangles);
  std::vector<int> candidates;
  for (const int ta : a.triangles) {
    const internal::Polygon2 clip = flat_triangle(ta, false);
    Eigen::Vector3d low(clip[0].x(), clip[0].y(), -1), high(clip[0].x(), clip[0].y(), 1);
    for (const auto& q : clip) {
      low.head<2>() = low.head<2>().cwiseMin(q);
      high.head<2>() = high.head<2>().cwiseMax(q);
    }
    candidates.clear();
    tree.for_each_in_box(low, high, [&](int k) {
      candidates.push_back(k);
      return false;
    });
    std::sort(candidates.begin(), candidates.end());
    for (const int k : candidates) {
      const internal::Polygon2 piece = internal::clip_convex(flat_b[k], clip);
      const double area = piece.size() >= 3 ? internal::signed_area(piece) : 0;
      if (area <= tolerance * tolerance) continue;
      pair.overlap_area += area;
      std::vector<Eigen::Vector3d> lifted;
      for (const auto& q : piece)
        lifted.push_back(basis.u * q.x() + basis.v * q.y() + a.normal * mid_offset);
      pair.overlap.push_back(std::move(lifted));
    }
  }
  return pair;
}

}  // namespace

ObjectModel::ObjectModel(std::string name, Mesh mesh, std::optional<Eigen::Vector3d> center_of_mass)
    : name_(std::move(name)), mesh_(std::move(mesh)) {
  validate_closed_mesh(mesh_);
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const auto& t : mesh_.triangles)
    for (const int v : t) {
      low = low.cwiseMin(mesh_.vertices[v]);
      high = high.cwiseMax(mesh_.vertices[v]);
    }
  tolerance_ = 1e-9 * (high - low).norm();
  const VolumeProperties properties = volume_properties(mesh_);
  volume_ = properties.volume;
  center_of_mass_ = center_of_mass.value_or(properties.centroid);
  faces_ = merge_faces(mesh_, tolerance_);
  hull_facets_ = compute_hull_facets(mesh_, faces_, center_of_mass_, tolerance_);
  if (center_of_mass)
    for (const HullFacet& facet : hull_facets_)
      if (facet.com_height <= tolerance_)
        throw GeometryError(mesh_.source +
                            ": the given centre of mass lies outside the object's "
                            "convex hull");
  const NormalIndex normals(faces_);
  for (const Face& a : faces_)
    for (const int index : normals.near(-a.normal)) {  // ascending ids: pairs sorted by (a, b)
      check_deadline();  // a batch's --time-limit (common/deadline.hpp); cheap without one
      const Face& b = faces_[index];
      if (a.id < b.id && a.normal.dot(b.normal) < -kParallelCosine &&
          a.offset + b.offset > tolerance_) {
        FacePair pair = make_pair(mesh_, a, b, tolerance_);
        if (pair.overlap_area > 0) face_pairs_.push_back(std::move(pair));
      }
    }
}

const Face& ObjectModel::face(int id) const {
  if (id < 1 || id > static_cast<int>(faces_.size()))
    throw GeometryError(name_ + ": no face " + std::to_string(id) + " (faces are 1.." +
                        std::to_string(faces_.size()) + ")");
  return faces_[id - 1];
}

}  // namespace spar::geometry
