#include "spar/geometry/grasps.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "spar/common/deadline.hpp"
#include "spar/geometry/internal/exposure.hpp"
#include "spar/geometry/internal/polygon2d.hpp"
#include "spar/geometry/internal/triangle_tree.hpp"

namespace spar::geometry {
namespace {

using internal::Exposure;
using internal::Polygon2;
using internal::TriangleTree;

// The axis-aligned box (object frame) around the gripper-frame box [low, high].
std::pair<Eigen::Vector3d, Eigen::Vector3d> object_frame_bounds(
    const Eigen::Isometry3d& gripper_to_object, const Eigen::Vector3d& low,
    const Eigen::Vector3d& high) {
  Eigen::Vector3d object_low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d object_high = -object_low;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1) ? high.x() : low.x(), (corner & 2) ? high.y() : low.y(),
                            (corner & 4) ? high.z() : low.z());
    const Eigen::Vector3d q = gripper_to_object * p;
    object_low = object_low.cwiseMin(q);
    object_high = object_high.cwiseMax(q);
  }
  return {object_low, object_high};
}

struct Box {
  Eigen::Vector3d low, high;
};

// The gripper's solid parts in its own frame with the fingers closed to `width`, shrunk by
// `shrink` so the finger pads resting on the contact faces do not count as collisions.
std::vector<Box> gripper_boxes(const GripperSpec& gripper, double width, double shrink) {
  const double tip = gripper.tip_beyond_contact, palm = tip - gripper.finger_length;
  const double fx = gripper.finger_width / 2, px = gripper.palm_width / 2;
  const double inner = width / 2, outer = width / 2 + gripper.finger_thickness;
  std::vector<Box> boxes{{{-fx, inner, palm}, {fx, outer, tip}},
                         {{-fx, -outer, palm}, {fx, -inner, tip}},
                         {{-px, -outer, palm - gripper.palm_height}, {px, outer, palm}}};
  for (Box& box : boxes) {
    box.low.array() += shrink;
    box.high.array() -= shrink;
  }
  return boxes;
}

// Does the closed triangle (a, b, c) meet the open box? The separating-axis test (Akenine-Möller):
// two convex sets are disjoint iff they are separated along the box's axes, the triangle's normal
// or a cross product of a box axis and a triangle edge. Touching counts as separated (the box is
// open); a zero cross product (an edge along a box axis) is no axis.
bool triangle_meets_open_box(const std::array<Eigen::Vector3d, 3>& corners, const Box& box) {
  const Eigen::Vector3d centre = (box.low + box.high) / 2, half = (box.high - box.low) / 2;
  const std::array<Eigen::Vector3d, 3> v{corners[0] - centre, corners[1] - centre,
                                         corners[2] - centre};
  const auto separated = [&](const Eigen::Vector3d& axis) {
    const double p0 = axis.dot(v[0]), p1 = axis.dot(v[1]), p2 = axis.dot(v[2]);
    const double radius = half.dot(axis.cwiseAbs());
    return std::min({p0, p1, p2}) >= radius || std::max({p0, p1, p2}) <= -radius;
  };
  for (int axis = 0; axis < 3; ++axis)
    if (separated(Eigen::Vector3d::Unit(axis))) return false;
  const std::array<Eigen::Vector3d, 3> edges{v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  const double scale = edges[0].squaredNorm() + edges[1].squaredNorm() + edges[2].squaredNorm();
  for (const Eigen::Vector3d& edge : edges)
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d cross = Eigen::Vector3d::Unit(axis).cross(edge);
      if (cross.squaredNorm() > 1e-24 * scale && separated(cross)) return false;
    }
  return !separated(edges[0].cross(edges[1]));  // the triangle's plane (non-degenerate)
}

