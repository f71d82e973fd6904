// PSEIKI's geometric measures (sensing/pseiki/collinearity.hpp): values worked out by hand, and
// the property that makes the relational measure useful under misregistration: any rigid motion
// of the image plane keeps two edges compatible with the model edges they are images of.
#include "spar/sensing/pseiki/collinearity.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace spar::sensing::pseiki {
namespace {

const Tolerance kTolerance{.angle = 0.05, .offset = 4, .margin = 5, .noise_px = 0};

TEST(Collinearity, TermsByHand) {
  const Segment model{{0, 0}, {100, 0}};
  // 1 px off the line (offset term 1 - (1/4)^2), parallel, inside the extent.
  const CollinearityTerms near =
      collinearity_terms({{10, 1}, {60, 1}}, std::span(&model, 1), kTolerance);
  EXPECT_DOUBLE_EQ(near.angle, 1);
  EXPECT_DOUBLE_EQ(near.offset, 1 - 1.0 / 16);
  EXPECT_DOUBLE_EQ(near.overlap, 1);
  // Half of it beyond the end plus the margin: from 105 to 115 of 95..115.
  const CollinearityTerms beyond =
      collinearity_terms({{95, 0}, {115, 0}}, std::span(&model, 1), kTolerance);
  EXPECT_DOUBLE_EQ(beyond.overlap, 0.5);
  // Tilted by half the angle tolerance about its midpoint (50, 0).
  const double tilt = 0.025;
  const Segment tilted{{50 - 20 * std::cos(tilt), -20 * std::sin(tilt)},
                       {50 + 20 * std::cos(tilt), 20 * std::sin(tilt)}};
  EXPECT_NEAR(collinearity(tilted, std::span(&model, 1), kTolerance), 0.75, 1e-12);
  // Beyond any tolerance: 0; exactly on the model: 1.
  EXPECT_EQ(collinearity({{0, 5}, {100, 5}}, std::span(&model, 1), kTolerance), 0);
  EXPECT_EQ(collinearity(model, std::span(&model, 1), kTolerance), 1);
}

// A model edge hidden in its middle has two pieces; an image edge in the hidden gap does not
// overlap it, one on a piece does.
TEST(Collinearity, OverlapCountsOnlyTheVisiblePieces) {
  const Segment pieces[] = {{{0, 0}, {40, 0}}, {{60, 0}, {100, 0}}};
  const Tolerance tight{.angle = 0.05, .offset = 4, .margin = 0, .noise_px = 0};
  EXPECT_EQ(collinearity({{45, 0}, {55, 0}}, pieces, tight), 0);
  EXPECT_EQ(collinearity({{65, 0}, {95, 0}}, pieces, tight), 1);
  EXPECT_DOUBLE_EQ(collinearity({{30, 0}, {70, 0}}, pieces, tight), 0.5);
}

TEST(Collinearity, ShortEdgesGetAWiderAngleTolerance) {
  const Segment model{{0, 0}, {100, 0}};
  const Tolerance noisy{.angle = 0.01, .offset = 4, .margin = 5, .noise_px = 1};
  const double tilt = 0.05;
  const auto edge = [&](double half) {
    return Segment{{50 - half * std::cos(tilt), -half * std::sin(tilt)},
                   {50 + half * std::cos(tilt), half * std::sin(tilt)}};
  };
  EXPECT_GT(collinearity(edge(5), std::span(&model, 1), noisy),
            collinearity(edge(40), std::span(&model, 1), noisy));
}

TEST(EdgeCollinearity, PiecesOfOneLineConfirmAParallelCopyDisconfirms) {
  const Tolerance noise = Tolerance::noise_only(0.5);  // offset 1.5 px
  const Segment a{{0, 0}, {40, 0}}, b{{60, 0}, {90, 0}};
  EXPECT_EQ(edge_collinearity(a, b, noise), 1);
  EXPECT_EQ(edge_noncollinearity(a, b, noise), 0);
  const Segment shadow{{0, 6}, {40, 6}};  // 6 px aside: beyond twice the tolerance
  EXPECT_EQ(edge_collinearity(a, shadow, noise), 0);
  EXPECT_EQ(edge_noncollinearity(a, shadow, noise), 1);
  // Between one and two tolerances: some of each, and room for ignorance.
  const Segment near{{60, 5}, {90, 5}};
  const double c = edge_collinearity(a, near, noise), n = edge_noncollinearity(a, near, noise);
  EXPECT_EQ(c, 0);
  EXPECT_GT(n, 0);
  EXPECT_LT(n, 1);
}

// The survey's defining property: collinearity(E_A, T_{A->B}(E_B)) = 1, i.e. with the image equal
// to the model, compatibility is 1.
TEST(Compatibility, TheModelItselfIsCompatible) {
  const Segment a{{0, 0}, {100, 0}}, b{{100, 0}, {100, 60}};
  EXPECT_NEAR(compatibility(a, b, a, b, kTolerance), 1, 1e-12);
  EXPECT_NEAR(incompatibility(a, b, a, b, kTolerance), 0, 1e-12);
  const Segment predicted = predicted_partner(b, a, b);
  EXPECT_TRUE(predicted.p0.isApprox(a.p0, 1e-12) && predicted.p1.isApprox(a.p1, 1e-12));
}

// Any rotation and translation of the whole image (misregistration) keeps the relation: e1 and e3
// moved together stay compatible with A and B, though each is far from its model edge.
RC_GTEST_PROP(Compatibility, RigidMotionOfTheImageKeepsItCompatible, ()) {
  const auto coordinate = [] { return *rc::gen::inRange(-300, 300) / 1.0; };
  const Segment a{{coordinate(), coordinate()}, {coordinate(), coordinate()}};
  const Segment b{{coordinate(), coordinate()}, {coordinate(), coordinate()}};
  RC_PRE(a.length() > 10 && b.length() > 10);
  const Eigen::Rotation2Dd turn(*rc::gen::inRange(-1000, 1000) / 1000.0);
  const Eigen::Vector2d shift(coordinate(), coordinate());
  const auto moved = [&](const Segment& s) {
    return Segment{turn * s.p0 + shift, turn * s.p1 + shift};
  };
  RC_ASSERT(std::abs(compatibility(moved(a), moved(b), a, b, kTolerance) - 1) < 1e-9);
}

// A wrong relation: an edge where A is not, given where B is.
TEST(Compatibility, AnEdgeWhereTheModelHasNoneIsIncompatible) {
  const Segment a{{0, 0}, {100, 0}}, b{{100, 0}, {100, 60}};
  const Segment elsewhere{{0, 30}, {100, 30}};  // parallel to A, 30 px off what B predicts
  EXPECT_EQ(compatibility(elsewhere, b, a, b, kTolerance), 0);
  EXPECT_EQ(incompatibility(elsewhere, b, a, b, kTolerance), 1);
}

}  // namespace
}  // namespace spar::sensing::pseiki
