#include "spar/geometry/collision.hpp"

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "spar/geometry/error.hpp"

namespace spar::geometry {
namespace internal {

struct ShapeData {
  std::vector<Eigen::Vector3d> vertices;  // only those the triangles use
  std::vector<std::array<int, 3>> triangles;
  Eigen::AlignedBox3d bounds;
  bool is_box{false};  // then `bounds` is the shape, and the inside test is the box test
  bool closed{true};   // false for a surface patch: nothing lies inside it
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> bvh;
};

}  // namespace internal

// The one place that reads a shape's data.
struct ShapeAccess {
  static const internal::ShapeData& data(const CollisionShape& shape) { return *shape.data_; }
  static CollisionShape make(std::shared_ptr<const internal::ShapeData> data) {
    return CollisionShape(std::move(data));
  }
};

namespace {

// The live CollisionTally's counters (nanoseconds as integers, so that threads can add).
struct AtomicCounts {
  std::atomic<long long> queries{0}, fcl_calls{0}, nanoseconds{0}, fcl_nanoseconds{0};
};
std::atomic<AtomicCounts*> live_tally{nullptr};
thread_local int query_depth = 0;  // top-level queries of this thread in progress

long long now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Counts one top-level query (or one FCL call) for its lifetime into the live tally, if any.
class Counted {
 public:
  explicit Counted(bool fcl_call) : fcl_call_(fcl_call) {
    if (!fcl_call_ && query_depth++ > 0) return;  // nested in another query
    tally_ = live_tally.load(std::memory_order_acquire);
    if (tally_ != nullptr) start_ = now_ns();
  }
  ~Counted() {
    if (!fcl_call_) --query_depth;
    if (tally_ == nullptr) return;
    const long long elapsed = now_ns() - start_;
    (fcl_call_ ? tally_->fcl_calls : tally_->queries).fetch_add(1, std::memory_order_relaxed);
    (fcl_call_ ? tally_->fcl_nanoseconds : tally_->nanoseconds)
        .fetch_add(elapsed, std::memory_order_relaxed);
  }
  Counted(const Counted&) = delete;
  Counted& operator=(const Counted&) = delete;

