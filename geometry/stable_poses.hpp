// Stable poses: the orientations in which an object rests on the table by itself (SPAR's position
// classes; a cube has six). A hull facet is a stable pose when the centre of mass projects
// strictly inside it (further than ObjectModel::tolerance() from its boundary).
//
// Each pose carries the rigid transform that rests the object on the table: its facet normal
// turned to world -z, the facet in the plane z = 0, the centre of mass above the world origin.
// The rotation is the smallest one taking the normal to -z; any further turn about world z is the
// same position class. `margin` is the distance of the projected centre of mass to the facet's
// boundary and `tipping_angle` = atan(margin / com_height), the tilt about the nearest edge that
// topples the object. Poses are ordered by their smallest table face id; poses resting on no face,
// only on edges and corners, come last, ordered by their facet normal (x, then y, then z,
// ascending), so the labels "P1", "P2", ... depend on the shape alone (scenario files use them).
//
// Several objects joined rigidly (a subassembly) rest as one body: resting_margin() takes the
// parts where they are in the world and says how firmly the whole stands on the table there. Its
// footing is the convex hull, seen from above, of the mesh vertices within `tolerance` of z = 0;
// its centre of mass is the parts' centres weighted by their volumes (one density for all); the
// margin is the centre's distance to the footing's boundary, positive inside. It stands when the
// margin exceeds `tolerance` (the same strictness as a stable pose).
//
// Example:
//   ObjectModel cube("cube", make_box({1, 1, 1}));
//   std::vector<StablePose> poses = stable_poses(cube);       // 6 poses
//   poses[0].table_faces;                                      // {1}
//   pose_leaves_free(poses[0], std::vector<int>{2, 3});        // true: faces 2, 3 stay free
//   classify_orientation(poses, Eigen::Matrix3d::Identity());  // the pose resting on "-z"
//   const PosedPart on_table[] = {{&cube, poses[0].object_to_world}};
//   resting_margin(on_table, 1e-7);                            // 0.5: centre 0.5 inside
//   const PosedPart joined[] = {{&cube, Eigen::Isometry3d::Identity()}};
//   joint_stable_poses(joined, 1e-7).size();                   // 6, as stable_poses(cube)
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spar/geometry/object.hpp"

namespace spar::geometry {

struct StablePose {
  int id{0};                          // 1-based
  std::string label;                  // "P" + id
  int hull_facet{0};                  // index into ObjectModel::hull_facets()
  Eigen::Vector3d facet_normal;       // object frame, outward
  Eigen::Isometry3d object_to_world;  // world = object_to_world * object point
  double margin{0};
  double tipping_angle{0};  // radians
  double com_height{0};
  std::vector<int> table_faces;  // faces touching the table (ids, ascending)
};

[[nodiscard]] std::vector<StablePose> stable_poses(const ObjectModel& object);

// True when none of `faces` touches the table in `pose` (SPAR: mating features not obscured).
[[nodiscard]] bool pose_leaves_free(const StablePose& pose, std::span<const int> faces);

// The stable pose whose resting orientation matches `rotation` (object to world) within
// `angle_tolerance` radians of its facet normal pointing down, if any (in_position_class for a
// sensed position).
[[nodiscard]] std::optional<int> classify_orientation(const std::vector<StablePose>& poses,
                                                      const Eigen::Matrix3d& rotation,
                                                      double angle_tolerance = 0.05);

// One part of a rigid body: its model at its world pose (the model must outlive the query).
struct PosedPart {
  const ObjectModel* model{nullptr};
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};
};

// How firmly `parts`, joined, stand on the table as posed (see the header comment); nullopt when
// some vertex lies more than `tolerance` below z = 0 or the footing has no area (the body touches
// the table along an edge, at a point or not at all).
[[nodiscard]] std::optional<double> resting_margin(std::span<const PosedPart> parts,
                                                   double tolerance);

// One way a joined body rests (see the header comment).
struct JointStablePose {
  Eigen::Vector3d down;              // the direction resting on the table, in the parts' frame
  Eigen::Isometry3d frame_to_world;  // world = frame_to_world * parts' frame
  double margin{0};                  // resting_margin there
};

// The resting orientations of `parts` joined as posed in a common frame (the header comment),
// ordered by `down` (x, then y, then z, ascending; hull facets whose normals differ by less than
// 1e-9 are one direction).
[[nodiscard]] std::vector<JointStablePose> joint_stable_poses(std::span<const PosedPart> parts,
                                                              double tolerance);

}  // namespace spar::geometry
