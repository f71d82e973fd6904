// Model edges, cameras and the scene renderer (sensing/model_features.hpp, camera.hpp,
// render.hpp) on scenes whose answers are worked out by hand: boxes seen along axes and diagonals,
// and a tall box hiding part of another (exact hidden-line pieces, visible area).
#include "spar/sensing/render.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/mesh.hpp"
#include "spar/sensing/camera.hpp"
#include "spar/sensing/internal/item_buffer.hpp"
#include "spar/sensing/model_features.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::sensing {
namespace {

// A buffer over the window its triangles cover (render()'s use, internal/item_buffer.hpp) holds
// exactly what the whole image's buffer holds there, in image coordinates, and nothing else; one
// triangle reaches past the image's left border (clamped alike).
TEST(ItemBuffer, TheWindowOfItsTrianglesHoldsWhatTheWholeImageHolds) {
  const std::array<std::array<Eigen::Vector2d, 3>, 3> triangles = {
      {{{{13.2, 4.1}, {40.7, 9.3}, {12.5, 37.9}}},
       {{{20.1, 2.2}, {55.3, 30.4}, {18.8, 25.6}}},
       {{{-5.0, 50.0}, {30.0, 61.0}, {45.0, 40.0}}}}};
  const std::array<std::array<double, 3>, 3> depths = {
      {{1.0, 2.0, 3.0}, {2.5, 0.5, 1.5}, {0.2, 0.4, 0.3}}};
  // Their box, floor and ceil, clamped to the 64 x 64 image: x 0..56, y 2..61.
  const internal::PixelWindow window{.x0 = 0, .y0 = 2, .width = 56, .height = 59};
  internal::ItemBuffer whole(64, 64);
  internal::ItemBuffer part(window);
  for (int t = 0; t < 3; ++t) {
    whole.draw(triangles[t], depths[t], t);
    part.draw(triangles[t], depths[t], t);
  }
  int covered = 0, covered_whole = 0;
  for (int y = window.y0; y < window.y0 + window.height; ++y)
    for (int x = window.x0; x < window.x0 + window.width; ++x) {
      EXPECT_EQ(part.item(x, y), whole.item(x, y)) << x << ", " << y;
      EXPECT_EQ(part.depth(x, y), whole.depth(x, y)) << x << ", " << y;
      covered += part.item(x, y) >= 0;
    }
  for (const int item : whole.items()) covered_whole += item >= 0;
  EXPECT_GT(covered, 500);
  EXPECT_EQ(covered, covered_whole);  // the window holds every drawn sample
  EXPECT_EQ(part.items().size(), 56U * 59U);
}

using geometry::make_box;
using geometry::ObjectModel;

Eigen::Isometry3d at(double x, double y, double z) {
  return Eigen::Isometry3d(Eigen::Translation3d(x, y, z));
}

// A box model with its features, kept together for a scene.
struct Part {
  ObjectModel model;
  ObjectFeatures features;
  explicit Part(const Eigen::Vector3d& size)
      : model("box", make_box(size)), features(object_features(model)) {}
};

std::vector<int> visible_faces(const Rendering& seen, int object = 0) {
  std::vector<int> ids;
  for (const FaceView& face : seen.faces)
    if (face.object == object) ids.push_back(face.face);
  return ids;
}

int face_along(const ObjectModel& model, const Eigen::Vector3d& normal) {
  for (const geometry::Face& face : model.faces())
    if (face.normal.isApprox(normal, 1e-12)) return face.id;
  return 0;
}

TEST(ModelFeatures, CubeHasTwelveRidgesFourPerFace) {
  const ObjectModel cube("cube", make_box({1, 1, 1}));
  const ObjectFeatures features = object_features(cube);
  ASSERT_EQ(features.edges.size(), 12U);
  for (const ModelEdge& edge : features.edges) {
    EXPECT_LT(edge.face_a, edge.face_b);
    EXPECT_NEAR(edge.dihedral, std::numbers::pi / 2, 1e-12);
    EXPECT_TRUE(edge.convex);
    EXPECT_NEAR(edge.length(), 1.0, 1e-12);
  }
  for (const std::vector<int>& ids : features.face_edges) EXPECT_EQ(ids.size(), 4U);
  for (std::size_t i = 0; i < features.edges.size(); ++i)
    EXPECT_EQ(features.edges[i].id, static_cast<int>(i) + 1);
}

// The block's top face meets the walls of the peg hole in valleys; the outer box edges are ridges.
TEST(ModelFeatures, BlockHoleEdgesAreValleys) {
  const ObjectModel block = geometry::make_builtin_object("block");
  const ObjectFeatures features = object_features(block);
  int valleys = 0, ridges = 0;
  for (const ModelEdge& edge : features.edges) (edge.convex ? ridges : valleys) += 1;
  EXPECT_GT(valleys, 0);
  EXPECT_GE(ridges, 12);
  // Every edge's endpoints lie on both of its faces' planes.
  for (const ModelEdge& edge : features.edges)
    for (const int id : {edge.face_a, edge.face_b}) {
      const geometry::Face& face = block.face(id);
      EXPECT_NEAR(face.normal.dot(edge.p0), face.offset, 1e-12);
      EXPECT_NEAR(face.normal.dot(edge.p1), face.offset, 1e-12);
    }
}

TEST(Camera, PinholeProjectsAsTheHeaderSays) {
  const Camera top(Projection::kPinhole,
                   {.fx = 500, .fy = 500, .cx = 320, .cy = 240, .width = 640, .height = 480},
                   look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}));
  const auto uv = top.project({0.1, 0, 0});
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 370, 1e-9);
  EXPECT_NEAR(uv->y(), 240, 1e-9);
  EXPECT_FALSE(top.project({0, 0, 2}).has_value());  // behind the camera
  EXPECT_TRUE(top.toward_viewer({0, 0, 0}).isApprox(Eigen::Vector3d(0, 0, 1)));
}