// Does the gripper, closed on the object at T_G, overlap the object: does one of its boxes (open:
// the finger pads rest on the contact faces) meet a triangle? Not detected: a box wholly inside
// the solid; the fingers start at exposed contacts and join the palm, so a gripper that reaches
// into the solid also has a box crossing the surface.
// Only the triangles whose bounding boxes meet a gripper box (as an oriented box in the object
// frame) are tested. The palm goes first: on a curved object it is the box that hits, and a hit
// ends the check.
bool gripper_hits_object(const ObjectModel& object, const TriangleTree& tree,
                         const Eigen::Isometry3d& object_to_gripper, const GripperSpec& gripper,
                         double width) {
  const auto& mesh = object.mesh();
  const Eigen::Isometry3d gripper_to_object = object_to_gripper.inverse(Eigen::Isometry);
  const double shrink = 1e-6 * object.tolerance() / 1e-9;  // 1e-6 of the bounding-box diagonal
  std::vector<Box> boxes = gripper_boxes(gripper, width, shrink);
  std::rotate(boxes.begin(), boxes.end() - 1, boxes.end());  // the palm (last) first
  for (const Box& box : boxes) {
    if ((box.low.array() >= box.high.array()).any()) continue;  // shrunk to nothing
    const bool hit =
        tree.for_each_in_oriented_box(gripper_to_object, box.low, box.high, [&](int t) {
          const auto& tri = mesh.triangles[t];
          return triangle_meets_open_box(
              {object_to_gripper * mesh.vertices[tri[0]], object_to_gripper * mesh.vertices[tri[1]],
               object_to_gripper * mesh.vertices[tri[2]]},
              box);
        });
    if (hit) return true;
  }
  return false;
}

// The overlap of a face pair in its mid-plane (2-D, plane_basis of face a's normal): where a
// contact point may go, and which points have both contacts reachable from outside.
class ContactRegion {
 public:
  ContactRegion(const ObjectModel& object, const TriangleTree& tree, const FacePair& pair)
      : normal_(object.face(pair.face_a).normal),
        basis_(internal::plane_basis(normal_)),
        mid_offset_(normal_.dot(pair.overlap.front().front())),
        face_offset_(object.face(pair.face_a).offset),
        width_(pair.width),
        tolerance_(object.tolerance()) {
    for (const auto& piece3 : pair.overlap) {
      Polygon2 piece;
      for (const auto& p : piece3) {
        piece.push_back(internal::project(basis_, p));
        low_ = low_.cwiseMin(piece.back());
        high_ = high_.cwiseMax(piece.back());
      }
      centroid_ += internal::signed_area(piece) * internal::area_centroid(piece);
      pieces_.emplace_back(piece, -tolerance_);
    }
    centroid_ /= pair.overlap_area;
    exposed_a_.emplace(object, tree, region(face_offset_), normal_);
    exposed_b_.emplace(object, tree, region(face_offset_ - width_), -normal_);
  }

  // The header's targets: the overlap's centroid, or a per_axis x per_axis grid over its box.
  [[nodiscard]] std::vector<Eigen::Vector2d> targets(int per_axis) const {
    if (per_axis == 1) return {centroid_};
    std::vector<Eigen::Vector2d> out;
    for (int i = 0; i < per_axis; ++i)
      for (int j = 0; j < per_axis; ++j) out.push_back(grid_point(i, j, per_axis));
    return out;
  }

  // In the closed overlap (a point on an edge shared by two pieces is inside), and both contact
  // points reachable from outside. The side that failed last is asked first: a face the object
  // hides fails at every point, at its first (remembered) blocker, while the other face's rays
  // pass every blocker of theirs.
  bool inside(const Eigen::Vector2d& q) {
    if (std::none_of(pieces_.begin(), pieces_.end(),
                     [&](const internal::InsetTest& in_piece) { return in_piece(q); }))
      return false;
    const Eigen::Vector3d mid = mid_plane_point(q);
    const Eigen::Vector3d on_a = mid + (face_offset_ - mid_offset_) * normal_;
    const Eigen::Vector3d on_b = mid - (width_ - (face_offset_ - mid_offset_)) * normal_;
    if (!(b_first_ ? (*exposed_b_)(on_b) : (*exposed_a_)(on_a))) return false;
    if (b_first_ ? (*exposed_a_)(on_a) : (*exposed_b_)(on_b)) return true;
    b_first_ = !b_first_;
    return false;
  }

