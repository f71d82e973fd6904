// planner/vision.hpp's vision_check: what PSEIKI must see at a verification step is what the
// camera sees of the object with the other objects and the gripper in the scene (issue 27:
// hidden-line removal between objects applies to the verification's edge list).
#include "spar/planner/vision.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/planner/scenario.hpp"
#include "spar/sensing/camera.hpp"
#include "spar/sensing/pseiki/matcher.hpp"
#include "spar/sensing/pseiki/simulate.hpp"
#include "spar/sensing/pseiki/splitter.hpp"
#include "tests/planner/plan_options.hpp"
#include "tests/sensing/pseiki/label_score.hpp"

namespace spar::planner {
namespace {

// Two 1 in cubes: `part` at (20, 0), `front` between it and a camera 10 in away on -y that looks
// along +y, shifted half a cube sideways so that it hides about half of the part.
Scenario two_cubes() {
  return parse_scenario(
      "units: {length: in, angle: deg}\n"
      "objects:\n"
      "  part: {builtin: cube, pose: {stable: P1, at: [20, 0]}}\n"
      "  front: {builtin: cube, pose: {stable: P1, at: [20.5, -3]}}\n"
      "sensors:\n  cameras:\n"
      "    - {name: side, pose: {xyz: [20, -10, 0.5], rpy: [-90, 0, 0]},\n"
      "       intrinsics: {fx: 800, fy: 800, cx: 320, cy: 240, width: 640, height: 480}}\n",
      "test.yaml", ".");
}

// Whether `p` lies inside the convex hull of `points` by more than `margin` pixels.
bool deep_inside_hull(std::vector<Eigen::Vector2d> points, const Eigen::Vector2d& p,
                      double margin) {
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {  // Andrew's monotone chain, counter-clockwise
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    if (cross(a, b, p) / (b - a).norm() <= margin) return false;
  }
  return true;
}

// The image points of `object`'s mesh vertices as `camera` sees them.
std::vector<Eigen::Vector2d> projected(const Scenario& scenario, const std::string& object,
                                       const std::string& camera) {
  const ObjectSpec& spec = scenario.object(object);
  const CameraSensor& sensor = scenario.camera(camera);
  const sensing::Camera view(sensor.projection, sensor.intrinsics, sensor.pose);
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector3d& vertex : spec.model.mesh().vertices)
    out.push_back(*view.project(spec.initial_pose * vertex));
  return out;
}

// The midpoints of the drawn pieces of `object`'s edges.
std::vector<Eigen::Vector2d> midpoints(const VisionCheck& check, const std::string& object) {
  std::vector<Eigen::Vector2d> out;
  for (const VisionEdge& edge : check.drawing)
    if (edge.object == object)
      for (const sensing::pseiki::Segment& piece : edge.pieces) out.push_back(piece.midpoint());
  return out;
}

double visible_length(const VisionCheck& check, const std::string& object) {
  double length = 0;
  for (const VisionEdge& edge : check.drawing)
    if (edge.object == object)
      for (const sensing::pseiki::Segment& piece : edge.pieces) length += piece.length();
  return length;
}

TEST(VisionCheck, AnObjectInFrontHidesPartOfTheVerifiedOnesEdges) {
  const Scenario scenario = two_cubes();
  const int part = 0;
  const kinematics::Transform& pose = scenario.object("part").initial_pose;
  const std::optional<VisionCheck> alone = vision_check(scenario, part, pose);
  VisionOccluders front;
  front.objects = {{1, scenario.object("front").initial_pose}};
  const std::optional<VisionCheck> hidden = vision_check(scenario, part, pose, front);
  ASSERT_TRUE(alone && hidden);
  EXPECT_EQ(hidden->camera, "side");
  EXPECT_EQ(hidden->width, 640);
  // The front cube is drawn whole; the part loses what lies behind it, and nothing of what it
  // keeps is drawn inside the front cube's outline (which, alone, it was).
  EXPECT_FALSE(midpoints(*hidden, "front").empty());
  const std::vector<Eigen::Vector2d> outline = projected(scenario, "front", "side");
  const auto behind = [&](const VisionCheck& check) {
    int count = 0;
    for (const Eigen::Vector2d& p : midpoints(check, "part"))
      count += deep_inside_hull(outline, p, 1.0);
    return count;
  };
  EXPECT_GT(behind(*alone), 0);
  EXPECT_EQ(behind(*hidden), 0);
  EXPECT_LT(visible_length(*hidden, "part"), 0.8 * visible_length(*alone, "part"));
  // The edges to see are the part's visible ones: fewer, each also visible alone.
  EXPECT_LT(hidden->edges.size(), alone->edges.size());
  const std::set<std::string> seen_alone(alone->edges.begin(), alone->edges.end());
  for (const std::string& edge : hidden->edges) {
    EXPECT_TRUE(seen_alone.contains(edge)) << edge;
    EXPECT_EQ(edge.rfind("part/e", 0), 0u) << edge;
  }
}

// The gripper at the step's grasp is drawn as its three boxes: it hides what it covers, and what
// lies behind the part is hidden.
TEST(VisionCheck, TheGripperIsDrawnAndHidesWhatItCovers) {
  const Scenario scenario = two_cubes();
  const kinematics::Transform& pose = scenario.object("part").initial_pose;
  const geometry::GripperSpec gripper{};
  // Closed on the part across y, approaching from above (its z down): the -y finger stands
  // between the camera and the part, the palm above it.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& vertex : scenario.object("part").model.mesh().vertices)
    centre += pose * vertex / 8.0;
  VisionOccluders occluders;
  occluders.gripper = &gripper;
  occluders.gripper_pose =
      Eigen::Translation3d(centre) * Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());
  occluders.opening = 1.0 * units::kInch;
  const std::optional<VisionCheck> alone = vision_check(scenario, 0, pose);
  const std::optional<VisionCheck> held = vision_check(scenario, 0, pose, occluders);
  ASSERT_TRUE(alone && held);
  std::set<std::string> bodies;
  for (const VisionEdge& edge : held->drawing) bodies.insert(edge.object);
  // Gripper +y is world -y: that finger stands in front of the part, the other behind it, hidden.
  EXPECT_EQ(bodies, (std::set<std::string>{"gripper/finger+y", "gripper/palm", "part"}));
  EXPECT_LT(visible_length(*held, "part"), visible_length(*alone, "part"));
}

