// Properties over random boxes and random convex polyhedra (RapidCheck): every stable pose rests
// its facet on the table with the whole object above it and the centre of mass over the facet;
// every grasp squeezes two parallel opposite faces exactly its width apart. Two random boxes
// joined rigidly rest somewhere (every rigid body does: on the hull facet nearest its centre of
// mass), and every resting pose joint_stable_poses gives has both boxes above the table and
// stands there; one box joined with nothing rests exactly as its stable poses. The triangle tree
// reports to a segment exactly the triangles whose boxes the segment meets. InsetTest is
// inset_distance compared, repeated vertices included. Exposure's lattice shortcut marks only
// points whose own ray is blocked.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/grasps.hpp"
#include "spar/geometry/internal/exposure.hpp"
#include "spar/geometry/internal/polygon2d.hpp"
#include "spar/geometry/internal/triangle_tree.hpp"
#include "spar/geometry/stable_poses.hpp"

namespace spar::geometry {
namespace {

double random_length(double low, double high) {
  return low + (high - low) * *rc::gen::inRange(0, 10001) / 10000.0;
}

void check_stable_poses(const ObjectModel& object) {
  const double tolerance = 1e3 * object.tolerance();
  const auto poses = stable_poses(object);
  RC_ASSERT(!poses.empty());
  for (const StablePose& pose : poses) {
    for (const auto& triangle : object.mesh().triangles)
      for (const int v : triangle)
        RC_ASSERT((pose.object_to_world * object.mesh().vertices[v]).z() >= -tolerance);
    const HullFacet& facet = object.hull_facets()[pose.hull_facet];
    std::vector<Eigen::Vector2d> footprint;
    for (const auto& corner : facet.polygon) {
      const Eigen::Vector3d world = pose.object_to_world * corner;
      RC_ASSERT(std::abs(world.z()) <= tolerance);
      footprint.push_back(world.head<2>());
    }
    // The centre of mass must be strictly on one side (inside) of every edge of the footprint.
    // Seen from above the facet (its outward normal now points down) the footprint is clockwise.
    const Eigen::Vector2d com = (pose.object_to_world * object.center_of_mass()).head<2>();
    double nearest_edge = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < footprint.size(); ++i) {
      const Eigen::Vector2d a = footprint[i], edge = footprint[(i + 1) % footprint.size()] - a;
      const Eigen::Vector2d to_com = com - a;
      nearest_edge =
          std::min(nearest_edge, (to_com.x() * edge.y() - to_com.y() * edge.x()) / edge.norm());
    }
    RC_ASSERT(nearest_edge > 0);
    RC_ASSERT(std::abs(nearest_edge - pose.margin) <= tolerance);
    for (const int face : pose.table_faces)
      RC_ASSERT(std::abs((pose.object_to_world * object.face(face).centroid).z()) <= tolerance);
  }
}

void check_grasps(const ObjectModel& object) {
  GripperSpec gripper;
  gripper.max_opening = 1e6;  // every pair, so random shapes exercise the grasp code
  for (const Grasp& grasp : compute_grasps(object, gripper, GraspQuantization{})) {
    const Face& a = object.face(grasp.face_plus_y);
    const Face& b = object.face(grasp.face_minus_y);
    RC_ASSERT(a.normal.dot(b.normal) < -1 + 1e-9);
    RC_ASSERT(std::abs(a.offset + b.offset - grasp.width) <= 1e3 * object.tolerance());
    const Eigen::Vector3d plus = grasp.gripper_in_object * Eigen::Vector3d(0, grasp.width / 2, 0);
    const Eigen::Vector3d minus = grasp.gripper_in_object * Eigen::Vector3d(0, -grasp.width / 2, 0);
    RC_ASSERT(std::abs(a.normal.dot(plus) - a.offset) <= 1e3 * object.tolerance());
    RC_ASSERT(std::abs(b.normal.dot(minus) - b.offset) <= 1e3 * object.tolerance());
  }
}

// The triangle tree reports to a segment query exactly the triangles whose boxes the segment
// meets (TriangleTree::segment_meets_box_of): the grasp search's exposure test gathers triangles
// once per face region and relies on this to answer as a walk of the tree per ray would. Points on
// a coarse grid, so segments run along box faces and axes (zero direction components) often.
RC_GTEST_PROP(GeometryProperties, TheTreeReportsToASegmentTheTrianglesWhoseBoxesItMeets, ()) {
  const auto coordinate = [] { return *rc::gen::inRange(-8, 9) / 4.0; };
  const auto point = [&] { return Eigen::Vector3d(coordinate(), coordinate(), coordinate()); };
  const int count = *rc::gen::inRange(1, 40);
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;
  for (int t = 0; t < count; ++t) {
    for (int k = 0; k < 3; ++k) vertices.push_back(point());
    triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  const internal::TriangleTree tree(vertices, triangles);
  const Eigen::Vector3d p = point(), q = point();
  std::vector<bool> reported(count, false);
  (void)tree.any_on_segment(p, q, [&](int t) {
    reported[t] = true;
    return false;  // every triangle the walk reaches
  });
  for (int t = 0; t < count; ++t) RC_ASSERT(reported[t] == tree.segment_meets_box_of(p, q, t));
}

// Over each face of `object`, a lattice of `n` x `n` points spanning the face's box in its plane:
// every point Exposure::surely_blocked marks must get false from the ray cast itself
// (Exposure::operator()). Returns how many points were marked.
int check_surely_blocked(const ObjectModel& object, int n) {
  const Mesh& mesh = object.mesh();
  const internal::TriangleTree tree(mesh.vertices, mesh.triangles);
  int marked = 0;
  for (const Face& face : object.faces()) {
    const internal::PlaneBasis basis = internal::plane_basis(face.normal);
    Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d high = -low;
    for (const int t : face.triangles)
      for (const int v : mesh.triangles[t]) {
        low = low.cwiseMin(internal::project(basis, mesh.vertices[v]));
        high = high.cwiseMax(internal::project(basis, mesh.vertices[v]));
      }
    const auto on_plane = [&](double x, double y) {
      return Eigen::Vector3d(basis.u * x + basis.v * y + face.normal * face.offset);
    };
    const std::array<Eigen::Vector3d, 4> corners{
        on_plane(low.x(), low.y()), on_plane(high.x(), low.y()), on_plane(low.x(), high.y()),
        on_plane(high.x(), high.y())};
    internal::Exposure exposed(object, tree, corners, face.normal);
    const Eigen::Vector3d origin = corners[0];
    const Eigen::Vector3d u_step = basis.u * ((high.x() - low.x()) / n);
    const Eigen::Vector3d v_step = basis.v * ((high.y() - low.y()) / n);
    const std::vector<char> blocked = exposed.surely_blocked(origin, u_step, v_step, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (blocked[static_cast<std::size_t>(i) * n + j]) {
          ++marked;
          const Eigen::Vector3d point = origin + (i + 0.5) * u_step + (j + 0.5) * v_step;
          RC_ASSERT(!exposed(point));
        }
  }
  return marked;
}

// The block's peg hole walls face each other: their lattices are marked, and rightly.
TEST(GeometryProperties, TheBlocksHiddenFacesAreSurelyBlocked) {
  const ObjectModel block = make_builtin_object("block");
  EXPECT_GT(check_surely_blocked(block, 41), 1000);
}

// Random stepped solids (a random grid's cells, one or two boxes of them carved out: holes,
// notches and faces hidden in them), turned by a random rotation so the rays run along no axis.
RC_GTEST_PROP(GeometryProperties, SurelyBlockedPointsAreBlockedOnRandomSteppedSolids, ()) {
  std::array<std::vector<double>, 3> grid;
  for (std::vector<double>& values : grid) {
    values = {0};
    const int count = *rc::gen::inRange(2, 6);
    for (int i = 0; i < count; ++i) values.push_back(values.back() + random_length(0.2, 2));
  }
  RectilinearSolid solid(grid[0], grid[1], grid[2]);
  const int carves = *rc::gen::inRange(1, 3);
  for (int c = 0; c < carves; ++c) {
    Eigen::Vector3d low, high;  // cell boundaries, so the carve takes whole cells
    for (int axis = 0; axis < 3; ++axis) {
      const int cells = static_cast<int>(grid[axis].size()) - 1;
      const int first = *rc::gen::inRange(0, cells);
      const int last = *rc::gen::inRange(first + 1, cells + 1);
      low[axis] = grid[axis][first] - (first == 0 ? 1 : 0);  // past the edge: a notch or hole
      high[axis] = grid[axis][last] + (last == cells ? 1 : 0);
    }
    solid.carve(low, high);
  }
  Mesh mesh;
  try {
    mesh = solid.to_mesh();
  } catch (const GeometryError&) {
    RC_DISCARD("cells that touch along an edge only, or none left");
  }
  const Eigen::Quaterniond turn = Eigen::Quaterniond(random_length(-1, 1), random_length(-1, 1),
                                                     random_length(-1, 1), random_length(-1, 1))
                                      .normalized();
  for (Eigen::Vector3d& vertex : mesh.vertices) vertex = turn * vertex;
  std::optional<ObjectModel> object;
  try {
    object.emplace("stepped", std::move(mesh));
  } catch (const GeometryError&) {
    RC_DISCARD("the turned mesh does not validate");
  }
  const int marked = check_surely_blocked(*object, *rc::gen::inRange(3, 42));
  RC_CLASSIFY(marked > 0, "some points marked");
}

RC_GTEST_PROP(GeometryProperties, RandomBoxesRestOnTheirFacetsAndGraspAcrossWidths, ()) {
  const Eigen::Vector3d size(random_length(0.1, 5), random_length(0.1, 5), random_length(0.1, 5));
  const ObjectModel box("box", make_box(size));
  RC_ASSERT(stable_poses(box).size() == 6u);
  check_stable_poses(box);
  check_grasps(box);
  // With fingers longer than the box, no grasp is dropped for a collision: 3 pairs x 4 approaches.
  RC_ASSERT(
      compute_grasps(box, GripperSpec{.max_opening = 1e6, .finger_length = 20}, GraspQuantization{})
          .size() == 12u);
}

RC_GTEST_PROP(GeometryProperties, RandomConvexPolyhedraRestOnTheirFacets, ()) {
  const int count = *rc::gen::inRange(4, 25);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i)
    points.emplace_back(random_length(-5, 5), random_length(-5, 5), random_length(-5, 5));
  Mesh mesh;
  try {
    mesh = make_convex_hull(points);
  } catch (const GeometryError&) {
    RC_DISCARD("the points are (nearly) coplanar");
  }
  const ObjectModel object("hull", mesh);
  check_stable_poses(object);
  check_grasps(object);
}

RC_GTEST_PROP(GeometryProperties, RandomJoinedBoxesRestSomewhereAndOnlyWhereTheyStand, ()) {
  const ObjectModel base(
      "base", make_box({random_length(0.1, 5), random_length(0.1, 5), random_length(0.1, 5)}));
  const ObjectModel part(
      "part", make_box({random_length(0.1, 5), random_length(0.1, 5), random_length(0.1, 5)}));
  const Eigen::Isometry3d relative =
      Eigen::Translation3d(random_length(-8, 8), random_length(-8, 8), random_length(-8, 8)) *
      Eigen::AngleAxisd(random_length(0, 3.14), Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(random_length(0, 3.14), Eigen::Vector3d::UnitX());
  const PosedPart joined[] = {{&base, Eigen::Isometry3d::Identity()}, {&part, relative}};
  const double tolerance = 1e-7;
  const std::vector<JointStablePose> poses = joint_stable_poses(joined, tolerance);
  RC_ASSERT(!poses.empty());
  for (const JointStablePose& pose : poses) {
    RC_ASSERT(std::abs(pose.down.norm() - 1) < 1e-12);
    // Eigen's smallest rotation loses digits when `down` is nearly +z (1 + cos is tiny): 2e-9 seen.
    RC_ASSERT(((pose.frame_to_world.linear() * pose.down) + Eigen::Vector3d::UnitZ()).norm() <
              1e-8);
    double lowest = std::numeric_limits<double>::infinity();
    for (const PosedPart& piece : joined)
      for (const Eigen::Vector3d& vertex : piece.model->mesh().vertices)
        lowest = std::min(lowest, (pose.frame_to_world * piece.pose * vertex).z());
    RC_ASSERT(std::abs(lowest) < 1e-9);
    const PosedPart placed[] = {{&base, pose.frame_to_world},
                                {&part, pose.frame_to_world * relative}};
    const std::optional<double> margin = resting_margin(placed, tolerance);
    RC_ASSERT(margin.has_value());
    RC_ASSERT(*margin > tolerance);
    RC_ASSERT(std::abs(*margin - pose.margin) < 1e-9);
  }
  const PosedPart alone[] = {{&base, Eigen::Isometry3d::Identity()}};
  RC_ASSERT(joint_stable_poses(alone, base.tolerance()).size() == stable_poses(base).size());
}

RC_GTEST_PROP(Polygon2d, InsetTestIsInsetDistanceCompared, ()) {
  // A random convex polygon (the hull of random points), in half the cases with one vertex
  // repeated: a point edge, whose distance is NaN and which inset_distance's minimum skips (and
  // which leaves InsetTest without its box). Points anywhere, and points just inside and outside
  // the corners of the polygon moved out by -distance, where the box's sides are.
  std::vector<Eigen::Vector2d> points;
  for (int i = *rc::gen::inRange(3, 9); i > 0; --i)
    points.emplace_back(random_length(-1, 1), random_length(-1, 1));
  internal::Polygon2 polygon = internal::convex_hull_2d(points);
  RC_PRE(polygon.size() >= 3u);
  if (*rc::gen::arbitrary<bool>()) {
    const std::size_t repeated = *rc::gen::inRange<std::size_t>(0, polygon.size());
    polygon.insert(polygon.begin() + static_cast<std::ptrdiff_t>(repeated), polygon[repeated]);
  }
  const double distance = random_length(-0.3, 0.3);
  const internal::InsetTest inset_at_least(polygon, distance);
  const auto check = [&](const Eigen::Vector2d& point) {
    RC_ASSERT(inset_at_least(point) == (internal::inset_distance(polygon, point) >= distance));
  };
  for (int i = 0; i < 20; ++i) check({random_length(-1.6, 1.6), random_length(-1.6, 1.6)});
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d in = polygon[(i + 1) % n] - polygon[i],
                          out = polygon[(i + n - 1) % n] - polygon[i];
    if (in.norm() == 0 || out.norm() == 0) continue;
    // The two edges' outward unit normals; the moved-out corner lies along their bisector, at
    // t sqrt(2 / (1 + n1 . n2)) from the vertex.
    const Eigen::Vector2d n1 = Eigen::Vector2d(-out.y(), out.x()).normalized(),
                          n2 = Eigen::Vector2d(in.y(), -in.x()).normalized();
    const double t = std::max(0.0, -distance), c = n1.dot(n2);
    if (1 + c < 1e-3) continue;
    const Eigen::Vector2d miter = (n1 + n2).normalized();
    for (const double by : {-1e-9, -1e-12, 0.0, 1e-12, 1e-9, 1e-6})
      check(polygon[i] + t * std::sqrt(2 / (1 + c)) * (1 + by) * miter);
  }
}

}  // namespace
}  // namespace spar::geometry