  // The grid point inside nearest `target` (the first in grid order among equally near ones).
  // A 41 x 41 grid over the bounding box. Each inside() casts rays against the mesh, so grid
  // points are tested nearest first and only until one is inside, each at most once for all
  // targets (testing the whole grid made `spar object` quadratic in the mesh size, and was a
  // tenth of a small scenario's instructions). Points Exposure::surely_blocked marks on either
  // side are known outside without a ray: a face the object hides settles its grid at once.
  std::optional<Eigen::Vector2d> nearest_inside(const Eigen::Vector2d& target) {
    constexpr int kGrid = 41;
    if (grid_.empty()) {
      for (int i = 0; i < kGrid; ++i)
        for (int j = 0; j < kGrid; ++j) grid_.push_back(grid_point(i, j, kGrid));
      const Eigen::Vector3d corner = basis_.u * low_.x() + basis_.v * low_.y();
      const Eigen::Vector3d u_step = basis_.u * ((high_.x() - low_.x()) / kGrid);
      const Eigen::Vector3d v_step = basis_.v * ((high_.y() - low_.y()) / kGrid);
      const std::vector<char> blocked_a =
          exposed_a_->surely_blocked(corner + face_offset_ * normal_, u_step, v_step, kGrid);
      const std::vector<char> blocked_b = exposed_b_->surely_blocked(
          corner + (face_offset_ - width_) * normal_, u_step, v_step, kGrid);
      grid_inside_.assign(grid_.size(), -1);
      for (std::size_t i = 0; i < grid_.size(); ++i)
        if (blocked_a[i] || blocked_b[i]) grid_inside_[i] = 0;
    }
    if (std::all_of(grid_inside_.begin(), grid_inside_.end(),
                    [](signed char known) { return known == 0; }))
      return std::nullopt;  // no point inside, nor any left to test
    std::vector<std::pair<double, std::size_t>> order;
    for (std::size_t i = 0; i < grid_.size(); ++i)
      order.emplace_back((grid_[i] - target).squaredNorm(), i);
    std::sort(order.begin(), order.end());
    for (const auto& [distance, i] : order) {
      if (grid_inside_[i] < 0) grid_inside_[i] = inside(grid_[i]) ? 1 : 0;
      if (grid_inside_[i] == 1) return grid_[i];
    }
    return std::nullopt;
  }

  [[nodiscard]] Eigen::Vector3d mid_plane_point(const Eigen::Vector2d& q) const {
    return basis_.u * q.x() + basis_.v * q.y() + normal_ * mid_offset_;
  }
  [[nodiscard]] double tolerance() const { return tolerance_; }

 private:
  // Cell (i, j)'s centre of an n x n grid over the bounding box.
  [[nodiscard]] Eigen::Vector2d grid_point(int i, int j, int n) const {
    return {low_.x() + (high_.x() - low_.x()) * (i + 0.5) / n,
            low_.y() + (high_.y() - low_.y()) * (j + 0.5) / n};
  }
  // The contact points of mid-plane points in [low, high] at `along_normal` (face a or b).
  [[nodiscard]] std::array<Eigen::Vector3d, 4> region(double along_normal) const {
    std::array<Eigen::Vector3d, 4> corners;
    for (int c = 0; c < 4; ++c)
      corners[c] = basis_.u * (c & 1 ? high_.x() : low_.x()) +
                   basis_.v * (c & 2 ? high_.y() : low_.y()) + normal_ * along_normal;
    return corners;
  }

  Eigen::Vector3d normal_;
  internal::PlaneBasis basis_;
  double mid_offset_, face_offset_, width_, tolerance_;
  std::vector<internal::InsetTest> pieces_;  // within the tolerance of each piece
  Eigen::Vector2d low_{Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity())};
  Eigen::Vector2d high_{-low_};
  Eigen::Vector2d centroid_{Eigen::Vector2d::Zero()};
  std::optional<Exposure> exposed_a_, exposed_b_;
  bool b_first_{false};
  std::vector<Eigen::Vector2d> grid_;
  std::vector<signed char> grid_inside_;  // -1 untested, else inside(grid_[i])
};

