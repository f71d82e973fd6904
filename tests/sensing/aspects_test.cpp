// Aspects of objects (sensing/aspects.hpp). The convex solids' aspects are derived by hand below
// (a face is seen iff the view direction is within max_angle of its normal); the non-convex ones
// are checked against visibility regions derived by hand (a blind hole's floor is seen through a
// pyramid of directions, its walls over half a cap) and against the outer box of the seed's block.
#include "spar/sensing/aspects.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>

#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/mesh.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::sensing {
namespace {

using geometry::ObjectModel;
using FaceSet = std::vector<int>;

constexpr double kPi = std::numbers::pi;
double degrees(double value) { return value * kPi / 180; }

AspectOptions at_angle(double max_angle) {
  AspectOptions options;
  options.max_angle = max_angle;
  return options;
}

std::set<FaceSet> face_sets(const AspectSet& aspects) {
  std::set<FaceSet> out;
  for (const Aspect& aspect : aspects.aspects) out.insert(aspect.faces);
  return out;
}

double total_solid_angle(const AspectSet& aspects) {
  double total = 0;
  for (const Aspect& aspect : aspects.aspects) total += aspect.solid_angle;
  return total;
}

// The face ids of `model` whose normal is `normal`.
int face_with_normal(const ObjectModel& model, const Eigen::Vector3d& normal) {
  for (const geometry::Face& face : model.faces())
    if (face.normal.isApprox(normal.normalized(), 1e-9)) return face.id;
  ADD_FAILURE() << "no face with normal " << normal.transpose();
  return 0;
}

FaceSet sorted(FaceSet faces) {
  std::sort(faces.begin(), faces.end());
  return faces;
}

// The solid angle of the cells of `aspects` seeing face `face`.
double region_of(const AspectSet& aspects, int face) {
  double total = 0;
  for (const Aspect& aspect : aspects.aspects)
    if (std::find(aspect.faces.begin(), aspect.faces.end(), face) != aspect.faces.end())
      total += aspect.solid_angle;
  return total;
}

// Uniform directions (fixed seed) classified by the faces they see, against the aspects' solid
// angles: each within 4 standard deviations of the sampled fraction.
void expect_solid_angles_match_sampling(const ObjectModel& model, const AspectSet& aspects,
                                        double max_angle) {
  std::mt19937_64 random(20261123);
  std::normal_distribution<double> normal;
  const int samples = 100000;
  std::map<FaceSet, int> counts;
  for (int i = 0; i < samples; ++i) {
    const Eigen::Vector3d d =
        Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
    FaceSet seen;
    for (const geometry::Face& face : model.faces())
      if (d.dot(face.normal) > std::cos(max_angle)) seen.push_back(face.id);
    ++counts[seen];
  }
  for (const Aspect& aspect : aspects.aspects) {
    const double p = aspect.solid_angle / (4 * kPi);
    const double sigma = std::sqrt(p * (1 - p) / samples);
    EXPECT_NEAR(counts[aspect.faces] / static_cast<double>(samples), p, 4 * sigma + 1e-9)
        << aspect.label;
  }
}

// ---- convex solids, derived by hand ----

// Cube at 75°: cos 75° = 0.259. A direction sees +x iff d_x > 0.259, never both of an opposite
// pair; it always sees some face (3 · 0.259² < 1). Any one face (6), two adjacent faces (12: the
// bisector is 45° from each) and three faces at a corner (8: the corner direction is 54.7° from
// each) are all possible: 26 aspects.
TEST(Aspects, CubeAt75DegreesHas26) {
  const ObjectModel cube("cube", geometry::make_box({1, 1, 1}));
  const AspectSet aspects = compute_aspects(cube);
  EXPECT_EQ(aspects.method, AspectMethod::kExactArrangement);
  std::set<FaceSet> expected;
  const std::array<Eigen::Vector3d, 3> axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                               Eigen::Vector3d::UnitZ()};
  for (int a = 0; a < 3; ++a)
    for (const double sa : {-1.0, 1.0}) {
      const int fa = face_with_normal(cube, sa * axes[a]);
      expected.insert({fa});
      for (int b = a + 1; b < 3; ++b)
        for (const double sb : {-1.0, 1.0}) {
          const int fb = face_with_normal(cube, sb * axes[b]);
          expected.insert(sorted({fa, fb}));
          for (int c = b + 1; c < 3; ++c)
            for (const double sc : {-1.0, 1.0})
              expected.insert(sorted({fa, fb, face_with_normal(cube, sc * axes[c])}));
        }
    }
  ASSERT_EQ(expected.size(), 26U);
  EXPECT_EQ(face_sets(aspects), expected);
  EXPECT_NEAR(total_solid_angle(aspects), 4 * kPi, 1e-9);
  expect_solid_angles_match_sampling(cube, aspects, degrees(75));
}