TEST(Camera, BadIntrinsicsSayWhich) {
  EXPECT_THROW_MESSAGE(
      Camera(Projection::kPinhole, {.fx = 0, .fy = 1, .cx = 0, .cy = 0, .width = 1, .height = 1},
             Eigen::Isometry3d::Identity()),
      "fx must be a positive number, got 0");
  EXPECT_THROW_MESSAGE(
      Camera(Projection::kPinhole, {.fx = 1, .fy = 1, .cx = 0, .cy = 0, .width = 0, .height = 1},
             Eigen::Isometry3d::Identity()),
      "width must be 1 to 16384 pixels, got 0");
}

// Seen straight down, a unit cube shows its top face (area 1) bounded by four silhouette edges.
TEST(Render, CubeFromAboveShowsItsTopFace) {
  const Part cube({1, 1, 1});
  Scene scene;
  scene.add("cube", cube.model, cube.features, Eigen::Isometry3d::Identity());
  const Camera camera = Camera::orthographic_view({0, 0, 1}, {0.5, 0.5, 0.5}, 1.0, 200);
  const Rendering seen = render(scene, camera);
  const int top = face_along(cube.model, {0, 0, 1});
  ASSERT_EQ(visible_faces(seen), std::vector<int>{top});
  EXPECT_NEAR(seen.faces[0].visible_area, 1.0, 0.02);
  EXPECT_NEAR(seen.faces[0].angle, 0.0, 1e-12);
  EXPECT_TRUE(seen.faces[0].centroid.isApprox(Eigen::Vector3d(0.5, 0.5, 1.0), 1e-2));
  ASSERT_EQ(seen.edges.size(), 4U);
  for (const EdgeView& edge : seen.edges) {
    EXPECT_TRUE(edge.silhouette);
    EXPECT_NEAR((edge.p1 - edge.p0).norm(), 1.0, 1e-12);
    EXPECT_NEAR((edge.u1 - edge.u0).norm(), 100.0, 1e-9);  // 200 pixels per 2 m
  }
}

// From the (1, 1, 1) diagonal: three faces, three crease edges at the near corner and six
// silhouette edges; the three faces look alike, so the creases have zero contrast.
TEST(Render, CubeFromTheDiagonalShowsThreeFacesNineEdges) {
  const Part cube({1, 1, 1});
  Scene scene;
  scene.add("cube", cube.model, cube.features, Eigen::Isometry3d::Identity());
  const Camera camera =
      Camera::orthographic_view(Eigen::Vector3d(1, 1, 1).normalized(), {0.5, 0.5, 0.5}, 1.0, 300);
  const Rendering seen = render(scene, camera);
  EXPECT_EQ(visible_faces(seen).size(), 3U);
  for (const FaceView& face : seen.faces) {
    EXPECT_NEAR(face.visible_area, 1.0, 0.03);
    EXPECT_NEAR(face.angle, std::acos(1 / std::sqrt(3.0)), 1e-12);
  }
  ASSERT_EQ(seen.edges.size(), 9U);
  const auto silhouettes = std::count_if(seen.edges.begin(), seen.edges.end(),
                                         [](const EdgeView& e) { return e.silhouette; });
  EXPECT_EQ(silhouettes, 6);
  for (const EdgeView& edge : seen.edges) {
    if (!edge.silhouette) {
      EXPECT_NEAR(edge.contrast, 0.0, 1e-12);
    }
  }
}

