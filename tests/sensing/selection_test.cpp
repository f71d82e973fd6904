// Simulated sensors, hypothesis evidence and the minimax-ambiguity choice of sensing operations
// (sensing/sensors.hpp, hypotheses.hpp, selection.hpp) on the seed's block.
//
// The constructed scene: the block rests on its left face (-x) or on its right face (+x), the two
// hypotheses. Either way the face on top is a plain 3 x 3 in square 3.5 in above the table, so a
// sensor looking down sees the same thing; so does one looking along y (the front face, whose
// cross hole is only mirrored). The block's top face, with the peg hole, points to world -x in
// one pose and to +x in the other: a sensor looking from +x sees the hole in one and the plain
// bottom face in the other. The selection must choose that sensor.
#include "spar/sensing/selection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>

#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/stable_poses.hpp"
#include "tests/common/expect_message.hpp"

namespace spar::sensing {
namespace {

using geometry::ObjectModel;

constexpr double kDegree = std::numbers::pi / 180;

// The block, its features and aspects, built once for the whole file.
struct Block {
  ObjectModel model = geometry::make_builtin_object("block");
  ObjectFeatures features = object_features(model);
  AspectSet aspects = compute_aspects(model);
  std::vector<geometry::StablePose> poses = geometry::stable_poses(model);
  // The stable pose resting on face `face`.
  [[nodiscard]] const geometry::StablePose& resting_on(int face) const {
    for (const geometry::StablePose& pose : poses)
      if (pose.table_faces == std::vector<int>{face}) return pose;
    throw std::logic_error("no stable pose rests on face " + std::to_string(face));
  }
};

const Block& block() {
  static const Block instance;
  return instance;
}

Eigen::Isometry3d resting(const geometry::StablePose& pose, const Eigen::Vector3d& offset,
                          double yaw) {
  return Eigen::Translation3d(offset) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
         pose.object_to_world;
}

HypothesisWorld world(const std::string& label, const geometry::StablePose& pose,
                      const Eigen::Vector3d& offset = Eigen::Vector3d::Zero(), double yaw = 0) {
  HypothesisWorld out;
  out.label = label;
  out.target = out.scene.add("block", block().model, block().features, resting(pose, offset, yaw));
  out.aspects = &block().aspects;
  return out;
}

SensorModel fixed(std::string name, SensorKind kind, const Eigen::Vector3d& eye) {
  SensorModel sensor = default_range_scanner();
  sensor.name = std::move(name);
  sensor.kind = kind;
  sensor.mount = Mount::kFixed;
  const Eigen::Vector3d target(0, 0, 0.04);
  const Eigen::Vector3d up =
      std::abs(eye.z() - target.z()) > 0.3 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ();
  sensor.pose = look_at(eye, target, up);
  if (kind == SensorKind::kCamera) {
    sensor.intrinsics = {.fx = 800, .fy = 800, .cx = 320, .cy = 240, .width = 640, .height = 480};
    sensor.noise_px = 0.5;
  }
  return sensor;
}

// The seed's Table 2 uncertainty of the block: ±0.11 in, ±5.5°; the block's bounding radius is
// 74 mm and the sensors stand 0.5 m away.
constexpr double kSeedOffset = 0.11 * 0.0254, kSeedYaw = 5.5 * kDegree;
MatchTolerances seed_tolerances(const SensorModel& sensor) {
  return match_tolerances(sensor, kSeedOffset, kSeedOffset, kSeedOffset, kSeedYaw, 0.074, 0.5);
}

// The two hypotheses and three fixed sensors. A camera at the front would see the mouth of the
// cross hole 15 mm left or right of the middle (the poses mirror it), which tells the poses
// apart too, so the cameras are only "top" and "side"; the range scanner gets no patch out of the
// small mouth and has all three.
SelectionProblem left_or_right(SensorKind kind) {
  SelectionProblem problem;
  problem.hypotheses.push_back(world("left", block().resting_on(1)));
  problem.hypotheses.push_back(world("right", block().resting_on(5)));
  problem.sensors = {fixed("top", kind, {0, 0, 0.5}), fixed("side", kind, {0.5, 0, 0.04})};
  if (kind == SensorKind::kRangeScanner)
    problem.sensors.push_back(fixed("front", kind, {0, -0.5, 0.04}));
  for (const SensorModel& sensor : problem.sensors)
    problem.tolerances.push_back(seed_tolerances(sensor));
  problem.prior = MassFunction::vacuous(2);
  return problem;
}

const CandidateOperation& candidate_named(const Selection& selection, const std::string& name) {
  for (const CandidateOperation& candidate : selection.candidates)
    if (candidate.viewpoint.label == name) return candidate;
  throw std::logic_error("no candidate " + name);
}

TEST(Sensors, PredictionSeesTheTopFaceFromAbove) {
  const Block& b = block();
  Scene scene;
  scene.add("block", b.model, b.features, resting(b.resting_on(13), {0, 0, 0}, 0));
  const SensorModel top = fixed("top", SensorKind::kRangeScanner, {0, 0, 0.5});
  const Observation seen = predict(scene, top, top.pose);
  // Looking down at the block on its bottom: the top face (19) and the peg hole's floor (16); the
  // cross hole's floors show through the hole in perspective only as slivers below the scanner's
  // 30-sample patches.
  std::vector<int> faces;
  for (const SensedFace& face : seen.faces) faces.push_back(face.truth_face);
  std::sort(faces.begin(), faces.end());
  EXPECT_EQ(faces, (std::vector<int>{16, 19}));
  for (const SensedFace& face : seen.faces) {
    EXPECT_GT(face.normal.z(), 0.99);
    EXPECT_EQ(face.prominence, 1.0);  // each fills more than a tenth of the block's image
  }
}

TEST(Sensors, MeasurementMissesAndJitters) {
  const Block& b = block();
  Scene scene;
  scene.add("block", b.model, b.features, resting(b.resting_on(13), {0, 0, 0}, 0));
  SensorModel camera = fixed("camera", SensorKind::kCamera, {0.3, -0.3, 0.3});
  camera.detection_probability = 0.5;
  camera.noise_px = 1.0;
  const Observation ideal = predict(scene, camera, camera.pose);
  std::mt19937_64 random(5);
  std::size_t found = 0, trials = 200;
  double squared = 0;
  std::size_t moved = 0;
  for (std::size_t i = 0; i < trials; ++i) {
    const Observation measured = measure(scene, camera, camera.pose, random);
    found += measured.edges.size();
    // Each measured endpoint against the nearest ideal endpoint of the same model edge.
    for (const SensedEdge& edge : measured.edges) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const SensedEdge& truth : ideal.edges)
        if (truth.truth_edge == edge.truth_edge)
          nearest = std::min(nearest, (edge.u0 - truth.u0).squaredNorm());
      squared += nearest;
      ++moved;
    }
  }
  EXPECT_NEAR(static_cast<double>(found) / (trials * ideal.edges.size()), 0.5, 0.05);
  EXPECT_NEAR(std::sqrt(squared / (2 * moved)), 1.0, 0.1);  // per-axis standard deviation
}