// At 90° a single face or a pair is seen only from directions of measure zero: eight corners.
TEST(Aspects, CubeAt90DegreesHasOnlyItsCorners) {
  const ObjectModel cube("cube", geometry::make_box({1, 1, 1}));
  const AspectSet aspects = compute_aspects(cube, at_angle(kPi / 2));
  ASSERT_EQ(aspects.aspects.size(), 8U);
  for (const Aspect& aspect : aspects.aspects) {
    EXPECT_EQ(aspect.faces.size(), 3U);
    EXPECT_NEAR(aspect.solid_angle, kPi / 2, 1e-9);  // an octant
  }
}

// Triangular prism (equilateral section, sides s1 s2 s3 with normals 120° apart, top, bottom) at
// 75°: singles 5; top or bottom with one side (6); two sides (3: their bisector is 60° from each);
// never three sides (the horizontal parts of the three dot products sum to zero); top or bottom
// with two sides (6: e.g. horizontal 0.9 along the bisector, vertical 0.436); never nothing.
// 5 + 6 + 3 + 6 = 20.
TEST(Aspects, TriangularPrismAt75DegreesHas20) {
  const ObjectModel prism("prism", geometry::make_prism(geometry::regular_polygon(1.0, 3), 2.0));
  const AspectSet aspects = compute_aspects(prism);
  const int top = face_with_normal(prism, {0, 0, 1}), bottom = face_with_normal(prism, {0, 0, -1});
  std::vector<int> sides;
  for (const geometry::Face& face : prism.faces())
    if (face.id != top && face.id != bottom) sides.push_back(face.id);
  ASSERT_EQ(sides.size(), 3U);
  std::set<FaceSet> expected = {{top}, {bottom}};
  for (std::size_t i = 0; i < 3; ++i) {
    expected.insert({sides[i]});
    for (const int cap : {top, bottom}) expected.insert(sorted({cap, sides[i]}));
    for (std::size_t j = i + 1; j < 3; ++j) {
      expected.insert(sorted({sides[i], sides[j]}));
      for (const int cap : {top, bottom}) expected.insert(sorted({cap, sides[i], sides[j]}));
    }
  }
  ASSERT_EQ(expected.size(), 20U);
  EXPECT_EQ(face_sets(aspects), expected);
  EXPECT_NEAR(total_solid_angle(aspects), 4 * kPi, 1e-9);
  expect_solid_angles_match_sampling(prism, aspects, degrees(75));
}

// Regular tetrahedron: normals 109.47° apart. At 75°: one face (4), two (6: their mid-direction
// is 54.7° from each), three around a vertex (4: the vertex direction is 70.53° from each of its
// three faces, inside 75°), never four (the normals sum to zero): 14. At 70° the three-face cells
// vanish and directions near the vertices see nothing: 4 + 6 + the empty aspect = 11.
TEST(Aspects, TetrahedronAt75DegreesHas14And70DegreesHas11) {
  const ObjectModel tetrahedron(
      "tetrahedron",
      geometry::make_convex_hull({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}));
  const AspectSet at75 = compute_aspects(tetrahedron);
  std::set<FaceSet> expected;
  for (int a = 1; a <= 4; ++a) {
    expected.insert({a});
    for (int b = a + 1; b <= 4; ++b) {
      expected.insert({a, b});
      for (int c = b + 1; c <= 4; ++c) expected.insert({a, b, c});
    }
  }
  ASSERT_EQ(expected.size(), 14U);
  EXPECT_EQ(face_sets(at75), expected);
  expect_solid_angles_match_sampling(tetrahedron, at75, degrees(75));

  const AspectSet at70 = compute_aspects(tetrahedron, at_angle(degrees(70)));
  std::set<FaceSet> expected70 = {{}};
  for (const FaceSet& faces : expected)
    if (faces.size() < 3) expected70.insert(faces);
  EXPECT_EQ(face_sets(at70), expected70);
  EXPECT_NEAR(total_solid_angle(at70), 4 * kPi, 1e-9);
}

// ---- lookups and representatives ----

