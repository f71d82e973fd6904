// An object model: a closed mesh seen as SPAR's object modelling system sees it — named planar
// faces with stable ids, a centre of mass, the convex hull's facets (candidate stable poses) and
// the pairs of parallel opposite faces a two-finger gripper can squeeze.
//
// Faces: edge-connected triangles that lie in one plane are merged into one face. Ids run 1..N in
// the order of each face's first triangle in the mesh, so a file always gives the same ids. A face
// is named after its first named triangle (OFF comment, OBJ group, builder name); names need not
// be unique, ids are.
// Hull facets: CGAL's hull triangles merged by plane (coplanar triangles are one facet), each with
// the signed distance of the centre-of-mass projection to its boundary (positive = inside).
// Face pairs: faces a < b with opposite normals (n_b = -n_a), outside each other (width > 0) and
// overlapping when seen along the normal; width = distance between their planes.
//
// Example:
//   ObjectModel cube("cube", make_box({1, 1, 1}));
//   cube.faces().size();                 // 6
//   cube.face(1).normal;                 // outward unit normal, object frame
//   cube.face_pairs()[0].width;          // 1.0
//   cube.hull_facets()[0].com_inset;     // 0.5: the centre projects 0.5 inside each facet
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "spar/geometry/mesh.hpp"

namespace spar::geometry {

struct Face {
  int id{0};  // 1-based, stable for a given mesh
  std::string name;
  Eigen::Vector3d normal;  // outward unit normal (object frame)
  double offset{0};        // the face's plane is normal · x = offset
  double area{0};
  Eigen::Vector3d centroid;    // area centroid
  std::vector<int> triangles;  // indices into the mesh's triangles
};

struct HullFacet {
  Eigen::Vector3d normal;                // outward unit normal
  double offset{0};                      // plane normal · x = offset
  std::vector<Eigen::Vector3d> polygon;  // convex, counter-clockwise seen from outside
  double com_inset{0};   // distance of the centre-of-mass projection to the boundary, < 0 outside
  double com_height{0};  // distance of the centre of mass from the facet's plane
  std::vector<int> table_faces;  // object faces lying in this facet's plane (ids, ascending)
};

struct FacePair {
  int face_a{0};  // lower id; the gripper's +y finger touches it
  int face_b{0};
  double width{0};  // distance between the two planes
  double overlap_area{0};
  // The faces' common region seen along normal_a, as convex pieces in the mid-plane (object
  // frame), each counter-clockwise seen from face_a's side.
  std::vector<std::vector<Eigen::Vector3d>> overlap;
};

class ObjectModel {
 public:
  // Validates the mesh (throws GeometryError) and computes faces, hull facets and face pairs.
  // Without `center_of_mass` the density is uniform; a given one must lie inside the hull.
  ObjectModel(std::string name, Mesh mesh,
              std::optional<Eigen::Vector3d> center_of_mass = std::nullopt);

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const Mesh& mesh() const { return mesh_; }
  [[nodiscard]] const std::vector<Face>& faces() const { return faces_; }
  [[nodiscard]] const Face& face(int id) const;  // throws GeometryError for an unknown id
  [[nodiscard]] const Eigen::Vector3d& center_of_mass() const { return center_of_mass_; }
  [[nodiscard]] double volume() const { return volume_; }
  [[nodiscard]] const std::vector<HullFacet>& hull_facets() const { return hull_facets_; }
  [[nodiscard]] const std::vector<FacePair>& face_pairs() const { return face_pairs_; }
  // Length tolerance for "on a plane", "strictly inside": 1e-9 of the bounding-box diagonal.
  [[nodiscard]] double tolerance() const { return tolerance_; }

 private:
  std::string name_;
  Mesh mesh_;
  std::vector<Face> faces_;  // faces_[id - 1].id == id
  Eigen::Vector3d center_of_mass_{Eigen::Vector3d::Zero()};
  double volume_{0};
  double tolerance_{0};
  std::vector<HullFacet> hull_facets_;
  std::vector<FacePair> face_pairs_;
};

}  // namespace spar::geometry
