// The collision layer (geometry/collision.hpp): distances, the margin rule, bodies inside
// bodies, the table, conservative sweeps, the gripper's boxes; properties against an independent
// separating-axis test of oriented boxes and against dense sampling of sweeps.
#include "spar/geometry/collision.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/stable_poses.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::geometry {
namespace {

Pose at(double x, double y, double z, double yaw = 0) {
  return Pose(Eigen::Translation3d(x, y, z) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

const Body& unit_cube() {
  static const Body cube("cube", CollisionShape(make_box({1, 1, 1})));
  return cube;
}

TEST(Collision, DistanceBetweenBoxesIsTheGapBetweenTheirFaces) {
  const PlacedBody a{&unit_cube(), at(0, 0, 0)}, b{&unit_cube(), at(1.25, 0, 0)};
  const Proximity p = proximity(a, b);
  EXPECT_NEAR(p.distance, 0.25, 1e-9);
  EXPECT_FALSE(p.intersecting);
  EXPECT_NEAR(p.point_a.x(), 1.0, 1e-9);
  EXPECT_NEAR(p.point_b.x(), 1.25, 1e-9);
}

TEST(Collision, MarginMakesNearBodiesCollideAndTouchingAlwaysDoes) {
  const PlacedBody a{&unit_cube(), at(0, 0, 0)};
  EXPECT_FALSE(collide(a, {&unit_cube(), at(1.002, 0, 0)}, 0.001));
  EXPECT_TRUE(collide(a, {&unit_cube(), at(1.0005, 0, 0)}, 0.001));
  EXPECT_TRUE(collide(a, {&unit_cube(), at(1.0, 0, 0)}, 0.0));  // touching
  EXPECT_TRUE(collide(a, {&unit_cube(), at(0.5, 0.5, 0)}, 0.0));
}

TEST(Collision, BodyWhollyInsideAnotherIntersects) {
  const Body small("small", CollisionShape::box({0, 0, 0}, {0.1, 0.1, 0.1}));
  const PlacedBody big{&unit_cube(), at(0, 0, 0)}, inside{&small, at(0.4, 0.4, 0.4)};
  EXPECT_TRUE(proximity(big, inside).intersecting);
  EXPECT_TRUE(proximity(inside, big).intersecting);
  EXPECT_TRUE(collide(inside, big, 0.001));
  // The same in a non-convex mesh: the peg inside the block's blind hole is not inside the
  // block's solid, a cube buried in the block's wall is.
  const Body block("block", CollisionShape(builtin_mesh("block")));
  const Body tiny("tiny", CollisionShape::box({0, 0, 0}, {0.002, 0.002, 0.002}));
  EXPECT_FALSE(proximity({&block, at(0, 0, 0)}, {&tiny, at(-0.001, -0.001, 2.5 * 0.0254)})
                   .intersecting);  // in the hole, above its floor
  EXPECT_TRUE(proximity({&block, at(0, 0, 0)}, {&tiny, at(0.04, 0.0, 0.01)}).intersecting);
}

TEST(Collision, PegInsertedInTheBlockTouchesOnlyAtTheHoleFloor) {
  // The seed's assembly: the peg upside down, its frame 6 in above the block's (Ta).
  const Body block("block", CollisionShape(builtin_mesh("block"))),
      peg("peg", CollisionShape(builtin_mesh("peg")));
  Pose relative = at(0, 0, 6 * units::kInch);
  relative.rotate(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  const PlacedBody fixed{&block, Pose::Identity()};
  EXPECT_NEAR(proximity(fixed, {&peg, relative}).distance, 0.0, 1e-9);
  // Lifted 1 mm, the shaft is 0.05 in from the hole's walls: 1 mm from the floor is the nearest.
  const PlacedBody lifted{&peg, at(0, 0, 0.001) * relative};
  EXPECT_NEAR(proximity(fixed, lifted).distance, 0.001, 1e-9);
  // Pushed sideways by 0.1 in (twice the clearance), the shaft enters the wall.
  const PlacedBody sideways{&peg, at(0.1 * units::kInch, 0, 0.001) * relative};
  EXPECT_TRUE(collide(fixed, sideways, 0.0));
}

TEST(Collision, ObjectsInStablePosesRestOnTheTable) {
  const ObjectModel block = make_builtin_object("block");
  const Body body("block", CollisionShape(block.mesh()));
  for (const StablePose& pose : stable_poses(block)) {
    const double lowest = lowest_z({&body, at(0.3, 0.1, 0, 0.7) * pose.object_to_world});
    EXPECT_NEAR(lowest, 0.0, kTableTolerance) << pose.label;
  }
  EXPECT_LT(lowest_z({&body, at(0, 0, -0.01)}), -kTableTolerance);
}

TEST(Collision, NearestNamesTheClosestBody) {
  const PlacedBody probe{&unit_cube(), at(0, 0, 0)};
  const std::vector<PlacedBody> others = {
      {&unit_cube(), at(3, 0, 0)}, {&unit_cube(), at(0, 1.5, 0)}, {&unit_cube(), at(-2.2, 0, 0)}};
  const Nearest found = nearest(probe, others);
  EXPECT_EQ(found.index, 1);
  EXPECT_NEAR(found.distance, 0.5, 1e-9);
  EXPECT_EQ(nearest(probe, {}).index, -1);
}

TEST(Collision, SweepStopsAtTheFirstObstacleOnThePath) {
  const PlacedBody moving{&unit_cube(), at(0, 0, 3)};
  const std::vector<PlacedBody> obstacles = {{&unit_cube(), at(5, 0, 0)},
                                             {&unit_cube(), at(0.2, 0.2, 0)}};
  const Sweep down = sweep(moving, {0, 0, -2.5}, obstacles, 0.001);
  EXPECT_FALSE(down.clear);
  EXPECT_EQ(down.obstacle, 1);
  EXPECT_GT(down.at, (2 - 0.001) / 2.5 - 1e-9);  // contact is 2 down, within the margin before
  const Sweep short_down = sweep(moving, {0, 0, -1.9}, obstacles, 0.001);
  EXPECT_TRUE(short_down.clear);
  EXPECT_GE(short_down.min_distance, 0.1 - 1e-9);  // a lower bound (+inf: broad phase only)
  // Far from everything, one sample: the broad phase drops both obstacles.
  EXPECT_EQ(sweep({&unit_cube(), at(0, 0, 10)}, {0, 0, 1}, obstacles, 0.001).samples, 0);
}

TEST(Collision, SweepDoesNotStepOverAThinPlate) {
  // A plate 0.2 mm thick across the path of a 1 mm-margin sweep 10 cm long.
  const Body plate("plate", CollisionShape::box({-1, -1, 0}, {1, 1, 0.0002}));
  const PlacedBody moving{&unit_cube(), at(-0.5, -0.5, 0.05)};
  const std::vector<PlacedBody> obstacles = {{&plate, Pose::Identity()}};
  const Sweep through = sweep(moving, {0, 0, -0.1}, obstacles, 0.001);
  EXPECT_FALSE(through.clear);
}

// The tally counts top-level queries once (a sweep's own distances are inside it), the FCL calls
// they make, and nothing before or after its lifetime; two tallies at once are refused.
TEST(CollisionTally, CountsTopLevelQueriesAndTheirFclCallsWhileAlive) {
  const PlacedBody a{&unit_cube(), at(0, 0, 0)}, near{&unit_cube(), at(1.0005, 0, 0)},
      far{&unit_cube(), at(10, 0, 0)};
  (void)collide(a, near, 0.001);  // before the tally: not counted
  CollisionCounts counts;
  {
    const CollisionTally tally;
    EXPECT_THROW_MESSAGE(CollisionTally(), "a CollisionTally is already counting");
    EXPECT_TRUE(collide(a, near, 0.001));  // FCL collide, then distance
    EXPECT_FALSE(collide(a, far, 0.001));  // broad phase only: no FCL call
    const std::vector<PlacedBody> obstacles = {{&unit_cube(), at(0.2, 0.2, 0)}};
    const Sweep down = sweep({&unit_cube(), at(0, 0, 3)}, {0, 0, -2.5}, obstacles, 0.001);
    EXPECT_FALSE(down.clear);
    counts = tally.counts();
  }
  EXPECT_EQ(counts.queries, 3);
  EXPECT_GE(counts.fcl_calls, 3);
  EXPECT_GT(counts.seconds, 0.0);
  EXPECT_LE(counts.fcl_seconds, counts.seconds);
  const CollisionTally again;  // the first one is gone
  EXPECT_EQ(again.counts().queries, 0);
}

TEST(Collision, GripperFingersAreAtHalfTheOpening) {
  const GripperSpec spec;
  const Body gripper = gripper_body(spec, 0.05);
  ASSERT_EQ(gripper.parts().size(), 3u);
  EXPECT_NEAR(gripper.parts()[0].shape.bounds().min().y(), 0.025, 1e-12);
  EXPECT_NEAR(gripper.parts()[1].shape.bounds().max().y(), -0.025, 1e-12);
  EXPECT_NEAR(gripper.parts()[0].shape.bounds().max().z(), spec.tip_beyond_contact, 1e-12);
  // Closed on a slab 0.05 wide, the fingers touch it; open, they clear it by 25.8 mm a side.
  const Body cube("cube", CollisionShape::box({-0.025, -0.025, -0.01}, {0.025, 0.025, 0.01}));
  EXPECT_NEAR(proximity({&gripper, Pose::Identity()}, {&cube, Pose::Identity()}).distance, 0,
              1e-12);
  const Body open = gripper_body(spec, spec.max_opening);
  EXPECT_NEAR(proximity({&open, Pose::Identity()}, {&cube, Pose::Identity()}).distance,
              spec.max_opening / 2 - 0.025, 1e-9);
}

TEST(Collision, JoinedBodyCollidesWithEitherPart) {
  const Body pair = unit_cube().joined(unit_cube(), at(3, 0, 0), "pair");
  ASSERT_EQ(pair.parts().size(), 2u);
  EXPECT_TRUE(collide({&pair, Pose::Identity()}, {&unit_cube(), at(3.5, 0.5, 0)}, 0.001));
  EXPECT_FALSE(collide({&pair, Pose::Identity()}, {&unit_cube(), at(1.5, 0, 0)}, 0.001));
  EXPECT_NEAR(pair.bounds().max().x(), 4.0, 1e-12);
}

TEST(Collision, BadShapesAreErrors) {
  EXPECT_THROW_MESSAGE(CollisionShape::box({0, 0, 0}, {1, 0, 1}),
                       "a collision box needs low < high in x, y and z");
  Mesh empty;
  empty.source = "empty.off";
  EXPECT_THROW_MESSAGE(CollisionShape{empty}, "empty.off: a collision shape needs triangles");
}

// --- properties ---

struct OrientedBox {
  Eigen::Vector3d half;
  Pose pose;
};

// Independent of FCL: do two oriented boxes overlap (open sets)? The separating axis theorem over
// the 15 axes (3 + 3 face normals, 9 edge cross products).
bool boxes_overlap(const OrientedBox& a, const OrientedBox& b) {
  const Eigen::Matrix3d ra = a.pose.linear(), rb = b.pose.linear();
  const Eigen::Vector3d d = b.pose.translation() - a.pose.translation();
  std::vector<Eigen::Vector3d> axes;
  for (int i = 0; i < 3; ++i) {
    axes.push_back(ra.col(i));
    axes.push_back(rb.col(i));
    for (int j = 0; j < 3; ++j) axes.push_back(ra.col(i).cross(rb.col(j)));
  }
  for (const Eigen::Vector3d& axis : axes) {
    if (axis.norm() < 1e-9) continue;
    const Eigen::Vector3d n = axis.normalized();
    double ra_extent = 0, rb_extent = 0;
    for (int i = 0; i < 3; ++i) {
      ra_extent += a.half[i] * std::abs(ra.col(i).dot(n));
      rb_extent += b.half[i] * std::abs(rb.col(i).dot(n));
    }
    if (std::abs(d.dot(n)) >= ra_extent + rb_extent) return false;
  }
  return true;
}

rc::Gen<OrientedBox> random_box() {
  return rc::gen::map(rc::gen::arbitrary<std::array<int, 9>>(), [](const std::array<int, 9>& r) {
    const auto unit = [](int v) { return (static_cast<unsigned>(v) % 10001) / 10000.0; };
    OrientedBox box;
    box.half = {0.02 + 0.2 * unit(r[0]), 0.02 + 0.2 * unit(r[1]), 0.02 + 0.2 * unit(r[2])};
    box.pose = Pose(Eigen::Translation3d(0.6 * unit(r[3]), 0.6 * unit(r[4]), 0.6 * unit(r[5])) *
                    Eigen::AngleAxisd(6.3 * unit(r[6]), Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(6.3 * unit(r[7]), Eigen::Vector3d::UnitX()) *
                    Eigen::AngleAxisd(6.3 * unit(r[8]), Eigen::Vector3d::UnitY()));
    return box;
  });
}

Body body_of(const OrientedBox& box) {
  return Body("box", CollisionShape::box(-box.half, box.half));
}

// Found by the property below (CI's sanitizer stage, 25 cases): a box inside a slightly larger
// one with four faces coincident was "apart" at 3.5e-18 m, FCL's collide missing the coplanar
// triangles and the inside test seeing a vertex on the surface.
TEST(Collision, NestedBoxesSharingFacesIntersect) {
  Pose pose(Eigen::Translation3d(0.47052, 0.47052, 0.47052) *
            Eigen::AngleAxisd(std::acos(0.226099), Eigen::Vector3d::UnitX()));
  const Body outer = body_of({{0.02002, 0.02, 0.02}, pose});
  const Body inner = body_of({{0.02, 0.02, 0.02}, pose});
  const Proximity p = proximity({&outer, pose}, {&inner, pose});
  EXPECT_TRUE(p.intersecting);
  EXPECT_EQ(p.distance, 0.0);
  EXPECT_TRUE(collide({&outer, pose}, {&inner, pose}, 0.0));
}

// Intersection as FCL and the inside test report it matches the separating-axis test.
RC_GTEST_PROP(CollisionProperty, IntersectionMatchesSeparatingAxes, ()) {
  const OrientedBox a = *random_box(), b = *random_box();
  const Body body_a = body_of(a), body_b = body_of(b);
  const Proximity p = proximity({&body_a, a.pose}, {&body_b, b.pose});
  RC_ASSERT((p.distance <= 0) == boxes_overlap(a, b));
}

// The distance is symmetric, and the margin rule is "distance < margin" for bodies apart.
RC_GTEST_PROP(CollisionProperty, CollideIsDistanceBelowTheMargin, ()) {
  const OrientedBox a = *random_box(), b = *random_box();
  const double margin = *rc::gen::inRange(0, 100) / 1000.0;
  const Body body_a = body_of(a), body_b = body_of(b);
  const PlacedBody pa{&body_a, a.pose}, pb{&body_b, b.pose};
  const double d = proximity(pa, pb).distance;
  RC_ASSERT(std::abs(d - proximity(pb, pa).distance) <= 1e-9);
  if (std::abs(d - margin) > 1e-9) RC_ASSERT(collide(pa, pb, margin) == (d <= 0 || d < margin));
}

// A clear sweep keeps at least half the margin everywhere along the path (checked at 400 points).
RC_GTEST_PROP(CollisionProperty, ClearSweepKeepsHalfTheMarginEverywhere, ()) {
  const OrientedBox moving = *random_box(), obstacle = *random_box();
  const Eigen::Vector3d motion(*rc::gen::inRange(-300, 300) / 1000.0,
                               *rc::gen::inRange(-300, 300) / 1000.0,
                               *rc::gen::inRange(-300, 300) / 1000.0);
  const double margin = 0.001 * *rc::gen::inRange(1, 20);
  const Body body_m = body_of(moving), body_o = body_of(obstacle);
  const std::vector<PlacedBody> obstacles = {{&body_o, obstacle.pose}};
  const Sweep result = sweep({&body_m, moving.pose}, motion, obstacles, margin);
  RC_CLASSIFY(result.clear, "clear");
  if (!result.clear) return;
  for (int k = 0; k <= 400; ++k) {
    const PlacedBody here{&body_m, Eigen::Translation3d(motion * (k / 400.0)) * moving.pose};
    RC_ASSERT(proximity(here, obstacles[0]).distance >= margin / 2 - 1e-9);
  }
}

// world_bounds (the broad phase's box) holds every vertex of the placed body as the exact queries
// turn it in doubles (by the part's world pose, the body's pose times the part's), far from the
// origin too, and for box parts it is their hull up to rounding. A body of two parts, the second
// placed off the first.
RC_GTEST_PROP(CollisionProperty, WorldBoundsHoldEveryTurnedVertex, ()) {
  const OrientedBox a = *random_box(), b = *random_box();
  const double far = std::pow(10.0, *rc::gen::inRange(-1, 4));  // metres: 0.1 to 1000
  const Pose pose = Pose(Eigen::Translation3d(far * a.pose.translation())) * b.pose;
  const Body body("two", {{CollisionShape::box(-a.half, a.half)},
                          {CollisionShape::box(-b.half, b.half), a.pose}});
  const Eigen::AlignedBox3d bounds = world_bounds({&body, pose});
  Eigen::AlignedBox3d hull;
  for (const BodyPart& part : body.parts())
    for (const Eigen::Vector3d& v : part.shape.vertices()) {
      const Eigen::Vector3d turned = (pose * part.pose) * v;
      RC_ASSERT(bounds.contains(turned));
      hull.extend(turned);
    }
  RC_ASSERT((bounds.min() - hull.min()).cwiseAbs().maxCoeff() <= 1e-12 * far + 1e-12);
  RC_ASSERT((bounds.max() - hull.max()).cwiseAbs().maxCoeff() <= 1e-12 * far + 1e-12);
}

}  // namespace
}  // namespace spar::geometry