TEST(Aspects, LookupAgreesWithTheDefinitionAndRepresentativesSeeTheirAspect) {
  const ObjectModel prism("prism", geometry::make_prism(geometry::regular_polygon(1.0, 3), 2.0));
  const AspectSet aspects = compute_aspects(prism);
  for (const Aspect& aspect : aspects.aspects) {
    EXPECT_EQ(faces_seen(prism, aspect.direction), aspect.faces) << aspect.label;
    EXPECT_NEAR(aspect.direction.norm(), 1.0, 1e-12);
  }
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d d(normal(random), normal(random), normal(random));
    const int index = aspects.aspect_at(d);
    ASSERT_GE(index, 0);
    EXPECT_EQ(aspects.aspects[static_cast<std::size_t>(index)].faces, faces_seen(prism, d));
  }
}

// The view sphere finds the cube's 26 aspects too, with solid angles near the exact ones.
TEST(Aspects, ViewSphereAgreesWithTheExactArrangementOnTheCube) {
  const ObjectModel cube("cube", geometry::make_box({1, 1, 1}));
  const AspectSet exact = compute_aspects(cube);
  AspectOptions options;
  options.view_sphere_level = 4;
  options.force_view_sphere = true;
  const AspectSet sphere = compute_aspects(cube, options);
  EXPECT_EQ(sphere.method, AspectMethod::kViewSphere);
  EXPECT_EQ(sphere.cells.size(), 5120U);
  ASSERT_EQ(face_sets(sphere), face_sets(exact));
  for (std::size_t i = 0; i < exact.aspects.size(); ++i)
    EXPECT_NEAR(sphere.aspects[i].solid_angle, exact.aspects[i].solid_angle,
                0.12 * exact.aspects[i].solid_angle)
        << exact.aspects[i].label;
  EXPECT_NEAR(total_solid_angle(sphere), 4 * kPi, 1e-9);
}

// ---- non-convex objects ----

// A 3 x 3 x 3 cup with a blind 1.6 x 1.6 hole 2 deep. Its floor is seen through the opening iff
// |d_x| < 0.8 d_z and |d_y| < 0.8 d_z: a rectangular pyramid of 4 asin(a b / sqrt((1 + a²)(1 +
// b²))) = 1.604 sr for a = b = 0.8 (its corners are 48.5° from +z, inside 75°). A wall is seen (a
// sliver below the rim) from every direction rising out of the hole within 75° of its normal: half
// of a 75° cap, π (1 - cos 75°) = 2.328 sr. Outer faces are never occluded: full caps, 4.657 sr.
TEST(Aspects, BlindHoleRegionsMatchTheirPyramidAndHalfCaps) {
  geometry::RectilinearSolid solid({0, 0.7, 2.3, 3}, {0, 0.7, 2.3, 3}, {0, 1, 3});
  solid.set_filled(1, 1, 1, false);
  const ObjectModel cup("cup", solid.to_mesh());
  const AspectSet aspects = compute_aspects(cup);
  EXPECT_EQ(aspects.method, AspectMethod::kViewSphere);
  EXPECT_NEAR(total_solid_angle(aspects), 4 * kPi, 1e-9);
  int floor = 0, wall = 0, outer = 0;
  for (const geometry::Face& face : cup.faces()) {
    if (face.normal.z() > 0.5 && std::abs(face.offset - 1) < 1e-9) floor = face.id;
    if (face.normal.x() < -0.5 && std::abs(face.offset + 2.3) < 1e-9) wall = face.id;
    if (face.normal.x() > 0.5 && std::abs(face.offset - 3) < 1e-9) outer = face.id;
  }
  ASSERT_TRUE(floor && wall && outer);
  const double cap = 2 * kPi * (1 - std::cos(degrees(75)));
  EXPECT_NEAR(region_of(aspects, floor), 4 * std::asin(0.64 / 1.64), 0.05 * 1.604);
  EXPECT_NEAR(region_of(aspects, wall), cap / 2, 0.05 * cap / 2);
  EXPECT_NEAR(region_of(aspects, outer), cap, 0.03 * cap);
  // The floor is only seen from above.
  for (const ViewCell& cell : aspects.cells) {
    const FaceSet& faces = aspects.aspects[static_cast<std::size_t>(cell.aspect)].faces;
    if (std::find(faces.begin(), faces.end(), floor) != faces.end()) {
      EXPECT_GT(cell.direction.z(), 0.6);
    }
  }
}