// Phase 2's camera verification (issue 27): a camera verifies an object only with a residual,
// only where it sees enough of it to correct its pose, and not through another object.
Scenario cube_behind(double front_x, const std::string& side_residual) {
  return parse_scenario(
      "units: {length: in, angle: deg}\n"
      "objects:\n"
      "  part: {builtin: cube, pose: {stable: P1, at: [20, 0]}}\n"
      "  front: {builtin: cube, pose: {stable: P1, at: [" +
          std::to_string(front_x) +
          ", -3]}}\n"
          "sensors:\n  cameras:\n"
          "    - {name: plain, pose: {xyz: [20, 0, 20], rpy: [180, 0, 0]},\n"
          "       intrinsics: {fx: 800, fy: 800, cx: 320, cy: 240, width: 640, height: 480}}\n"
          "    - {name: side, pose: {xyz: [20, -10, 0.5], rpy: [-90, 0, 0]},\n"
          "       intrinsics: {fx: 800, fy: 800, cx: 320, cy: 240, width: 640, height: 480}" +
          side_residual + "}\n",
      "test.yaml", ".");
}

TEST(VerifyingCameras, OnlyACameraWithAResidualThatSeesThePartVerifiesIt) {
  const std::string residual = ", residual: {dx: 0.02, dy: 0.1, dz: 0.02, dtheta: 1}";
  // The front cube 4 in aside: the side camera sees the part whole.
  const Scenario clear = cube_behind(24, residual);
  const kinematics::Transform& pose = clear.object("part").initial_pose;
  VisionOccluders front;
  front.objects = {{1, clear.object("front").initial_pose}};
  const std::vector<CameraVerification> seen = verifying_cameras(clear, 0, pose, front);
  ASSERT_EQ(seen.size(), 1U);  // `plain` sees the part from above, but has no residual
  EXPECT_EQ(seen[0].camera, 1);
  EXPECT_EQ(seen[0].check.camera, "side");
  EXPECT_GE(seen[0].check.edges.size(), 3U);
  EXPECT_TRUE(verifying_cameras(clear, 0, pose, front, /*camera=*/0).empty());
  EXPECT_EQ(verifying_cameras(clear, 0, pose, front, /*camera=*/1).size(), 1U);
  // Without a residual no camera verifies, though both see the part.
  EXPECT_TRUE(verifying_cameras(cube_behind(24, ""), 0, pose, front).empty());
  // The front cube right between the side camera and the part hides it.
  const Scenario hidden = cube_behind(20, residual);
  front.objects = {{1, hidden.object("front").initial_pose}};
  EXPECT_TRUE(verifying_cameras(hidden, 0, pose, front).empty());
  // Alone, the part is seen again.
  EXPECT_EQ(verifying_cameras(hidden, 0, pose, {}).size(), 1U);
}

