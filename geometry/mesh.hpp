// Closed triangle meshes: the raw shape of an object before spar finds its faces, stable poses and
// grasps (see object.hpp).
//
// A Mesh is a polygon soup made watertight: every triangle is counter-clockwise seen from outside,
// and every edge is shared by exactly two triangles that run it in opposite directions.
// `validate_closed_mesh` checks this and throws GeometryError naming the file and line of the
// offending polygon. Each triangle remembers the name of the polygon it came from (OFF comments,
// OBJ groups, or the primitive builders' names); object.hpp merges coplanar triangles into faces
// and names each face after its first named triangle.
//
// Building composites without booleans: `RectilinearSolid` is a union of cells of a non-uniform
// axis-aligned grid (a block with a slot, an L, a box with a square cross hole); `attach_prism`
// stands a convex prism on a horizontal top face (a peg's shaft on its base).
//
// Example:
//   RectilinearSolid block({0, 1, 2, 3}, {0, 2}, {0, 1, 2});   // 3 x 1 x 2 cells, all filled
//   block.set_filled(1, 0, 1, false);                           // cut a slot in the top middle
//   Mesh mesh = block.to_mesh();                                // validated, faces "+z (z=2)" ...
//   Mesh cube = make_box({1, 1, 1});
//   Mesh shaft = make_prism(regular_polygon(0.75, 8), 3.0);     // a cylinder as an octagonal prism
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "spar/geometry/error.hpp"

namespace spar::geometry {

struct Mesh {
  std::string source{"<built in code>"};      // file name or builder, for error messages
  std::vector<Eigen::Vector3d> vertices;      // may hold unreferenced vertices; they are ignored
  std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside
  std::vector<std::string> triangle_names;    // same size as triangles; "" when unnamed
  std::vector<int> triangle_lines;            // same size; source line of the polygon, 0 if none
  // content_digest() when validate_closed_mesh last accepted the mesh (0: never). A mesh changed
  // since then has another digest and is checked again; an unchanged one is not checked twice
  // (a builder's or file's mesh handed to ObjectModel).
  std::uint64_t validated_digest{0};

  // "file:line" (or just the source) for triangle `t`, used to prefix error messages.
  [[nodiscard]] std::string where(int t) const;
};

// Whether a building step validates what it built (validate_closed_mesh), or leaves that to the
// caller, who validates the finished mesh once (ObjectModel's constructor always does): a
// composite built in several steps (the built-in objects) is then checked once, not per step.
enum class MeshCheck { kValidate, kDeferred };

// Accumulates planar convex polygons and fan-triangulates them.
class MeshBuilder {
 public:
  explicit MeshBuilder(std::string source);
  int add_vertex(const Eigen::Vector3d& point);
  // `loop`: vertex indices of a planar convex polygon, counter-clockwise seen from outside.
  // Throws GeometryError (with `line`) when it has fewer than 3 vertices, an index is out of range,
  // or it is not convex (fan triangles would flip).
  void add_polygon(std::span<const int> loop, const std::string& name, int line = 0);
  // Multiplies every vertex by `scale` (finite and > 0, else GeometryError: from the polygons'
  // length unit to metres), then validates (validate_closed_mesh) the scaled mesh, unless
  // `check` defers that.
  [[nodiscard]] Mesh build(double scale = 1.0, MeshCheck check = MeshCheck::kValidate) &&;
  [[nodiscard]] const std::vector<Eigen::Vector3d>& vertices() const { return mesh_.vertices; }

 private:
  Mesh mesh_;
};

// Checks closedness, consistent orientation, non-degenerate triangles, non-zero volume and that no
// two triangles cross (exact predicates; triangles meeting only at a shared edge or vertex do not
// count), so volume and centre of mass are those of a real solid; flips every triangle if the mesh
// is consistently oriented inward. Throws GeometryError otherwise. Cost: O(n log n) in the
// triangles, dominated by the self-crossing search; O(n) (a digest) for a mesh it accepted before
// and that has not changed since.
void validate_closed_mesh(Mesh& mesh);
// A 64-bit digest of the vertices and triangles (what validity depends on; not names or lines).
[[nodiscard]] std::uint64_t content_digest(const Mesh& mesh);

// Signed volume (positive for an outward mesh) and centre of the enclosed volume.
struct VolumeProperties {
  double volume{0};
  Eigen::Vector3d centroid{Eigen::Vector3d::Zero()};
};
[[nodiscard]] VolumeProperties volume_properties(const Mesh& mesh);

// The mesh with every vertex multiplied by `factor` (> 0; throws GeometryError otherwise): from a
// file's length unit to metres. Vertices that share a coordinate still do, so faces stay planar.
[[nodiscard]] Mesh scale_mesh(Mesh mesh, double factor);

// Box [0,sx] x [0,sy] x [0,sz]; faces named as RectilinearSolid's, "-x (x=0)" ... "+z (z=sz)".
[[nodiscard]] Mesh make_box(const Eigen::Vector3d& size);
// Counter-clockwise convex polygon in the xy-plane, radius to the vertices.
[[nodiscard]] std::vector<Eigen::Vector2d> regular_polygon(double radius, int sides);
// The convex polygon extruded from z = 0 to z = height; faces "bottom", "top", "side k".
[[nodiscard]] Mesh make_prism(const std::vector<Eigen::Vector2d>& polygon, double height);
// The convex hull of points (CGAL), as a closed mesh; throws if the points are flat.
[[nodiscard]] Mesh make_convex_hull(const std::vector<Eigen::Vector3d>& points);

// Union of filled cells of the grid xs x ys x zs (strictly increasing coordinates). Boundary quads
// are named by their outward direction and plane, e.g. "+z (z=3)" or "-x (x=0.8)". Cells that touch
// only along an edge make a non-manifold mesh, which to_mesh() rejects.
class RectilinearSolid {
 public:
  RectilinearSolid(std::vector<double> xs, std::vector<double> ys, std::vector<double> zs);
  void set_filled(int i, int j, int k, bool filled);
  // Empties every cell whose centre lies in the box [low, high].
  void carve(const Eigen::Vector3d& low, const Eigen::Vector3d& high);
  [[nodiscard]] bool filled(int i, int j, int k) const;
  [[nodiscard]] Mesh to_mesh(const std::string& source = "<rectilinear solid>",
                             MeshCheck check = MeshCheck::kValidate) const;

 private:
  std::array<std::vector<double>, 3> coordinates_;
  std::vector<char> filled_;  // cells, index (k * ny + j) * nx + i; all filled initially
};

// Stands the prism `polygon` x [top_z, top_z + height] on the mesh's triangles that lie at
// z = top_z facing +z: they are replaced by a ring joining their outline to the prism's base (the
// outline must be one convex loop around the polygon; the ring keeps the old triangles' name).
// New faces: `name` + " side k" and `name` + " end". The result is validated unless `check`
// defers that.
void attach_prism(Mesh& mesh, double top_z, const std::vector<Eigen::Vector2d>& polygon,
                  double height, const std::string& name, MeshCheck check = MeshCheck::kValidate);

}  // namespace spar::geometry