 private:
  bool fcl_call_;
  AtomicCounts* tally_{nullptr};
  long long start_{0};
};

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// A sweep measures distances exactly only up to this many margins (further ones are bounded
// below, cheaply): each step then advances at most that far, and FCL prunes at that bound.
constexpr double kSweepReach = 3;

std::shared_ptr<internal::ShapeData> shape_data(const std::vector<Eigen::Vector3d>& vertices,
                                                const std::vector<std::array<int, 3>>& triangles,
                                                const std::string& source) {
  if (triangles.empty()) throw GeometryError(source + ": a collision shape needs triangles");
  auto data = std::make_shared<internal::ShapeData>();
  // Keep the used vertices only (a mesh may carry unreferenced ones), renumbered.
  std::vector<int> index(vertices.size(), -1);
  for (const auto& triangle : triangles) {
    std::array<int, 3> renumbered{};
    for (int corner = 0; corner < 3; ++corner) {
      int& slot = index.at(triangle[corner]);
      if (slot < 0) {
        slot = static_cast<int>(data->vertices.size());
        data->vertices.push_back(vertices[triangle[corner]]);
      }
      renumbered[corner] = slot;
    }
    data->triangles.push_back(renumbered);
  }
  for (const Eigen::Vector3d& v : data->vertices) data->bounds.extend(v);
  std::vector<fcl::Triangle> fcl_triangles;
  fcl_triangles.reserve(data->triangles.size());
  for (const auto& [a, b, c] : data->triangles) fcl_triangles.emplace_back(a, b, c);
  data->bvh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  data->bvh->beginModel(static_cast<int>(fcl_triangles.size()),
                        static_cast<int>(data->vertices.size()));
  data->bvh->addSubModel(data->vertices, fcl_triangles);
  data->bvh->endModel();
  return data;
}

// Generalized winding number of the closed mesh about `point` (1 inside, 0 outside), from the
// solid angles of its triangles (Van Oosterom & Strackee 1983). Only asked for points that are
// not on the surface (the caller has measured a positive distance), where it is far from 1/2.
double winding_number(const internal::ShapeData& shape, const Eigen::Vector3d& point) {
  double total = 0;
  for (const auto& [i, j, k] : shape.triangles) {
    const Eigen::Vector3d a = shape.vertices[i] - point, b = shape.vertices[j] - point,
                          c = shape.vertices[k] - point;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    total += 2 * std::atan2(numerator, denominator);
  }
  return total / (4 * std::numbers::pi);
}

bool shape_contains(const internal::ShapeData& shape, const Eigen::Vector3d& local_point) {
  if (!shape.closed || !shape.bounds.contains(local_point)) return false;
  if (shape.is_box) return true;
  return winding_number(shape, local_point) > 0.5;
}

// The box around `box` turned by `pose`: centre R c + t, half-sizes |R| h (the turned corners'
// hull, in exact arithmetic), widened by twice the rounding bound of a corner turned in doubles,
// 4.5e-16 (|R| (|c| + h) + |t|) per axis, so it holds every corner as computed: a broad phase
// that may skip a pair by its box gap stays conservative. A fifth of the cost of turning the
// eight corners (world_bounds was 5% of a crowded table's plan).
Eigen::AlignedBox3d turned_box(const Eigen::AlignedBox3d& box, const Pose& pose) {
  if (box.isEmpty()) return box;
  const Eigen::Vector3d centre = box.center(), half = box.sizes() / 2;
  const Eigen::Matrix3d turn = pose.linear().cwiseAbs();
  const Eigen::Vector3d turned_centre = pose * centre, turned_half = turn * half;
  const Eigen::Vector3d slack =
      2 * 4.5e-16 * (turn * (centre.cwiseAbs() + half) + pose.translation().cwiseAbs());
  return {turned_centre - turned_half - slack, turned_centre + turned_half + slack};
}

// The gap between two boxes (0 when they meet).
double box_gap(const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b) {
  return std::sqrt(a.squaredExteriorDistance(b));
}

// One part of a placed body: its shape and its world pose.
struct PlacedPart {
  const internal::ShapeData* shape;
  Pose pose;
};

// The surface distance of two parts (0 when touching or crossing), with nearest points, when it
// is below `bound`; otherwise some value >= `bound` (FCL's distance traversal starts from `bound`
// and prunes every pair of bounding volumes at least that far apart, so far pairs cost little).
// FCL's collide first: it is an order of magnitude faster than its distance (bench/RESULTS.md)
// and settles every pair whose surfaces meet.
Proximity part_proximity(const PlacedPart& a, const PlacedPart& b, double bound) {
  Proximity out;
  fcl::CollisionRequestd collision_request;
  fcl::CollisionResultd collision;
  {
    const Counted counted(/*fcl_call=*/true);
    fcl::collide(a.shape->bvh.get(), a.pose, b.shape->bvh.get(), b.pose, collision_request,
                 collision);
  }
  if (collision.isCollision()) {
    out.intersecting = true;
    out.point_a = out.point_b = collision.getContact(0).pos;
    return out;
  }
  out.distance = bound;
  if (bound <= 0) return out;  // apart, and nothing more was asked
  fcl::DistanceRequestd request(/*enable_nearest_points=*/true);
  fcl::DistanceResultd result;
  if (std::isfinite(bound)) result.min_distance = bound;
  {
    const Counted counted(/*fcl_call=*/true);
    fcl::distance(a.shape->bvh.get(), a.pose, b.shape->bvh.get(), b.pose, request, result);
  }
  if (!(result.min_distance < bound)) return out;
  // Surfaces that meet along coincident faces (coplanar triangles, which FCL's collide misses)
  // come out of the distance query as rounding noise (3e-18 m for two nested boxes sharing
  // faces): below kTouching they touch, and touching counts as intersecting.
  constexpr double kTouching = 1e-12;  // m: far below any margin, far above rounding at 10 m
  out.distance = result.min_distance <= kTouching ? 0.0 : result.min_distance;
  out.intersecting = out.distance == 0;
  // FCL 0.7 reports a BVH pair's nearest points in the world frame.
  out.point_a = result.nearest_points[0];
  out.point_b = result.nearest_points[1];
  return out;
}

// Whether one part lies inside the other, asked when their surfaces do not meet: then all of a
// part is inside or all is outside, so one vertex of each decides.
bool one_inside_other(const PlacedPart& a, const PlacedPart& b) {
  const Eigen::Vector3d a_vertex_in_b = b.pose.inverse() * (a.pose * a.shape->vertices.front());
  const Eigen::Vector3d b_vertex_in_a = a.pose.inverse() * (b.pose * b.shape->vertices.front());
  return shape_contains(*b.shape, a_vertex_in_b) || shape_contains(*a.shape, b_vertex_in_a);
}

std::vector<PlacedPart> placed_parts(const PlacedBody& body) {
  std::vector<PlacedPart> parts;
  parts.reserve(body.body->parts().size());
  for (const BodyPart& part : body.body->parts())
    parts.push_back({&ShapeAccess::data(part.shape), body.pose * part.pose});
  return parts;
}

// Proximity of two bodies, exact when the distance is below `reach`; otherwise the result is
// some lower bound >= `reach`, found cheaply: part pairs whose boxes lie `reach` or more apart are
// not handed to FCL (their box gap stands in), and FCL prunes at `reach`. `test_inside`: also ask
// whether a part lies wholly inside another (needed once per pair of placements; a sweep asks at
// its start only).
Proximity body_proximity(const PlacedBody& a, const PlacedBody& b, double reach,
                         bool test_inside = true) {
  Proximity best;
  best.distance = kInfinity;
  const std::vector<PlacedPart> parts_b = placed_parts(b);
  std::vector<Eigen::AlignedBox3d> boxes_b;
  for (const PlacedPart& pb : parts_b) boxes_b.push_back(turned_box(pb.shape->bounds, pb.pose));
  for (const PlacedPart& pa : placed_parts(a)) {
    const Eigen::AlignedBox3d box_a = turned_box(pa.shape->bounds, pa.pose);
    for (std::size_t j = 0; j < parts_b.size(); ++j) {
      const double gap = box_gap(box_a, boxes_b[j]);
      if (gap > 0 && gap >= reach) {
        best.distance = std::min(best.distance, gap);
        continue;
      }
      Proximity pair = part_proximity(pa, parts_b[j], std::min(reach, best.distance));
      if (test_inside && !pair.intersecting && one_inside_other(pa, parts_b[j])) {
        pair.distance = 0;
        pair.intersecting = true;
      }
      if (pair.intersecting) return pair;
      if (pair.distance < best.distance) best = pair;
    }
  }
  return best;
}

// Whether a proximity breaks the margin rule (touching always does).
bool too_close(const Proximity& p, double margin) { return p.intersecting || p.distance < margin; }

}  // namespace

CollisionShape::CollisionShape(const Mesh& mesh)
    : data_(shape_data(mesh.vertices, mesh.triangles, mesh.source)) {}

CollisionShape CollisionShape::box(const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
  if (!(low.array() < high.array()).all())
    throw GeometryError("a collision box needs low < high in x, y and z");
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back((i & 1) ? high.x() : low.x(), (i & 2) ? high.y() : low.y(),
                         (i & 4) ? high.z() : low.z());
  // Counter-clockwise seen from outside: -z, +z, -y, +y, -x, +x.
  const std::vector<std::array<int, 3>> triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                                     {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                                     {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  auto data = shape_data(corners, triangles, "<box>");
  data->is_box = true;
  return ShapeAccess::make(std::move(data));
}

CollisionShape CollisionShape::surface(const Mesh& mesh, std::span<const int> triangles,
                                       double inset) {
  std::vector<Eigen::Vector3d> corners;
  std::vector<std::array<int, 3>> kept;
  for (const int t : triangles) {
    const std::array<int, 3>& triangle = mesh.triangles.at(t);
    const Eigen::Vector3d centroid =
        (mesh.vertices[triangle[0]] + mesh.vertices[triangle[1]] + mesh.vertices[triangle[2]]) / 3;
    std::array<int, 3> own{};
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d& v = mesh.vertices[triangle[c]];
      const double reach = (v - centroid).norm();
      corners.push_back(reach > inset ? Eigen::Vector3d(v + (centroid - v) * (inset / reach))
                                      : centroid);
      own[c] = static_cast<int>(corners.size()) - 1;
    }
    kept.push_back(own);
  }
  auto data = shape_data(corners, kept, mesh.source);
  data->closed = false;
  return ShapeAccess::make(std::move(data));
}

const Eigen::AlignedBox3d& CollisionShape::bounds() const { return data_->bounds; }
std::span<const Eigen::Vector3d> CollisionShape::vertices() const { return data_->vertices; }
std::size_t CollisionShape::triangle_count() const { return data_->triangles.size(); }

Body::Body(std::string name, std::vector<BodyPart> parts)
    : name_(std::move(name)), parts_(std::move(parts)) {
  if (parts_.empty()) throw GeometryError("body '" + name_ + "' has no part");
  for (const BodyPart& part : parts_) bounds_.extend(turned_box(part.shape.bounds(), part.pose));
}

Body Body::joined(const Body& other, const Pose& other_in_this, std::string name) const {
  std::vector<BodyPart> parts = parts_;
  for (const BodyPart& part : other.parts_)
    parts.push_back({part.shape, other_in_this * part.pose});
  return Body(std::move(name), std::move(parts));
}

Eigen::AlignedBox3d world_bounds(const PlacedBody& placed) {
  Eigen::AlignedBox3d out;
  for (const BodyPart& part : placed.body->parts())
    out.extend(turned_box(part.shape.bounds(), placed.pose * part.pose));
  return out;
}

double lowest_z(const PlacedBody& placed) {
  const Counted counted(/*fcl_call=*/false);
  double lowest = kInfinity;
  for (const BodyPart& part : placed.body->parts()) {
    const Pose pose = placed.pose * part.pose;
    // z of R v + t is the third row of R dotted with v, plus t.z.
    const Eigen::Vector3d row = pose.linear().row(2).transpose();
    for (const Eigen::Vector3d& v : part.shape.vertices())
      lowest = std::min(lowest, row.dot(v) + pose.translation().z());
  }
  return lowest;
}

Proximity proximity(const PlacedBody& a, const PlacedBody& b) {
  const Counted counted(/*fcl_call=*/false);
  return body_proximity(a, b, kInfinity);
}

bool collide(const PlacedBody& a, const PlacedBody& b, double margin) {
  const Counted counted(/*fcl_call=*/false);
  const double gap = box_gap(world_bounds(a), world_bounds(b));
  if (gap > 0 && gap >= margin) return false;
  return too_close(body_proximity(a, b, margin), margin);
}

Nearest nearest(const PlacedBody& body, std::span<const PlacedBody> others) {
  const Counted counted(/*fcl_call=*/false);
  Nearest best{.index = -1, .distance = kInfinity};
  const Eigen::AlignedBox3d box = world_bounds(body);
  for (std::size_t i = 0; i < others.size(); ++i) {
    // A body whose box is further than the best distance so far cannot be nearer.
    if (box_gap(box, world_bounds(others[i])) >= best.distance) continue;
    const double distance = body_proximity(body, others[i], best.distance).distance;
    if (distance < best.distance) best = {.index = static_cast<int>(i), .distance = distance};
  }
  return best;
}

Sweep sweep(const PlacedBody& moving, const Eigen::Vector3d& motion,
            std::span<const PlacedBody> obstacles, double margin) {
  const Counted counted(/*fcl_call=*/false);
  Sweep result;
  result.min_distance = kInfinity;
  const double length = motion.norm();
  // Broad phase over the whole path: the box swept by a translation is the hull of its ends.
  Eigen::AlignedBox3d path = world_bounds(moving);
  path.extend(world_bounds({moving.body, Eigen::Translation3d(motion) * moving.pose}));
  std::vector<int> near;
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const double gap = box_gap(path, world_bounds(obstacles[i]));
    if (gap <= 0 || gap < margin) near.push_back(static_cast<int>(i));
  }
  if (near.empty()) return result;
  // The step never falls below the margin (margin 0: the two ends only).
  const double least_step = margin > 0 ? margin : std::max(length, 1e-300);
  for (double travelled = 0;;) {
    const double fraction = length > 0 ? travelled / length : 0.0;
    const PlacedBody here{moving.body, Eigen::Translation3d(fraction * motion) * moving.pose};
    ++result.samples;
    // A lower bound of the distance to every obstacle.
    double closest = kInfinity;
    for (const int i : near) {
      // Exact below kSweepReach margins (or the rest of the path, if shorter) plus the margin:
      // beyond, a lower bound does, and an obstacle further than the rest of the path cannot be
      // reached by what remains of the motion.
      const Proximity p = body_proximity(
          here, obstacles[i], std::min(length - travelled, kSweepReach * margin) + margin,
          travelled == 0);
      if (too_close(p, margin)) {
        result.clear = false;
        result.obstacle = i;
        result.at = fraction;
        result.min_distance = std::min(result.min_distance, p.distance);
        return result;
      }
      closest = std::min(closest, p.distance);
    }
    result.min_distance = std::min(result.min_distance, closest);
    if (travelled >= length) return result;
    travelled = std::min(length, travelled + std::max(least_step, closest - margin / 2));
  }
}

CollisionTally::CollisionTally() {
  auto counts = std::make_unique<AtomicCounts>();
  AtomicCounts* expected = nullptr;
  if (!live_tally.compare_exchange_strong(expected, counts.get()))
    throw GeometryError("a CollisionTally is already counting");
  counts.release();  // live_tally owns it until the destructor
}

CollisionTally::~CollisionTally() {
  // Queries still running on other threads hold the pointer: a tally lives only around work
  // that has returned (the benches' use), so deleting here is safe.
  delete live_tally.exchange(nullptr);
}

CollisionCounts CollisionTally::counts() const {
  const AtomicCounts& live = *live_tally.load();
  return {.queries = live.queries.load(),
          .fcl_calls = live.fcl_calls.load(),
          .seconds = 1e-9 * static_cast<double>(live.nanoseconds.load()),
          .fcl_seconds = 1e-9 * static_cast<double>(live.fcl_nanoseconds.load())};
}

Body gripper_body(const GripperSpec& gripper, double opening, double shrink) {
  const double tip = gripper.tip_beyond_contact, palm = tip - gripper.finger_length;
  const double fx = gripper.finger_width / 2, px = gripper.palm_width / 2;
  const double inner = opening / 2, outer = opening / 2 + gripper.finger_thickness;
  const double palm_y = gripper.max_opening / 2 + gripper.finger_thickness;
  const Eigen::Vector3d in = Eigen::Vector3d::Constant(shrink);
  const auto box = [&](const Eigen::Vector3d& low, const Eigen::Vector3d& high) {
    return BodyPart{CollisionShape::box(low + in, high - in)};
  };
  return Body("gripper", {box({-fx, inner, palm}, {fx, outer, tip}),
                          box({-fx, -outer, palm}, {fx, -inner, tip}),
                          box({-px, -palm_y, palm - gripper.palm_height}, {px, palm_y, palm})});
}

}  // namespace spar::geometry