// Back box B = [0,4]x[2,3]x[0,2]; a taller front box S = [1,2]x[0,1]x[0,3] between it and a
// camera looking along +y. B's front top edge (y = 2, z = 2) is hidden exactly for x in [1, 2]:
// two pieces, [0, 1] and [2, 4]. B's front face (8 m²) loses 2 m² behind S.
TEST(Render, FrontBoxHidesExactlyItsShadowOfTheBackEdge) {
  const Part back({4, 1, 2}), front({1, 1, 3});
  Scene scene;
  scene.add("back", back.model, back.features, at(0, 2, 0));
  scene.add("front", front.model, front.features, at(1, 0, 0));
  const Camera camera = Camera::orthographic_view({0, -1, 0}, {2, 1.5, 1.5}, 4.0, 400);
  const Rendering seen = render(scene, camera);
  std::vector<std::pair<double, double>> pieces;
  for (const EdgeView& edge : seen.edges)
    if (edge.object == 0 && std::abs(edge.p0.y() - 2) < 1e-12 &&
        std::abs(edge.p1.y() - 2) < 1e-12 && std::abs(edge.p0.z() - 2) < 1e-12 &&
        std::abs(edge.p1.z() - 2) < 1e-12)
      pieces.emplace_back(std::min(edge.p0.x(), edge.p1.x()), std::max(edge.p0.x(), edge.p1.x()));
  std::sort(pieces.begin(), pieces.end());
  ASSERT_EQ(pieces.size(), 2U);
  EXPECT_NEAR(pieces[0].first, 0, 1e-9);
  EXPECT_NEAR(pieces[0].second, 1, 1e-9);
  EXPECT_NEAR(pieces[1].first, 2, 1e-9);
  EXPECT_NEAR(pieces[1].second, 4, 1e-9);
  const int back_front_face = face_along(back.model, {0, -1, 0});
  for (const FaceView& face : seen.faces)
    if (face.object == 0 && face.face == back_front_face) {
      EXPECT_NEAR(face.visible_area, 6.0, 0.1);
      EXPECT_NEAR(face.visible_fraction, 0.75, 0.0125);
    }
}

// A pinhole camera 2 m above a unit cube: the top face's four edges project to the square of side
// f * 1 / (2 - 1) = 100 pixels around the principal point; every side face is turned away from an
// eye above the cube's middle.
TEST(Render, PinholeAboveACubeSeesTheTopSquare) {
  const Part cube({1, 1, 1});
  Scene scene;
  scene.add("cube", cube.model, cube.features, at(-0.5, -0.5, 0));
  const Camera camera(Projection::kPinhole,
                      {.fx = 100, .fy = 100, .cx = 160, .cy = 120, .width = 320, .height = 240},
                      look_at({0, 0, 2}, {0, 0, 0}, {0, 1, 0}));
  const Rendering seen = render(scene, camera);
  ASSERT_EQ(visible_faces(seen).size(), 1U);
  EXPECT_NEAR(seen.faces[0].visible_area, 1.0, 0.05);
  ASSERT_EQ(seen.edges.size(), 4U);
  for (const EdgeView& edge : seen.edges) {
    EXPECT_NEAR((edge.u1 - edge.u0).norm(), 100.0, 1e-9);
    for (const Eigen::Vector2d& uv : {edge.u0, edge.u1}) {
      EXPECT_NEAR(std::abs(uv.x() - 160), 50.0, 1e-9);
      EXPECT_NEAR(std::abs(uv.y() - 120), 50.0, 1e-9);
    }
  }
}

// An edge leaving the image is cut at the image border.
TEST(Render, EdgesAreClippedToTheImage) {
  const Part slab({10, 1, 1});
  Scene scene;
  scene.add("slab", slab.model, slab.features, at(-5, -0.5, 0));
  const Camera camera(Projection::kPinhole,
                      {.fx = 100, .fy = 100, .cx = 160, .cy = 120, .width = 320, .height = 240},
                      look_at({0, 0, 2}, {0, 0, 0}, {0, 1, 0}));
  const Rendering seen = render(scene, camera);
  for (const EdgeView& edge : seen.edges)
    for (const Eigen::Vector2d& uv : {edge.u0, edge.u1}) {
      EXPECT_GE(uv.x(), -1e-9);
      EXPECT_LE(uv.x(), 320 + 1e-9);
    }
  EXPECT_FALSE(seen.edges.empty());
}

}  // namespace
}  // namespace spar::sensing