// Contact positions of a pair (mid-plane points, object frame), per the header's quantization:
// each target, or the nearest grid point inside when it is not, once within the tolerance.
std::vector<Eigen::Vector3d> contact_positions(const ObjectModel& object, const TriangleTree& tree,
                                               const FacePair& pair, int per_axis) {
  ContactRegion region(object, tree, pair);
  std::vector<Eigen::Vector2d> chosen;
  for (const auto& target : region.targets(per_axis)) {
    Eigen::Vector2d best = target;
    if (!region.inside(target)) {
      const std::optional<Eigen::Vector2d> moved = region.nearest_inside(target);
      if (!moved) continue;
      best = *moved;
    }
    const bool repeated = std::any_of(chosen.begin(), chosen.end(), [&](const auto& c) {
      return (c - best).norm() <= region.tolerance();
    });
    if (!repeated) chosen.push_back(best);
  }
  std::vector<Eigen::Vector3d> positions;
  for (const auto& q : chosen) positions.push_back(region.mid_plane_point(q));
  return positions;
}

Eigen::Vector3d approach_reference(const Eigen::Vector3d& closing_axis) {
  for (const Eigen::Vector3d& candidate :
       {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, -1, 0)}) {
    const Eigen::Vector3d projected = candidate - candidate.dot(closing_axis) * closing_axis;
    if (projected.norm() >= 0.5) return projected.normalized();
  }
  return {};  // unreachable: -x, -y, -z cannot all be within 60° of one axis
}

// Does the face's projection along the gripper's z meet the footprint rectangle?
bool face_meets_footprint(const ObjectModel& object, const Face& face,
                          const Eigen::Isometry3d& object_to_gripper, double half_x,
                          double half_y) {
  const Polygon2 footprint{
      {-half_x, -half_y}, {half_x, -half_y}, {half_x, half_y}, {-half_x, half_y}};
  const double tolerance = object.tolerance();
  for (const int t : face.triangles) {
    Polygon2 flat;
    for (const int v : object.mesh().triangles[t])
      flat.push_back((object_to_gripper * object.mesh().vertices[v]).head<2>());
    if (internal::signed_area(flat) < 0) std::reverse(flat.begin(), flat.end());
    const Polygon2 common = internal::clip_convex(flat, footprint);
    if (common.size() >= 3 && internal::signed_area(common) > tolerance * tolerance) return true;
  }
  return false;
}

}  // namespace