TEST(Hypotheses, ConsonantSupportFollowsTheMatchQuality) {
  const MassFunction m = consonant_support({0.2, 1.0, 0.6});
  // Pl({h}) = 1 - κ (q(1) - q_h).
  EXPECT_NEAR(m.plausibility(FocalSet::of(3, {1})), 1.0, 1e-12);
  EXPECT_NEAR(m.plausibility(FocalSet::of(3, {2})), 1 - kMaxSupport * 0.4, 1e-12);
  EXPECT_NEAR(m.plausibility(FocalSet::of(3, {0})), 1 - kMaxSupport * 0.8, 1e-12);
  EXPECT_EQ(consonant_support({0.7, 0.7}).elements().size(), 1U);  // equal: no evidence
}

TEST(Hypotheses, LookingDownCannotTellLeftFromRight) {
  const SelectionProblem problem = left_or_right(SensorKind::kRangeScanner);
  const SensorModel& top = problem.sensors[0];
  const std::vector<Expectation> expected = expectations(problem, 0, top.pose);
  for (std::size_t truth = 0; truth < 2; ++truth) {
    const Observation seen{.sensor = "top",
                           .kind = top.kind,
                           .sensor_pose = top.pose,
                           .faces = expected[truth].faces,
                           .edges = {}};
    const Weighing weighed =
        weigh_evidence(seen, expected, problem.tolerances[0], top, problem.prior);
    EXPECT_GT(weighed.combined.ambiguity(), 0.9);
    EXPECT_EQ(weighed.features, 1);
  }
}

// The selection's one job: only "side" brings the ambiguity below the threshold (0.3 bits); the
// others leave it above (the top view tells the poses apart a little, by where the top face sits
// relative to the centre of mass, which `at` places).
TEST(Selection, ChoosesTheOnlyViewpointThatDisambiguates) {
  for (const SensorKind kind : {SensorKind::kRangeScanner, SensorKind::kCamera}) {
    const SelectionProblem problem = left_or_right(kind);
    const Selection chosen = select_operations(problem, SelectionOptions{});
    ASSERT_EQ(chosen.candidates.size(), problem.sensors.size());
    EXPECT_NEAR(chosen.ambiguity_before, 1.0, 1e-12);
    for (const CandidateOperation& candidate : chosen.candidates) {
      if (candidate.viewpoint.label != "side") {
        EXPECT_GT(candidate.max_ambiguity, 0.3)
            << candidate.viewpoint.label << ' ' << to_string(kind);
      }
    }
    EXPECT_LT(candidate_named(chosen, "side").max_ambiguity, 0.3) << to_string(kind);
    ASSERT_EQ(chosen.sequence.size(), 1U) << to_string(kind);
    EXPECT_EQ(chosen.candidates[chosen.sequence[0].candidate].viewpoint.label, "side");
    EXPECT_TRUE(chosen.resolved);
  }
}

