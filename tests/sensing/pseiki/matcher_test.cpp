// PSEIKI end to end on simulated images (sensing/pseiki/matcher.hpp, simulate.hpp), issue 27's
// acceptance: with the poses perturbed within their uncertainty, 20% of the edges dropped, 10%
// split, shadows and clutter added and 0.5 px of noise, at least 90% of the surviving edges get
// their true label, clutter stays unlabelled or below 0.2 belief, the scene is accepted and the
// pose correction reduces the pose error; with an object missing or swapped for another the scene
// is rejected. Fixed seeds, several trials.
#include "spar/sensing/pseiki/matcher.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "spar/sensing/pseiki/simulate.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/sensing/pseiki/label_score.hpp"
#include "tests/sensing/pseiki/scenes.hpp"

namespace spar::sensing::pseiki {
namespace {

constexpr int kTrials = 10;

using testing::inputs_of;
const ImagePerturbation& kPerturbation = testing::kIssuePerturbation;

// The pose error of an eq. 2 offset, each component as a fraction of its half-width.
double normalised(const PoseOffset& o, const kinematics::PoseUncertainty& h) {
  double sum = 0;
  for (const auto& [value, half] : {std::pair{o.dx, h.dx}, std::pair{o.dy, h.dy},
                                    std::pair{o.dz, h.dz}, std::pair{o.dtheta, h.dtheta}})
    if (half > 0) sum += (value / half) * (value / half);
  return std::sqrt(sum);
}

PoseOffset minus(const PoseOffset& a, const PoseOffset& b) {
  return {a.dx - b.dx, a.dy - b.dy, a.dz - b.dz, a.dtheta - b.dtheta};
}

TEST(Verification, SimulatedImagesAreLabelledAcceptedAndCorrected) {
  const testing::TestScene test = testing::two_boxes();
  MatchOptions options;
  options.detection_probability = 0.8;
  for (int seed = 1; seed <= kTrials; ++seed) {
    const SimulatedImage image = simulate(test.scene, test.camera, test.uncertainty, kPerturbation,
                                          static_cast<std::uint64_t>(seed));
    const Verification result =
        verify(test.scene, test.camera, test.uncertainty, inputs_of(image), options);
    const testing::LabelScore s = testing::score(result, image);
    EXPECT_GE(s.right, 0.9 * s.surviving)
        << "seed " << seed << ": " << s.right << " of " << s.surviving;
    EXPECT_EQ(s.clutter_believed, 0) << "seed " << seed << " of " << s.clutter;
    EXPECT_TRUE(result.accepted) << "seed " << seed << ": " << result.board.scene.belief;
    ASSERT_TRUE(result.correction.has_value()) << "seed " << seed;
    const int target = result.correction->target;
    ASSERT_GE(target, 0);
    const PoseOffset& truth = image.object_offsets[static_cast<std::size_t>(target)];
    const kinematics::PoseUncertainty& prior =
        test.uncertainty.objects[static_cast<std::size_t>(target)];
    EXPECT_LT(normalised(minus(truth, result.correction->offset), prior), normalised(truth, prior))
        << "seed " << seed;
  }
}

TEST(Verification, AMissingObjectIsRejected) {
  const testing::TestScene test = testing::two_boxes();
  testing::TestScene without(test.camera);
  without.add("block", {0.20, 0.14, 0.08}, testing::at(0, 0), test.uncertainty.objects[0]);
  without.uncertainty.noise_px = test.uncertainty.noise_px;
  MatchOptions options;
  options.detection_probability = 0.8;
  for (int seed = 1; seed <= kTrials; ++seed) {
    const SimulatedImage image = simulate(without.scene, without.camera, without.uncertainty,
                                          kPerturbation, static_cast<std::uint64_t>(seed));
    const Verification result =
        verify(test.scene, test.camera, test.uncertainty, inputs_of(image), options);
    EXPECT_FALSE(result.accepted) << "seed " << seed << ": " << result.board.scene.belief;
    EXPECT_FALSE(result.correction.has_value());
  }
}

// The tower's place holds another object: a box of the block's size.
TEST(Verification, ASwappedObjectIsRejected) {
  const testing::TestScene test = testing::two_boxes();
  testing::TestScene swapped(test.camera);
  swapped.add("block", {0.20, 0.14, 0.08}, testing::at(0, 0), test.uncertainty.objects[0]);
  swapped.add("tower~block", {0.20, 0.14, 0.08}, testing::at(0.2, 0.15, 0.3),
              test.uncertainty.objects[1]);
  swapped.uncertainty.noise_px = test.uncertainty.noise_px;
  MatchOptions options;
  options.detection_probability = 0.8;
  for (int seed = 1; seed <= kTrials; ++seed) {
    const SimulatedImage image = simulate(swapped.scene, swapped.camera, swapped.uncertainty,
                                          kPerturbation, static_cast<std::uint64_t>(seed));
    const Verification result =
        verify(test.scene, test.camera, test.uncertainty, inputs_of(image), options);
    EXPECT_FALSE(result.accepted) << "seed " << seed << ": " << result.board.scene.belief;
  }
}

TEST(Verification, OnePassOrTwo) {
  const testing::TestScene test = testing::two_boxes();
  const SimulatedImage image =
      simulate(test.scene, test.camera, test.uncertainty, kPerturbation, 3);
  MatchOptions options;
  options.passes = 1;
  EXPECT_EQ(verify(test.scene, test.camera, test.uncertainty, inputs_of(image), options).passes, 1);
  options.passes = 3;
  EXPECT_THROW_MESSAGE(verify(test.scene, test.camera, test.uncertainty, inputs_of(image), options),
                       "verify: 1 or 2 passes, got 3");
}

// The same seed gives the same image.
TEST(Simulate, ASeedGivesOneImage) {
  const testing::TestScene test = testing::two_boxes();
  const SimulatedImage a = simulate(test.scene, test.camera, test.uncertainty, kPerturbation, 11);
  const SimulatedImage b = simulate(test.scene, test.camera, test.uncertainty, kPerturbation, 11);
  ASSERT_EQ(a.edges.size(), b.edges.size());
  for (std::size_t i = 0; i < a.edges.size(); ++i) {
    EXPECT_EQ(a.edges[i].truth, b.edges[i].truth);
    EXPECT_EQ(a.edges[i].edge.segment.p0, b.edges[i].edge.segment.p0);
  }
  int clutter = 0;
  for (const SimulatedEdge& edge : a.edges) clutter += edge.truth.empty() ? 1 : 0;
  EXPECT_GE(clutter, kPerturbation.clutter / 2);  // some clutter may fall outside the image
}

TEST(Simulate, MistakesAreNamed) {
  const testing::TestScene test = testing::two_boxes();
  EXPECT_THROW_MESSAGE(simulate(test.scene, test.camera, test.uncertainty, {.drop = 1.5}, 1),
                       "drop must be a probability in [0, 1], got 1.5");
  EXPECT_THROW_MESSAGE(simulate(test.scene, test.camera, test.uncertainty, {.noise_px = -1}, 1),
                       "noise must be >= 0 pixels, got -1");
}

}  // namespace
}  // namespace spar::sensing::pseiki