// The sidewalk's two borders hold 58% of its visible edge length; the issue's simulated image
// drops each edge with probability 0.2, so both go together in 4% of images. Those images are
// still of the expected scene and are accepted (seeds found over 1..200: the normal
// approximation's coverage floor rejected them; grouper.hpp's exact floor does not).
TEST(SidewalkVerification, AnImageMissingBothBordersIsStillTheExpectedScene) {
  const Scenario sidewalk = load_scenario(kExamples / "vision" / "pseiki_sidewalk.yaml");
  const VisionSetup setup(sidewalk, "front");
  namespace pseiki = sensing::pseiki;
  for (const std::uint64_t seed : {55U, 125U, 147U, 176U, 187U}) {
    const pseiki::SimulatedImage image =
        pseiki::simulate(setup.scene(), setup.camera(), setup.uncertainty(),
                         pseiki::testing::kIssuePerturbation, seed);
    const auto seen = [&](const std::string& id) {
      return std::any_of(image.edges.begin(), image.edges.end(),
                         [&](const pseiki::SimulatedEdge& edge) { return edge.truth == id; });
    };
    ASSERT_FALSE(seen("walk/e1") || seen("walk/e7")) << "seed " << seed << " has a border";
    const pseiki::Verification result =
        pseiki::verify(setup.scene(), setup.camera(), setup.uncertainty(),
                       pseiki::testing::inputs_of(image), setup.options());
    EXPECT_TRUE(result.accepted) << "seed " << seed << ": scene belief "
                                 << result.board.scene.belief;
  }
}

// A shadow 3-6 px beside a piece of a walk border, running along it, under the border's pass-2
// tolerance: pieces of one edge do not run side by side, so the shadow is not believed (seeds
// found over 1..200; while labeler.hpp's duplicate measure faded out 3-6 px from the piece's line,
// these shadows kept a belief of 0.21 and 0.27 beside the believed border).
TEST(SidewalkVerification, AShadowBesideABorderIsNotBelieved) {
  const Scenario sidewalk = load_scenario(kExamples / "vision" / "pseiki_sidewalk.yaml");
  const VisionSetup setup(sidewalk, "front");
  namespace pseiki = sensing::pseiki;
  for (const std::uint64_t seed : {33U, 46U}) {
    const pseiki::SimulatedImage image =
        pseiki::simulate(setup.scene(), setup.camera(), setup.uncertainty(),
                         pseiki::testing::kIssuePerturbation, seed);
    const pseiki::Verification result =
        pseiki::verify(setup.scene(), setup.camera(), setup.uncertainty(),
                       pseiki::testing::inputs_of(image), setup.options());
    const pseiki::testing::LabelScore score = pseiki::testing::score(result, image);
    EXPECT_EQ(score.clutter_believed, 0) << "seed " << seed;
    EXPECT_GE(score.accuracy(), 0.9) << "seed " << seed;
    EXPECT_TRUE(result.accepted) << "seed " << seed;
  }
}

// The bench's model where the lamp should stand: the lamp is seen at coverage 0.15-0.35 (the
// bench's legs lie along the post's lines) and believed at most 0.13, yet while the scene's
// support weighed each object by its visible edge length the walk and the bench outvoted it and
// these seeds (found over 1..200) were accepted at 0.51-0.61. Each object is one vote now.
TEST(SidewalkVerification, ALampReplacedByABenchIsRejected) {
  const Scenario sidewalk = load_scenario(kExamples / "vision" / "pseiki_sidewalk.yaml");
  const VisionSetup setup(sidewalk, "front");
  const VisionSetup::ChangedScene swapped = setup.changed_scene({}, {{"lamp", "bench"}});
  namespace pseiki = sensing::pseiki;
  for (const std::uint64_t seed : {14U, 26U, 87U, 124U, 174U, 198U, 199U}) {
    const pseiki::SimulatedImage image =
        pseiki::simulate(swapped.scene, setup.camera(), swapped.uncertainty,
                         pseiki::testing::kIssuePerturbation, seed);
    const pseiki::Verification result =
        pseiki::verify(setup.scene(), setup.camera(), setup.uncertainty(),
                       pseiki::testing::inputs_of(image), setup.options());
    EXPECT_FALSE(result.accepted) << "seed " << seed << ": scene belief "
                                  << result.board.scene.belief;
  }
}