// End to end, with the documented noise: the block in either pose, its position and yaw anywhere
// within the seed's ±0.11 in and ±5.5° of the nominal ones; the chosen sensor measures with its
// noise (1 mm and 0.01 rad for the scanner, 0.5 px for the camera) and misses 5% of the features;
// the true pose has the highest belief in at least 95% of the trials.
TEST(Selection, AfterTheChosenOperationTheTruthLeads) {
  for (const SensorKind kind : {SensorKind::kRangeScanner, SensorKind::kCamera}) {
    const SelectionProblem problem = left_or_right(kind);
    const Selection chosen = select_operations(problem, SelectionOptions{});
    ASSERT_FALSE(chosen.sequence.empty());
    const Viewpoint& viewpoint = chosen.candidates[chosen.sequence[0].candidate].viewpoint;
    const SensorModel& sensor = problem.sensors[static_cast<std::size_t>(viewpoint.sensor)];
    const std::vector<Expectation> expected =
        expectations(problem, viewpoint.sensor, viewpoint.sensor_pose);
    std::mt19937_64 random(20261123);
    std::uniform_real_distribution<double> offset(-kSeedOffset, kSeedOffset),
        yaw(-kSeedYaw, kSeedYaw);
    const int trials = 200;
    int right = 0;
    for (int trial = 0; trial < trials; ++trial) {
      const int truth = trial % 2;
      const HypothesisWorld actual = world("actual", block().resting_on(truth == 0 ? 1 : 5),
                                           {offset(random), offset(random), 0}, yaw(random));
      const Observation measured = measure(actual.scene, sensor, viewpoint.sensor_pose, random);
      const Weighing weighed = weigh_evidence(
          measured, expected, problem.tolerances[static_cast<std::size_t>(viewpoint.sensor)],
          sensor, problem.prior);
      const std::vector<double> betp = weighed.combined.pignistic();
      if (betp[static_cast<std::size_t>(truth)] > betp[static_cast<std::size_t>(1 - truth)])
        ++right;
    }
    EXPECT_GE(right, 0.95 * trials) << to_string(kind);
  }
}

// A wrist sensor: viewpoints are classes of directions grouped by the aspects the two poses show;
// the chosen class looks at the block from the +x or -x side (where the poses differ).
TEST(Selection, WristViewpointClassesAndTheChoice) {
  SelectionProblem problem = left_or_right(SensorKind::kRangeScanner);
  problem.sensors = {default_range_scanner()};
  problem.tolerances = {seed_tolerances(problem.sensors[0])};
  SelectionOptions options;
  options.standoff = 0.5;
  const Selection chosen = select_operations(problem, options);
  EXPECT_GT(chosen.candidates.size(), 3U);
  std::set<std::vector<int>> tuples;
  for (const CandidateOperation& candidate : chosen.candidates) {
    EXPECT_TRUE(tuples.insert(candidate.viewpoint.aspects).second);  // one class per tuple
    EXPECT_GE(candidate.viewpoint.direction.z(), std::sin(options.min_elevation) - 1e-12);
  }
  ASSERT_FALSE(chosen.sequence.empty());
  EXPECT_TRUE(chosen.resolved);
  const Viewpoint& best = chosen.candidates[chosen.sequence[0].candidate].viewpoint;
  EXPECT_GT(std::abs(best.direction.x()), 0.5);
  // Nothing reachable: nothing chosen, every class listed as unreachable.
  options.reachable = [](int, const Eigen::Isometry3d&) { return false; };
  const Selection none = select_operations(problem, options);
  EXPECT_TRUE(none.sequence.empty());
  EXPECT_FALSE(none.resolved);
  for (const CandidateOperation& candidate : none.candidates) {
    EXPECT_FALSE(candidate.viewpoint.reachable);
    EXPECT_TRUE(std::isinf(candidate.max_ambiguity));
  }
}

TEST(Selection, IllFormedProblemsSayWhat) {
  SelectionProblem problem = left_or_right(SensorKind::kRangeScanner);
  problem.prior = MassFunction::vacuous(3);
  EXPECT_THROW_MESSAGE(select_operations(problem, SelectionOptions{}),
                       "a prior over 3 hypotheses for 2");
  problem = left_or_right(SensorKind::kRangeScanner);
  problem.sensors[1].detection_probability = 0;
  EXPECT_THROW_MESSAGE(select_operations(problem, SelectionOptions{}),
                       "sensor 'side': detection_probability must be in (0, 1], got 0");
}

}  // namespace
}  // namespace spar::sensing
