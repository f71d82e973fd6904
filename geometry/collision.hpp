// Collision and distance between rigid bodies made of closed triangle meshes and boxes, on FCL
// (the Flexible Collision Library MoveIt uses: bounding-volume hierarchies of oriented boxes and
// swept spheres over the triangles, exact triangle-triangle distance at the leaves). bench/
// geometry_bench.cpp measured it against CGAL's Rigid_triangle_mesh_collision_detection on the
// project's meshes (bench/RESULTS.md, "geometry: collision"): FCL answers the same collide queries
// faster and it is the one of the two that measures the distance between two meshes, which the
// margin, the clearance and the nearest-body queries need.
//
// A CollisionShape is one closed mesh (or box) with its hierarchy, built once and shared by every
// copy (immutable). A Body is a named set of parts, each a shape at a fixed pose in the body's
// frame: an object, the gripper (palm and two fingers), the gripper holding an object, or a
// subassembly (two bodies joined as one). A PlacedBody is a body at a pose in the world.
//
// Rules of the queries:
//   * distance is between the two surfaces, 0 when they touch or cross. A body wholly inside
//     another has no surface contact, so a query also tests one vertex of each part for lying
//     inside the other part (the winding number of the closed mesh, which needs no manifold
//     structure, unlike CGAL's Side_of_triangle_mesh): such a pair is `intersecting` with
//     distance 0.
//   * collide(a, b, margin) holds when the bodies interpenetrate or their surfaces come closer
//     than `margin`; touching (distance 0) always collides. So two objects resting side by side
//     need a gap of at least `margin`.
//   * The table is the half-space z <= 0: a body rests on it when its lowest point is at z = 0
//     and goes through it when its lowest point is below -kTableTolerance (resting is no
//     collision; the table is not a Body, ask lowest_z).
//   * sweep(moving, motion, obstacles, margin): the straight-line translation of `moving` by
//     `motion`, by conservative advancement: the surface distance changes by at most the length
//     moved, so after a sample at distance d the next sample is d - margin/2 further on, but never
//     more than `margin` later. Every sample must be at least `margin` from every obstacle, and
//     then no point of the path comes closer than margin/2 (between two samples a distance
//     falls by at most half the step from one of them): the sampling cannot miss any contact, let
//     alone one deeper than the margin. Being inside an obstacle cannot begin without the surfaces
//     meeting, so containment is tested at the start only. (Margin 0 checks the two ends only.)
// Broad phase: a pair whose world bounding boxes lie `margin` or more apart is never handed to
// FCL (its surfaces are at least that far apart).
//
// Cost: building a shape is O(t log t) for t triangles; a distance query between two parts costs
// a traversal of both hierarchies (microseconds for the project's meshes: bench/RESULTS.md), the
// inside test O(log t) per vertex tested; a sweep of length L costs at most L / margin + 1
// samples, far fewer when the obstacles are far. Hot paths never throw.
//
// Example:
//   const Body block("block", CollisionShape(builtin_mesh("block")));
//   const Body cube("cube", CollisionShape::box({0, 0, 0}, {0.0254, 0.0254, 0.0254}));
//   const PlacedBody a{&block, Pose::Identity()}, b{&cube, Pose(Eigen::Translation3d(0.2, 0, 0))};
//   const Proximity near = proximity(a, b);              // near.distance: metres apart
//   const bool hit = collide(a, b, 0.001) || lowest_z(a) < -kTableTolerance;
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "spar/geometry/grasps.hpp"
#include "spar/geometry/mesh.hpp"

namespace spar::geometry {

using Pose = Eigen::Isometry3d;

namespace internal {
struct ShapeData;
}

// How far below z = 0 a body may reach and still count as resting on the table (rounding of
// poses composed from stable poses).
inline constexpr double kTableTolerance = 1e-7;

// One closed triangle mesh or box with its bounding-volume hierarchy; immutable, cheap to copy.
class CollisionShape {
 public:
  // A closed mesh (validate_closed_mesh's rules; object models' meshes are). Throws
  // GeometryError when it has no triangle.
  explicit CollisionShape(const Mesh& mesh);
  // The axis-aligned box [low, high] in the shape's frame; throws GeometryError unless low < high
  // in every coordinate.
  [[nodiscard]] static CollisionShape box(const Eigen::Vector3d& low, const Eigen::Vector3d& high);
  // Some triangles of a closed mesh (indices into mesh.triangles): a surface only, never asked
  // whether something lies inside it (an object without its mating faces). Each triangle is
  // pulled in toward its centroid by `inset` (>= 0, metres), so that surfaces meeting only along
  // the triangles' edges or at their corners no longer touch. Throws GeometryError when
  // `triangles` is empty.
  [[nodiscard]] static CollisionShape surface(const Mesh& mesh, std::span<const int> triangles,
                                              double inset = 0);

  [[nodiscard]] const Eigen::AlignedBox3d& bounds() const;  // in the shape's frame
  [[nodiscard]] std::span<const Eigen::Vector3d> vertices() const;
  [[nodiscard]] std::size_t triangle_count() const;