// An image made the way a tool outside the project makes one from the model panel `spar vision
// render` prints (each edge from its p0 to its p1): 0.5 px of noise on every end point, exactly
// 20% of the edges dropped, 10% split with a 2 px gap, 8 clutter segments of 15-120 px anywhere.
sensing::pseiki::SimulatedImage image_from_panel(const sensing::pseiki::ModelPanel& panel,
                                                 std::uint64_t seed) {
  namespace pseiki = sensing::pseiki;
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto noisy = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(p.x() + noise(random), p.y() + noise(random));
  };
  const std::size_t count = panel.edges().size();
  std::vector<std::size_t> order(count);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), random);
  const auto dropped = static_cast<std::size_t>(std::lround(0.2 * static_cast<double>(count)));
  const auto split = static_cast<std::size_t>(std::lround(0.1 * static_cast<double>(count)));
  pseiki::SimulatedImage image;
  const auto add = [&](const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, std::string truth) {
    image.edges.push_back(
        {{"i" + std::to_string(image.edges.size()), {noisy(p0), noisy(p1)}}, std::move(truth)});
  };
  for (std::size_t k = dropped; k < count; ++k) {
    const pseiki::PanelEdge& edge = panel.edges()[order[k]];
    const pseiki::Segment& span = edge.span;
    if (k < dropped + split && span.length() > 20) {
      const double at = 0.3 + 0.4 * unit(random), gap = 1.0 / span.length();
      add(span.p0, span.p0 + (at - gap) * (span.p1 - span.p0), edge.id);
      add(span.p0 + (at + gap) * (span.p1 - span.p0), span.p1, edge.id);
    } else {
      add(span.p0, span.p1, edge.id);
    }
  }
  const sensing::Intrinsics& size = panel.camera().intrinsics();
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector2d p(size.width * unit(random), size.height * unit(random));
    const double length = 15 + 105 * unit(random), angle = std::numbers::pi * unit(random);
    image.edges.push_back({{"c" + std::to_string(c),
                            {p, p + length * Eigen::Vector2d(std::cos(angle), std::sin(angle))}},
                           ""});
  }
  return image;
}

// The block seen down its hole from above and the on-back scene from above: their model panels
// once held edges seen end-on (0 px long) and the hole's two rims 0.3 px apart, which images made
// from the panel labelled with their twins (about 75% right); the panel holds only what an edge
// detector resolves now (sensing/pseiki/expected_scene.hpp's Resolution).
TEST(PanelImages, ImagesMadeFromTheRenderedPanelAreLabelledAndAccepted) {
  namespace pseiki = sensing::pseiki;
  for (const char* name : {"peg_block_camera_verify.yaml", "peg_block_on_back_camera.yaml"}) {
    const Scenario scenario = load_scenario(kExamples / name);
    const VisionSetup setup(scenario, "overhead");
    const pseiki::ModelPanel panel(setup.scene(), setup.camera(), setup.uncertainty());
    for (const pseiki::PanelEdge& edge : panel.edges())
      for (const pseiki::Segment& piece : edge.pieces)
        EXPECT_GE(piece.length(), pseiki::kMinimumPiece) << name << ": " << edge.id;
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const pseiki::SimulatedImage image = image_from_panel(panel, seed);
      const pseiki::Verification result =
          pseiki::verify(setup.scene(), setup.camera(), setup.uncertainty(),
                         pseiki::testing::inputs_of(image), setup.options());
      const pseiki::testing::LabelScore score = pseiki::testing::score(result, image);
      EXPECT_GE(score.accuracy(), 0.9) << name << " seed " << seed;
      EXPECT_EQ(score.clutter_believed, 0) << name << " seed " << seed;
      EXPECT_TRUE(result.accepted) << name << " seed " << seed;
    }
  }
}

}  // namespace
}  // namespace spar::planner