// The seed's block: its outer box shows the cube's 26 combinations of outer faces; each outer
// face is seen over its full 75° cap; every aspect's representative direction sees the aspect.
TEST(Aspects, SeedBlockOuterFacesFormTheBoxAspects) {
  const ObjectModel block = geometry::make_builtin_object("block");
  const AspectSet aspects = compute_aspects(block);
  EXPECT_EQ(aspects.method, AspectMethod::kViewSphere);
  EXPECT_NEAR(total_solid_angle(aspects), 4 * kPi, 1e-9);
  const std::set<int> outer = {1, 5, 9, 11, 13, 19};  // left, right, front, back, bottom, top
  std::set<FaceSet> outer_sets;
  for (const Aspect& aspect : aspects.aspects) {
    FaceSet faces;
    for (const int face : aspect.faces)
      if (outer.contains(face)) faces.push_back(face);
    outer_sets.insert(faces);
  }
  EXPECT_EQ(outer_sets.size(), 26U);
  const double cap = 2 * kPi * (1 - std::cos(degrees(75)));
  for (const int face : outer) EXPECT_NEAR(region_of(aspects, face), cap, 0.03 * cap) << face;
  for (const Aspect& aspect : aspects.aspects)
    EXPECT_EQ(faces_seen(block, aspect.direction), aspect.faces) << aspect.label;
  // Inside faces are seen only through the holes' openings (top, front, back).
  for (const ViewCell& cell : aspects.cells) {
    const FaceSet& faces = aspects.aspects[static_cast<std::size_t>(cell.aspect)].faces;
    if (std::find(faces.begin(), faces.end(), 16) != faces.end()) {  // the peg hole's floor
      EXPECT_GT(cell.direction.z(), std::cos(degrees(75)));
    }
  }
}

// A cube's faces each fill at least a tenth of its image from any aspect's direction; an edge is
// as prominent as its contrast once it is a tenth of the cube's diameter (1.73) long, less when
// shorter (an edge of a face seen almost edge-on).
TEST(Aspects, ProminenceOfTheCubesFeatures) {
  const ObjectModel cube("cube", geometry::make_box({1, 1, 1}));
  const ObjectFeatures features = object_features(cube);
  const AspectSet aspects = compute_aspects(cube);
  for (const Aspect& aspect : aspects.aspects) {
    const AspectFeatures seen = aspect_features(cube, features, aspect);
    ASSERT_EQ(seen.faces.size(), aspect.faces.size());
    for (const FaceProminence& face : seen.faces) EXPECT_EQ(face.prominence, 1.0) << aspect.label;
    for (const EdgeProminence& edge : seen.edges) {
      EXPECT_GE(edge.prominence, 0.0);
      EXPECT_LE(edge.prominence, edge.contrast + 1e-15);
      if (edge.visible_length >= 0.173) {
        EXPECT_NEAR(edge.prominence, edge.contrast, 1e-12);
      }
    }
  }
  // Face-on: the face's four edges are its silhouette, all fully prominent.
  const Aspect& single = aspects.aspects[static_cast<std::size_t>(aspects.aspect_at({1, 0, 0}))];
  const AspectFeatures seen = aspect_features(cube, features, single);
  ASSERT_EQ(seen.edges.size(), 4U);
  for (const EdgeProminence& edge : seen.edges) EXPECT_EQ(edge.prominence, 1.0);
}

// On the seed's block seen from above, the peg hole's floor is a large face and the cross hole's
// floors, seen only as slivers, are hardly prominent.
TEST(Aspects, SliversAreNotProminent) {
  const ObjectModel block = geometry::make_builtin_object("block");
  const ObjectFeatures features = object_features(block);
  Aspect above;
  above.faces = {16, 19};
  above.direction = Eigen::Vector3d::UnitZ();
  const AspectFeatures seen = aspect_features(block, features, above);
  ASSERT_EQ(seen.faces.size(), 2U);
  EXPECT_EQ(seen.faces[0].prominence, 1.0);  // the floor: 2.56 of 10.5 in² of image
  EXPECT_EQ(seen.faces[1].prominence, 1.0);
}

TEST(Aspects, BadOptionsSayWhich) {
  const ObjectModel cube("cube", geometry::make_box({1, 1, 1}));
  EXPECT_THROW_MESSAGE(compute_aspects(cube, at_angle(degrees(95))),
                       "max_angle must be in (0, 90] degrees, got 95");
  AspectOptions level;
  level.view_sphere_level = 9;
  EXPECT_THROW_MESSAGE(compute_aspects(cube, level), "view_sphere_level must be 0 to 6, got 9");
  AspectOptions resolution;
  resolution.resolution = 4;
  EXPECT_THROW_MESSAGE(compute_aspects(cube, resolution),
                       "resolution must be 16 to 1024 samples, got 4");
}

}  // namespace
}  // namespace spar::sensing
