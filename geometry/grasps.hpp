// Quantized grasps: SPAR's grasping configurations, labelled by the faces the fingers touch and
// the faces the gripper obscures, each with its grasp transform T_G (gripper frame in the object
// frame).
//
// Gripper frame (SPAR's pickup inequalities): origin midway between the two contact points, the
// fingers close along y (finger pads at y = ±W/2; the +y finger touches the pair's face_a), the
// gripper approaches along +z (z points from the palm into the object), x = y × z. So the contact
// points are T_G·(0, ±W_g/2, 0).
//
// Quantization (GraspQuantization, all configurable):
//  - face pairs: every FacePair of the object whose width lies in [min_opening, max_opening);
//  - approach: z turns about the closing axis y in steps of `approach_step` (radians; default
//    π/2, so 4 approaches) from a reference: the object's -z projected onto the plane normal to y
//    (or -x, then -y, when -z is nearly along y);
//  - contact position: `positions_per_axis` = 1 (default) puts the grasp centre at the area
//    centroid of the pair's overlap, or the overlap point nearest it when the centroid falls in a
//    hole; n > 1 aims at the centres of an n × n split of the overlap's bounding box (in its own
//    2D frame) and keeps the distinct overlap points nearest those centres.
// A contact position counts only where both contact points face the outside (the ray along each
// face's outward normal leaves the object: no grasps from inside a hole). A grasp is dropped when
// the gripper closed on the object (two finger boxes, the palm box) would overlap the object.
// Labels: "G1", "G2", ... in the order pair, position, approach (numbered after dropping).
//
// Obscured faces: the two contact faces plus every face that faces the gripper (outward normal ·
// z ≤ -obscure_facing_cosine) and whose projection along z meets the gripper's footprint (|x| ≤
// palm_width/2, |y| ≤ max_opening/2 + finger_thickness). Occlusion by nearer faces is ignored,
// so this over-reports, which keeps "grasp leaves the mating faces free" safe.
//
// Usability in a stable pose (SPAR's reachable(Grasp, Position) for a position class): no contact
// face on the table, the approach within `max_approach_tilt` of straight down (default 90°: never
// from below), and no corner of the gripper's fingers (closed to W_g and open to max_opening) or
// palm below the table. The sweep of the approach motion is not checked against the object.
//
// Example:
//   ObjectModel block = make_block();
//   std::vector<Grasp> grasps = compute_grasps(block, GripperSpec{}, GraspQuantization{});
//   std::vector<StablePose> poses = stable_poses(block);
//   grasp_usability(grasps[0], poses[0], GripperSpec{}) == GraspUsability::usable;
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/geometry/object.hpp"
#include "spar/geometry/stable_poses.hpp"

namespace spar::geometry {

// A parallel-jaw gripper, lengths in metres (the defaults are the seed's gripper in round inches:
// it opens to W_m = 4 in).
struct GripperSpec {
  double max_opening{4 * units::kInch};
  double min_opening{0.05 * units::kInch};
  double finger_length{2 * units::kInch};          // along z, palm to fingertip
  double finger_width{0.75 * units::kInch};        // along x
  double finger_thickness{0.25 * units::kInch};    // along y, outside the pad
  double tip_beyond_contact{0.25 * units::kInch};  // fingertips reach this far past the contact
  double palm_width{1.5 * units::kInch};           // along x
  double palm_height{1 * units::kInch};            // along z, behind the fingers
  double max_approach_tilt{90 * units::kDegree};   // between z and world -z

  bool operator==(const GripperSpec&) const = default;
};

struct GraspQuantization {
  double approach_step{90 * units::kDegree};  // radians, in (0, 2π]
  int positions_per_axis{1};
  double obscure_facing_cosine{0.5};  // faces within 60° of facing the gripper count

  bool operator==(const GraspQuantization&) const = default;
};

struct Grasp {
  int id{0};                            // 1-based
  std::string label;                    // "G" + id
  int face_plus_y{0};                   // contact face at y = +W/2 (FacePair::face_a)
  int face_minus_y{0};                  // contact face at y = -W/2
  double width{0};                      // W_g
  Eigen::Isometry3d gripper_in_object;  // T_G
  double approach{0};                   // turn of z about y from the reference, radians
  int position{0};                      // index of the contact position within the pair
  std::vector<int> obscured_faces;      // ascending, includes both contact faces
};

// Throws GeometryError if the quantization is invalid (step not in (0, 2π], positions < 1).
[[nodiscard]] std::vector<Grasp> compute_grasps(const ObjectModel& object,
                                                const GripperSpec& gripper,
                                                const GraspQuantization& quantization);
// compute_grasps, remembered process-wide: a later call with the same mesh (vertices and
// triangles compared exactly, not by digest), gripper and quantization (compared exactly) gets
// the list computed the first time, shared. The grasps depend on nothing else (faces, face pairs
// and tolerance are derived from the mesh). For whoever plans the same parts again: a batch of
// scenarios, a Python loop, the random-scene properties. Thread-safe; holds the
// kRememberedGraspLists most recently used lists (a mesh copy each); errors are not remembered.
inline constexpr std::size_t kRememberedGraspLists = 64;
[[nodiscard]] std::shared_ptr<const std::vector<Grasp>> remembered_grasps(
    const ObjectModel& object, const GripperSpec& gripper, const GraspQuantization& quantization);

enum class GraspUsability {
  usable,
  contact_face_on_table,
  approach_outside_cone,
  gripper_below_table
};
[[nodiscard]] std::string_view to_string(GraspUsability usability);

[[nodiscard]] GraspUsability grasp_usability(const Grasp& grasp, const StablePose& pose,
                                             const GripperSpec& gripper);
[[nodiscard]] inline bool grasp_usable(const Grasp& grasp, const StablePose& pose,
                                       const GripperSpec& gripper) {
  return grasp_usability(grasp, pose, gripper) == GraspUsability::usable;
}
// True when the grasp obscures none of `faces` (SPAR: grasps that leave the mating features free).
[[nodiscard]] bool grasp_leaves_free(const Grasp& grasp, std::span<const int> faces);

}  // namespace spar::geometry
