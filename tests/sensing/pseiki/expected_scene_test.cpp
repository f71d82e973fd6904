// The model panel (sensing/pseiki/expected_scene.hpp): its five levels for a box seen from a
// corner, the ids `spar vision render` prints, and tolerances worked out by hand for a camera
// looking straight down (a pose offset of dx moves every edge by f dx / z pixels).
#include "spar/sensing/pseiki/expected_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "spar/sensing/error.hpp"
#include "spar/sensing/pseiki/splitter.hpp"
#include "spar/sensing/render.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/sensing/pseiki/scenes.hpp"

namespace spar::sensing::pseiki {
namespace {

using testing::at;
using testing::TestScene;

// A box seen from a corner above shows three faces and nine edges.
TEST(ExpectedScene, ABoxFromACornerHasThreeFacesNineEdgesSevenVertices) {
  TestScene test(Camera(Projection::kPinhole,
                        {.fx = 800, .fy = 800, .cx = 320, .cy = 240, .width = 640, .height = 480},
                        look_at({1, -1, 1}, {0, 0, 0.05}, {0, 0, 1})));
  test.add("box", {0.2, 0.2, 0.1}, at(0, 0), {});
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  EXPECT_EQ(panel.faces().size(), 3U);
  EXPECT_EQ(panel.edges().size(), 9U);
  EXPECT_EQ(panel.vertices().size(), 7U);
  ASSERT_EQ(panel.objects().size(), 1U);
  EXPECT_EQ(panel.objects()[0].edges.size(), 9U);
  std::set<std::string> ids;
  for (const PanelEdge& edge : panel.edges()) {
    EXPECT_EQ(edge.id.rfind("box/e", 0), 0U) << edge.id;
    EXPECT_TRUE(ids.insert(edge.id).second);
    EXPECT_EQ(panel.edge_index(edge.id), &edge - panel.edges().data());
    EXPECT_EQ(edge.pieces.size(), 1U);
    // Three edges of the silhouette's six bound one visible face, the three inner ones two.
    EXPECT_EQ(edge.faces.size(), edge.silhouette ? 1U : 2U) << edge.id;
  }
  for (const PanelFace& face : panel.faces()) {
    EXPECT_EQ(face.edges.size(), 4U);
    EXPECT_GT(face.area_px, 100);
    EXPECT_GT(internal::area(face.region), 0.9 * face.area_px);
    EXPECT_LT(internal::area(face.region), 1.1 * face.area_px);
  }
  EXPECT_EQ(panel.edge_index("box/e99"), -1);
}

// Straight down from 1 m with f = 800: a 5 mm error in x moves every edge 4 px; with no
// uncertainty only the noise (3 sigma) and half a pixel remain.
TEST(ExpectedScene, TolerancesAreWhatTheUncertaintyDoesInPixels) {
  TestScene test(testing::straight_down_camera());
  test.add("slab", {0.3, 0.2, 0.1}, at(0, 0), {.dx = 0.005});
  test.uncertainty.noise_px = 0.5;
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  ASSERT_EQ(panel.edges().size(), 4U);  // the top face's outline
  for (const PanelEdge& edge : panel.edges()) {
    const bool across_x = std::abs(edge.span.direction().x()) < 0.5;  // moved across by dx
    EXPECT_NEAR(edge.tolerance.offset, (across_x ? 4.0 : 0.0) + 1.5 + kMinimumOffsetPx, 1e-6)
        << edge.id;
    EXPECT_NEAR(edge.tolerance.angle, 0, 1e-9);
  }
  // The relation between two edges of the face does not change under a translation.
  const int a = 0, b = panel.neighbours(0).front();
  EXPECT_NEAR(panel.relational(a, b).offset, 1.5 + kMinimumOffsetPx, 1e-6);
  test.uncertainty.objects[0] = {};
  const ModelPanel exact(test.scene, test.camera, test.uncertainty);
  for (const PanelEdge& edge : exact.edges())
    EXPECT_NEAR(edge.tolerance.offset, 1.5 + kMinimumOffsetPx, 1e-9);
}

// The longest an edge's image can be: its length where the uncertainty brings it nearest the camera
// (dz up, the top face's outline seen from straight above: f L / (z_camera - z_top - dz)), plus
// two noisy ends (3 sqrt(2) sigma); exact poses keep the length itself.
TEST(ExpectedScene, TheLongestAnEdgeCanBeIsItsLengthNearestTheCamera) {
  TestScene test(testing::straight_down_camera());
  test.add("slab", {0.3, 0.2, 0.1}, at(0, 0), {.dz = 0.01});
  test.uncertainty.noise_px = 0.5;
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  test.uncertainty.objects[0] = {};
  const ModelPanel exact(test.scene, test.camera, test.uncertainty);
  const double slack = 3 * std::sqrt(2.0) * 0.5;
  ASSERT_EQ(panel.edges().size(), 4U);
  for (std::size_t e = 0; e < panel.edges().size(); ++e) {
    const double seen = exact.edges()[e].span.length();
    EXPECT_NEAR(exact.edges()[e].longest_px, seen + slack, 1e-9);
    const double metres = std::abs(panel.edges()[e].span.direction().x()) > 0.5 ? 0.3 : 0.2;
    const double depth = 800 * metres / seen;  // from the camera to the top face
    EXPECT_NEAR(panel.edges()[e].longest_px, 800 * metres / (depth - 0.01) + slack, 1e-6)
        << panel.edges()[e].id;
  }
}

// A tall box in front of a long low one hides the middle of its far top edge: one edge, two
// pieces, its overlap measured on the pieces.
TEST(ExpectedScene, AnEdgeHiddenInItsMiddleHasTwoPieces) {
  TestScene test(Camera(Projection::kPinhole,
                        {.fx = 800, .fy = 800, .cx = 320, .cy = 240, .width = 640, .height = 480},
                        look_at({0, -1.2, 0.35}, {0, 0, 0.05}, {0, 0, 1})));
  test.add("wall", {0.5, 0.05, 0.1}, at(0, 0.1), {});
  test.add("post", {0.06, 0.06, 0.3}, at(0, -0.2), {});
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  int split = 0;
  for (const PanelEdge& edge : panel.edges())
    if (edge.pieces.size() == 2) ++split;
  EXPECT_GE(split, 1);
}

// distinct_edges: an edge lying on a longer one (within kResolvePixels of its line, along it) is
// seen as that one; 2.5 px off, or with a piece past the other's end, it is an edge of its own; of
// two equal ones the first stays.
TEST(ExpectedScene, AnEdgeLyingOnALongerOneIsSeenAsIt) {
  const std::vector<std::vector<Segment>> edges = {
      {{{10, 1.0}, {40, 1.2}}},                          // 1.2 px from the next one's line
      {{{0, 0}, {100, 0}}},                              //
      {{{10, 2.5}, {40, 2.5}}},                          // 2.5 px off
      {{{50, -0.5}, {90, -0.5}}, {{120, 0}, {140, 0}}},  // its second piece is past the end
      {},                                                // no piece
      {{{0, 50}, {30, 50}}},                             //
      {{{0, 50.5}, {30, 50.5}}}};                        // as long as the one before
  EXPECT_EQ(distinct_edges(edges),
            (std::vector<bool>{false, true, true, true, false, true, false}));
}

// Two flat boxes side by side seen from above and to one side: where they touch, their top edges
// are one line in the image, and the side nearest the camera shows edges about a pixel long. The
// renderer has both; the panel holds one edge on that line and nothing under kMinimumPiece.
TEST(ExpectedScene, WhatAnEdgeDetectorCannotResolveIsNotInThePanel) {
  TestScene test(Camera(Projection::kPinhole,
                        {.fx = 800, .fy = 800, .cx = 320, .cy = 240, .width = 640, .height = 480},
                        look_at({0.3, 0, 1.5}, {0.05, 0, 0}, {0, 1, 0})));
  test.add("left", {0.1, 0.1, 0.02}, at(0, 0), {});
  test.add("right", {0.1, 0.1, 0.02}, at(0.1, 0), {});
  // Whether every piece of one edge lies on a piece of the other (both ends within
  // kResolvePixels of its line, along it).
  const auto on = [](const std::vector<Segment>& pieces, const std::vector<Segment>& others) {
    return std::all_of(pieces.begin(), pieces.end(), [&](const Segment& piece) {
      return std::any_of(others.begin(), others.end(), [&](const Segment& other) {
        const auto along = [&](const Eigen::Vector2d& p) {
          return (p - other.p0).dot(other.direction()) / other.length();
        };
        return other.line_distance(piece.p0) <= kResolvePixels &&
               other.line_distance(piece.p1) <= kResolvePixels && along(piece.p0) > -0.1 &&
               along(piece.p0) < 1.1 && along(piece.p1) > -0.1 && along(piece.p1) < 1.1;
      });
    });
  };
  const Rendering seen = render(test.scene, test.camera, {.faces = false, .edges = true});
  int short_pieces = 0;
  std::set<std::string> touching;  // panel ids of the edges of two objects on one line
  for (const EdgeView& a : seen.edges) {
    if ((a.u1 - a.u0).norm() < kMinimumPiece) ++short_pieces;
    for (const EdgeView& b : seen.edges)
      if (a.object != b.object && (a.u1 - a.u0).norm() >= kMinimumPiece &&
          on({{a.u0, a.u1}}, {{b.u0, b.u1}}))
        touching.insert(test.scene.objects()[static_cast<std::size_t>(a.object)].name + "/e" +
                        std::to_string(a.edge));
  }
  ASSERT_GT(short_pieces, 0);
  ASSERT_EQ(touching.size(), 2U);

  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  int touching_kept = 0;
  for (const PanelEdge& edge : panel.edges()) {
    touching_kept += static_cast<int>(touching.count(edge.id));
    for (const Segment& piece : edge.pieces) EXPECT_GE(piece.length(), kMinimumPiece) << edge.id;
    for (const PanelEdge& other : panel.edges())
      EXPECT_FALSE(&edge != &other && on(edge.pieces, other.pieces))
          << edge.id << " on " << other.id;
  }
  EXPECT_EQ(touching_kept, 1);
}

TEST(ExpectedScene, MistakesAreNamed) {
  testing::TestScene test = testing::two_boxes();
  test.uncertainty.objects.pop_back();
  EXPECT_THROW_MESSAGE(ModelPanel(test.scene, test.camera, test.uncertainty),
                       "1 object uncertainties for 2 objects");
  test = testing::two_boxes();
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  EXPECT_THROW_MESSAGE(panel.relational(0, 0), "share no visible face");
}

}  // namespace
}  // namespace spar::sensing::pseiki