std::vector<Grasp> compute_grasps(const ObjectModel& object, const GripperSpec& gripper,
                                  const GraspQuantization& quantization) {
  constexpr double kTurn = 2 * std::numbers::pi;
  if (!(quantization.approach_step > 0 && quantization.approach_step <= kTurn * (1 + 1e-12)))
    throw GeometryError("grasp quantization: the approach step must be in (0, 2 pi] radians, got " +
                        std::to_string(quantization.approach_step));
  if (quantization.positions_per_axis < 1)
    throw GeometryError("grasp quantization: positions per axis must be at least 1");
  std::vector<Grasp> grasps;
  const double half_x = gripper.palm_width / 2;
  const double half_y = gripper.max_opening / 2 + gripper.finger_thickness;
  const Mesh& mesh = object.mesh();
  const TriangleTree tree(mesh.vertices, mesh.triangles);
  std::vector<int> face_of_triangle(mesh.triangles.size(), 0);
  for (const Face& face : object.faces())
    for (const int t : face.triangles) face_of_triangle[t] = face.id;
  Eigen::Vector3d object_low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d object_high = -object_low;
  for (const auto& tri : mesh.triangles)
    for (const int v : tri) {
      object_low = object_low.cwiseMin(mesh.vertices[v]);
      object_high = object_high.cwiseMax(mesh.vertices[v]);
    }
  // Faces with a triangle in the footprint's prism over the object's extent along z: only they can
  // meet the footprint (ascending ids).
  const auto faces_under_footprint = [&](const Eigen::Isometry3d& object_to_gripper) {
    double z_low = std::numeric_limits<double>::infinity(), z_high = -z_low;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d p((corner & 1) ? object_high.x() : object_low.x(),
                              (corner & 2) ? object_high.y() : object_low.y(),
                              (corner & 4) ? object_high.z() : object_low.z());
      const double z = (object_to_gripper * p).z();
      z_low = std::min(z_low, z);
      z_high = std::max(z_high, z);
    }
    const auto [low, high] =
        object_frame_bounds(object_to_gripper.inverse(Eigen::Isometry), {-half_x, -half_y, z_low},
                            {half_x, half_y, z_high});
    std::vector<int> ids;
    tree.for_each_in_box(low, high, [&](int t) {
      ids.push_back(face_of_triangle[t]);
      return false;
    });
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
  };
  for (const FacePair& pair : object.face_pairs()) {
    check_deadline();  // a batch's --time-limit (common/deadline.hpp); cheap without one
    if (pair.width < gripper.min_opening || pair.width >= gripper.max_opening) continue;
    const Eigen::Vector3d y = object.face(pair.face_a).normal;
    const Eigen::Vector3d reference = approach_reference(y);
    const auto positions = contact_positions(object, tree, pair, quantization.positions_per_axis);
    for (std::size_t position = 0; position < positions.size(); ++position)
      for (int step = 0; step * quantization.approach_step < kTurn * (1 - 1e-11); ++step) {
        const double angle = step * quantization.approach_step;
        const Eigen::Vector3d z = Eigen::AngleAxisd(angle, y) * reference;
        Grasp grasp;
        grasp.face_plus_y = pair.face_a;
        grasp.face_minus_y = pair.face_b;
        grasp.width = pair.width;
        grasp.approach = angle;
        grasp.position = static_cast<int>(position);
        grasp.gripper_in_object = Eigen::Isometry3d::Identity();
        grasp.gripper_in_object.linear() << y.cross(z), y, z;
        grasp.gripper_in_object.translation() = positions[position];
        const Eigen::Isometry3d object_to_gripper =
            grasp.gripper_in_object.inverse(Eigen::Isometry);
        if (gripper_hits_object(object, tree, object_to_gripper, gripper, pair.width)) continue;
        std::vector<int> candidates = faces_under_footprint(object_to_gripper);
        candidates.push_back(pair.face_a);
        candidates.push_back(pair.face_b);
        std::sort(candidates.begin(), candidates.end());
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
        for (const int id : candidates) {
          const Face& face = object.face(id);
          const bool contact = face.id == pair.face_a || face.id == pair.face_b;
          if (contact || (face.normal.dot(z) <= -quantization.obscure_facing_cosine &&
                          face_meets_footprint(object, face, object_to_gripper, half_x, half_y)))
            grasp.obscured_faces.push_back(face.id);
        }
        grasp.id = static_cast<int>(grasps.size()) + 1;
        grasp.label = "G" + std::to_string(grasp.id);
        grasps.push_back(std::move(grasp));
      }
  }
  return grasps;
}

std::string_view to_string(GraspUsability usability) {
  switch (usability) {
    case GraspUsability::usable:
      return "usable";
    case GraspUsability::contact_face_on_table:
      return "a contact face is on the table";
    case GraspUsability::approach_outside_cone:
      return "the approach is too far from straight down";
    case GraspUsability::gripper_below_table:
      return "the gripper would go through the table";
  }
  return "?";
}