 private:
  friend struct ShapeAccess;
  explicit CollisionShape(std::shared_ptr<const internal::ShapeData> data)
      : data_(std::move(data)) {}
  std::shared_ptr<const internal::ShapeData> data_;  // never null
};

struct BodyPart {
  CollisionShape shape;
  Pose pose{Pose::Identity()};  // the shape's frame in the body's frame
};

// A rigid body: its parts never move relative to each other.
class Body {
 public:
  Body(std::string name, std::vector<BodyPart> parts);
  Body(std::string name, CollisionShape shape)
      : Body(std::move(name), std::vector<BodyPart>{{std::move(shape)}}) {}

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const std::vector<BodyPart>& parts() const { return parts_; }
  // One body made of this one's parts and `other`'s, `other` at `other_in_this` (a subassembly,
  // the gripper with what it holds).
  [[nodiscard]] Body joined(const Body& other, const Pose& other_in_this, std::string name) const;
  // A box in the body's frame containing every part.
  [[nodiscard]] const Eigen::AlignedBox3d& bounds() const { return bounds_; }

 private:
  std::string name_;
  std::vector<BodyPart> parts_;
  Eigen::AlignedBox3d bounds_;  // of the parts' boxes, each turned into the body frame
};

// A body at a pose in the world; the body must outlive it.
struct PlacedBody {
  const Body* body{nullptr};
  Pose pose{Pose::Identity()};
};

// The world-frame box around a placed body (conservative: the parts' boxes turned, then boxed).
[[nodiscard]] Eigen::AlignedBox3d world_bounds(const PlacedBody& placed);
// The lowest z of any vertex of the placed body (the table test: rests at 0, below it < 0).
[[nodiscard]] double lowest_z(const PlacedBody& placed);

struct Proximity {
  double distance{0.0};      // between the surfaces (metres); 0 exactly when `intersecting`
  bool intersecting{false};  // the surfaces meet (touch or cross) or one body is inside the other
  Eigen::Vector3d point_a{Eigen::Vector3d::Zero()};  // nearest points, world frame (a contact
  Eigen::Vector3d point_b{Eigen::Vector3d::Zero()};  // point twice when intersecting)
};
[[nodiscard]] Proximity proximity(const PlacedBody& a, const PlacedBody& b);

// The bodies interpenetrate, touch, or their surfaces come closer than `margin` (>= 0).
[[nodiscard]] bool collide(const PlacedBody& a, const PlacedBody& b, double margin);

// The nearest of `others` to `body`: its index and distance (index -1, distance +inf for none).
struct Nearest {
  int index{-1};
  double distance{0.0};
};
[[nodiscard]] Nearest nearest(const PlacedBody& body, std::span<const PlacedBody> others);

// The translation of `moving` by `motion` (world frame) among fixed `obstacles`, sampled as the
// header says. `clear`: every sample is at least `margin` from every obstacle (so the whole path
// stays margin/2 away); otherwise `obstacle` is the first one found closer (or inside), at the
// fraction `at` of the motion. `min_distance` is the smallest sampled distance (+inf when no
// obstacle came within the margin of the path's bounding box).
struct Sweep {
  bool clear{true};
  int obstacle{-1};
  double at{0.0};
  double min_distance{0.0};
  int samples{0};  // distance evaluations (of the whole set) made
};
[[nodiscard]] Sweep sweep(const PlacedBody& moving, const Eigen::Vector3d& motion,
                          std::span<const PlacedBody> obstacles, double margin);

// The work of the collision layer, counted while a CollisionTally is alive (bench/planner_bench
// reports with it the share of phase 1 spent checking collisions, and how much of that is FCL's
// own traversal of the same part pairs). Queries from every thread count; a query made inside
// another one (a sweep's distances) counts only in the outer one. At most one tally is alive at
// a time (a second one throws GeometryError). Counting costs two clock reads per top-level query
// and per FCL call; without a tally, one atomic load per query.
struct CollisionCounts {
  long long queries{0};     // top-level calls of proximity, collide, nearest, sweep, lowest_z
  long long fcl_calls{0};   // FCL collide and distance calls on part pairs made by them
  double seconds{0.0};      // wall time inside the top-level queries
  double fcl_seconds{0.0};  // of which inside FCL's calls
};
class CollisionTally {
 public:
  CollisionTally();
  ~CollisionTally();
  CollisionTally(const CollisionTally&) = delete;
  CollisionTally& operator=(const CollisionTally&) = delete;
  [[nodiscard]] CollisionCounts counts() const;
};

// The parallel-jaw gripper as three boxes in its frame (grasps.hpp: origin midway between the
// finger pads, closing along y, approaching along +z): two fingers of finger_width (x) x
// finger_thickness (y) x finger_length (z), their inner faces at y = +-opening/2, reaching
// tip_beyond_contact past z = 0; the palm, palm_width x (max_opening + 2 finger_thickness) x
// palm_height, behind the fingers. `opening` in (0, max_opening]: the grasp width when holding,
// max_opening when approaching or leaving an object. `shrink` >= 0 moves every box face inward
// by that much (a gripper whose pads may rest on what it grasps without counting as contact).
[[nodiscard]] Body gripper_body(const GripperSpec& gripper, double opening, double shrink = 0);

}  // namespace spar::geometry