GraspUsability grasp_usability(const Grasp& grasp, const StablePose& pose,
                               const GripperSpec& gripper) {
  for (const int face : {grasp.face_plus_y, grasp.face_minus_y})
    if (!pose_leaves_free(pose, std::span<const int>(&face, 1)))
      return GraspUsability::contact_face_on_table;
  const Eigen::Isometry3d gripper_to_world = pose.object_to_world * grasp.gripper_in_object;
  const Eigen::Vector3d approach = gripper_to_world.linear().col(2);
  if (approach.dot(-Eigen::Vector3d::UnitZ()) < std::cos(gripper.max_approach_tilt) - 1e-12)
    return GraspUsability::approach_outside_cone;
  // The fingers (closed on the object and fully open) and the palm are boxes; a box is above the
  // table when its eight corners are.
  const double tip = gripper.tip_beyond_contact;
  const double palm = tip - gripper.finger_length;
  const double fx = gripper.finger_width / 2;
  const double px = gripper.palm_width / 2;
  const double py = gripper.max_opening / 2 + gripper.finger_thickness;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes;  // low, high corners
  for (const double opening : {grasp.width, gripper.max_opening}) {
    const double inner = opening / 2, outer = opening / 2 + gripper.finger_thickness;
    boxes.push_back({{-fx, inner, palm}, {fx, outer, tip}});
    boxes.push_back({{-fx, -outer, palm}, {fx, -inner, tip}});
  }
  boxes.push_back({{-px, -py, palm - gripper.palm_height}, {px, py, palm}});
  const double tolerance = 1e-9 * (gripper.finger_length + gripper.max_opening);
  for (const auto& [low, high] : boxes)
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d p((corner & 1) ? high.x() : low.x(), (corner & 2) ? high.y() : low.y(),
                              (corner & 4) ? high.z() : low.z());
      if ((gripper_to_world * p).z() < -tolerance) return GraspUsability::gripper_below_table;
    }
  return GraspUsability::usable;
}

bool grasp_leaves_free(const Grasp& grasp, std::span<const int> faces) {
  return std::none_of(faces.begin(), faces.end(), [&](int face) {
    return std::binary_search(grasp.obscured_faces.begin(), grasp.obscured_faces.end(), face);
  });
}

std::shared_ptr<const std::vector<Grasp>> remembered_grasps(const ObjectModel& object,
                                                            const GripperSpec& gripper,
                                                            const GraspQuantization& quantization) {
  struct Remembered {
    std::uint64_t digest;  // content_digest(mesh): a cheap first comparison
    std::vector<Eigen::Vector3d> vertices;
    std::vector<std::array<int, 3>> triangles;
    GripperSpec gripper;
    GraspQuantization quantization;
    std::shared_ptr<const std::vector<Grasp>> grasps;
    std::uint64_t last_used;
  };
  static std::mutex mutex;
  static std::vector<Remembered> remembered;  // at most kRememberedGraspLists
  static std::uint64_t clock = 0;
  const Mesh& mesh = object.mesh();
  const std::uint64_t digest = content_digest(mesh);
  const auto same = [&](const Remembered& entry) {
    return entry.digest == digest && entry.gripper == gripper &&
           entry.quantization == quantization && entry.triangles == mesh.triangles &&
           entry.vertices == mesh.vertices;
  };
  {
    const std::scoped_lock lock(mutex);
    const auto found = std::ranges::find_if(remembered, same);
    if (found != remembered.end()) {
      found->last_used = ++clock;
      return found->grasps;
    }
  }
  // Computed outside the lock: two threads asking for the same new list both compute it (the
  // second one's is dropped below), nobody waits for another's search.
  auto grasps =
      std::make_shared<const std::vector<Grasp>>(compute_grasps(object, gripper, quantization));
  const std::scoped_lock lock(mutex);
  if (const auto found = std::ranges::find_if(remembered, same); found != remembered.end())
    return found->grasps;
  if (remembered.size() == kRememberedGraspLists)
    remembered.erase(std::ranges::min_element(remembered, {}, &Remembered::last_used));
  remembered.push_back(
      {digest, mesh.vertices, mesh.triangles, gripper, quantization, grasps, ++clock});
  return grasps;
}

}  // namespace spar::geometry
