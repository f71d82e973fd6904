// PSEIKI's knowledge sources one at a time (labeler.hpp, merger.hpp, splitter.hpp, grouper.hpp)
// on images made from the expected scene itself, changed in one way per test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "spar/sensing/pseiki/grouper.hpp"
#include "spar/sensing/pseiki/labeler.hpp"
#include "spar/sensing/pseiki/merger.hpp"
#include "spar/sensing/pseiki/splitter.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/sensing/pseiki/scenes.hpp"

namespace spar::sensing::pseiki {
namespace {

// The expected scene as an image: every visible piece, ids "e1", "e2", ... in panel order.
std::vector<ImageEdgeInput> image_of(const ModelPanel& panel) {
  std::vector<ImageEdgeInput> out;
  for (const PanelEdge& edge : panel.edges())
    for (const Segment& piece : edge.pieces)
      out.push_back({std::string("e").append(std::to_string(out.size() + 1)), piece});
  return out;
}

// The panel edge an input came from in image_of (one piece per edge in these scenes).
int truth_of(const ModelPanel& panel, int input) {
  int count = 0;
  for (std::size_t e = 0; e < panel.edges().size(); ++e)
    for (std::size_t p = 0; p < panel.edges()[e].pieces.size(); ++p)
      if (count++ == input) return static_cast<int>(e);
  return -1;
}

// Segment `s` moved by `shift` pixels along its normal.
Segment shifted(const Segment& s, double shift) {
  const Eigen::Vector2d d = s.direction(), n(-d.y(), d.x());
  return {s.p0 + shift * n, s.p1 + shift * n};
}

struct Fixture {
  testing::TestScene test = testing::two_boxes();
  ModelPanel panel{test.scene, test.camera, test.uncertainty};
};

TEST(Labeler, TheExpectedSceneItselfGetsItsOwnLabels) {
  const Fixture f;
  Blackboard board(f.panel, image_of(f.panel), 1.0);
  Labeler().label(board);
  for (std::size_t i = 0; i < board.edges.size(); ++i) {
    EXPECT_EQ(board.edges[i].label, truth_of(f.panel, static_cast<int>(i)));
    EXPECT_EQ(board.edges[i].belief, kMaxSupport);  // collinearity 1, capped
    EXPECT_LE(board.edges[i].candidates.size(), 4U);
  }
}

// The survey: "The belief of the match made then is set to the degree of collinearity".
TEST(Labeler, InitialBeliefIsTheDegreeOfCollinearity) {
  const Fixture f;
  const PanelEdge& edge = f.panel.edges()[0];
  const Segment off = shifted(edge.pieces[0], 0.5 * edge.tolerance.offset);
  Blackboard board(f.panel, {{"a", off}}, 1.0);
  Labeler(1).label(board);
  EXPECT_EQ(board.edges[0].label, 0);
  EXPECT_NEAR(board.edges[0].belief, collinearity(off, edge.pieces, edge.tolerance), 1e-15);
  EXPECT_NEAR(board.edges[0].belief, 0.75, 0.05);
}

// Relational evidence: an edge whose neighbours on its faces agree with its label gains belief;
// one that sits where no model edge is, given its neighbours, loses it.
TEST(Labeler, ConstraintsRaiseConsistentLabelsAndLowerInconsistentOnes) {
  const Fixture f;
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  // Move the whole image by about half the smallest tolerance (a misregistration): initial
  // beliefs drop, while the relations between edges and where they meet are kept.
  double smallest = f.panel.edges()[0].tolerance.offset;
  for (const PanelEdge& edge : f.panel.edges())
    smallest = std::min(smallest, edge.tolerance.offset);
  const Eigen::Vector2d move = 0.5 * smallest * Eigen::Vector2d(0.6, 0.8);
  for (ImageEdgeInput& edge : image)
    edge.segment = {edge.segment.p0 + move, edge.segment.p1 + move};
  Blackboard board(f.panel, image, 1.0);
  const Labeler labeler;
  labeler.label(board);
  std::vector<double> initial;
  for (const ImageEdge& edge : board.edges) initial.push_back(edge.belief);
  labeler.update(board);
  int raised = 0;
  for (std::size_t i = 0; i < board.edges.size(); ++i)
    if (board.edges[i].belief > initial[i]) ++raised;
  EXPECT_GT(raised, static_cast<int>(board.edges.size()) / 2);
}

TEST(Labeler, AShadowBesideAnEdgeLosesToTheEdge) {
  const Fixture f;
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  const Segment shadow = shifted(image[0].segment, 0.6 * f.panel.edges()[0].tolerance.offset);
  image.push_back({"shadow", shadow});
  Blackboard board(f.panel, image, 1.0);
  const Labeler labeler;
  labeler.label(board);
  for (int round = 0; round < 4; ++round) {
    labeler.update(board);
    Grouper().group(board);
  }
  EXPECT_EQ(board.edges[0].label, truth_of(f.panel, 0));
  EXPECT_GT(board.edges[0].belief, board.edges.back().belief);
}

// Shafer's discounting by the element's reliability (labeler.hpp): alone, a 4 px piece of a
// model edge keeps its label with at most 4 / kReliableLength of belief; a 20 px piece is not
// discounted.
TEST(Labeler, AShortEdgeIsALessReliableMeasurement) {
  const Fixture f;
  const Segment& piece = f.panel.edges()[0].pieces[0];
  ASSERT_GT(piece.length(), 20);
  for (const double length : {4.0, 20.0}) {
    const Eigen::Vector2d middle = piece.midpoint(), direction = piece.direction();
    Blackboard board(
        f.panel, {{"a", {middle - 0.5 * length * direction, middle + 0.5 * length * direction}}},
        1.0);
    const Labeler labeler;
    labeler.label(board);
    labeler.update(board);
    EXPECT_EQ(board.edges[0].label, 0) << length;
    if (length < kReliableLength) {
      EXPECT_LE(board.edges[0].belief, length / kReliableLength);
    } else {
      EXPECT_GT(board.edges[0].belief, 0.9);
    }
  }
}

// Runs the labeler's rounds as match() does without its other sources.
void settle(Blackboard& board) {
  const Labeler labeler;
  labeler.label(board);
  for (int round = 0; round < 4; ++round) {
    labeler.update(board);
    Grouper().group(board);
  }
}

// Junction evidence (labeler.hpp): a shadow 6 px beside an edge whose own edge was not detected,
// as long as it and inside its tolerance, is nearly as collinear with the model edge as the edge
// would be, and no rival says otherwise; what gives it away is that the edges meeting the model
// edge at its vertices end on the model edge's line, not on the shadow's.
TEST(Labeler, AShadowWhoseEndsMeetNoNeighbourIsNotBelieved) {
  const Fixture f;
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  const double shift = std::min(6.0, 0.6 * f.panel.edges()[0].tolerance.offset);
  ASSERT_GT(shift, 4.0);  // a shadow, not noise
  image[0] = {"shadow", shifted(image[0].segment, shift)};
  Blackboard board(f.panel, image, 1.0);
  settle(board);
  EXPECT_TRUE(board.edges[0].label < 0 || board.edges[0].belief < kDetectionBelief)
      << board.edges[0].belief;
  // The same edge where it belongs is believed.
  image[0].segment = f.panel.edges()[0].pieces[0];
  Blackboard seen(f.panel, image, 1.0);
  settle(seen);
  EXPECT_EQ(seen.edges[0].label, 0);
  EXPECT_GE(seen.edges[0].belief, 0.9);
}

// A believed piece of model edge A confirms an edge on its line, but not beyond A's extent: an
// edge on A's line that runs mostly past A's end (clutter along a border) stays doubted.
TEST(Labeler, AnEdgeOnTheLineButPastTheModelEdgeIsNotConfirmedByIt) {
  const Fixture f;
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  const Segment& edge = image[0].segment;
  const Eigen::Vector2d d = edge.direction();
  const double margin = f.panel.edges()[0].tolerance.margin;
  const Segment past{edge.p1 + (margin - 3) * d, edge.p1 + (margin + 27) * d};  // 3 px inside
  image.push_back({"past", past});
  Blackboard board(f.panel, image, 1.0);
  settle(board);
  EXPECT_GE(board.edges[0].belief, 0.9);
  EXPECT_TRUE(board.edges.back().label < 0 || board.edges.back().belief < kDetectionBelief)
      << board.edges.back().belief;
}

// An edge detector reports one edge where two coincide: clutter running along a believed edge,
// 1.5-2.5 px off its line at a small angle (within the noise tolerance of the model edge, as
// collinear with it as the edge itself), duplicates it and is not believed; the edge still is.
TEST(Labeler, AnEdgeRunningAlongABelievedEdgeDuplicatesItAndIsNotBelieved) {
  const Fixture f;
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  const Segment edge = image[0].segment;
  const Eigen::Vector2d d = edge.direction(), n(-d.y(), d.x());
  const double along = std::min(20.0, 0.4 * edge.length());
  ASSERT_GT(along, 10.0);
  const Eigen::Vector2d start = edge.p0 + 0.3 * edge.length() * d;
  image.push_back({"along", {start + 1.5 * n, start + along * d + 2.5 * n}});
  Blackboard board(f.panel, image, 1.0);
  settle(board);
  EXPECT_EQ(board.edges[0].label, 0);
  EXPECT_GE(board.edges[0].belief, 0.9);
  EXPECT_TRUE(board.edges.back().label < 0 || board.edges.back().belief < kDetectionBelief)
      << board.edges.back().belief;
}

// The noise allowed where two pieces of one edge meet is at the believed piece's ends only: a
// fragment shorter than that allowance (2.4 px) lying off the line within the piece's extent,
// away from its ends, duplicates the piece entirely (with the allowance taken off anywhere, only
// 12% of it counted and such fragments kept a belief of 0.21 on the on-back scene).
TEST(Labeler, AShortFragmentWithinABelievedEdgeDuplicatesAllOfIt) {
  const Fixture f;
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  const Segment edge = image[0].segment;
  const Eigen::Vector2d d = edge.direction(), n(-d.y(), d.x());
  const Eigen::Vector2d start = edge.p0 + 0.5 * edge.length() * d + 2.5 * n;
  image.push_back({"fragment", {start, start + 2.4 * d}});
  Blackboard board(f.panel, image, 1.0);
  settle(board);
  EXPECT_EQ(board.edges[0].label, 0);
  EXPECT_GE(board.edges[0].belief, 0.9);
  EXPECT_TRUE(board.edges.back().label < 0 || board.edges.back().belief < 0.01)
      << board.edges.back().belief;
}

// Downward flow: doubt about an object bears on the labels of all its candidates at once (an
// internal node of the element's hypothesis tree).
TEST(Labeler, DoubtAboutTheObjectLowersItsEdgesLabels) {
  const Fixture f;
  Blackboard board(f.panel, image_of(f.panel), 1.0);
  const Labeler labeler;
  labeler.label(board);
  const double before = labeler.evidence(board, 0).tree.combine().belief[static_cast<std::size_t>(
      labeler.evidence(board, 0).candidate_leaves[0])];
  board.objects.push_back({.label = f.panel.edges()[0].object,
                           .faces = {},
                           .coverage = 0,
                           .belief = 0,
                           .disbelief = 0.5});
  const ElementEvidence doubted = labeler.evidence(board, 0);
  const double after =
      doubted.tree.combine().belief[static_cast<std::size_t>(doubted.candidate_leaves[0])];
  EXPECT_LT(after, before);
}

TEST(Labeler, AtLeastOneCandidate) {
  EXPECT_THROW_MESSAGE(Labeler(0), "at least one candidate label per edge, got 0");
}

// Two pieces of one edge with a gap become one element (the survey's "top:38%").
TEST(Merger, TwoPiecesOfOneEdgeBecomeOne) {
  const Fixture f;
  const Segment& whole = f.panel.edges()[0].pieces[0];
  const Eigen::Vector2d d = whole.direction();
  const double length = whole.length();
  Blackboard board(f.panel,
                   {{"a", {whole.p0, whole.p0 + 0.4 * length * d}},
                    {"b", {whole.p0 + 0.5 * length * d, whole.p1}}},
                   1.0);
  Labeler().label(board);
  ASSERT_EQ(board.edges[0].label, 0);
  ASSERT_EQ(board.edges[1].label, 0);
  EXPECT_EQ(Merger().merge(board), 1);
  ASSERT_EQ(board.edges.size(), 3U);
  EXPECT_FALSE(board.edges[0].active);
  EXPECT_FALSE(board.edges[1].active);
  EXPECT_EQ(board.edges[2].inputs, (std::vector<int>{0, 1}));
  EXPECT_NEAR(board.edges[2].segment.length(), length, 1e-9);
  EXPECT_EQ(board.element_of(0), 2);
  EXPECT_EQ(board.element_of(1), 2);
}

// A parallel edge a few pixels aside is not a piece of the same line.
TEST(Merger, AParallelEdgeAsideIsNotMerged) {
  const Fixture f;
  const Segment& whole = f.panel.edges()[0].pieces[0];
  Blackboard board(f.panel, {{"a", whole}, {"b", shifted(whole, 5)}}, 1.0);
  Labeler().label(board);
  ASSERT_EQ(board.edges[1].label, 0);
  EXPECT_EQ(Merger().merge(board), 0);
}

// A fragment continuing an edge's line past its end, within the pose's margin there, would make
// the edge longer than its image can be (PanelEdge::longest_px): a shadow or clutter, not a piece
// of it. It is not merged with the edge, and it is not believed; the edge still is.
TEST(Merger, AnEdgeAndAFragmentPastItsEndLongerThanItCanBeAreNotMerged) {
  const Fixture f;
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  // An edge whose margin leaves room for a fragment from 1 px past its end to 3 px past what
  // its image can be (pixels past p1).
  const auto room = [&](const PanelEdge& e) {
    return e.tolerance.margin - (e.longest_px - e.span.length() + 3);
  };
  const auto model = std::ranges::max_element(f.panel.edges(), {}, room);
  ASSERT_GT(room(*model), 0.5);
  const int a = static_cast<int>(model - f.panel.edges().begin());
  ASSERT_EQ(truth_of(f.panel, a), a);  // one piece per edge: input a is edge a
  const Segment edge = image[static_cast<std::size_t>(a)].segment;
  const Eigen::Vector2d d = edge.direction();
  const double start = 1, end = model->longest_px - edge.length() + 3;
  image.push_back({"past", {edge.p1 + start * d, edge.p1 + end * d}});
  Blackboard board(f.panel, image, 1.0);
  Labeler().label(board);
  ASSERT_EQ(board.edges.back().label, a);
  EXPECT_EQ(Merger().merge(board), 0);
  settle(board);
  EXPECT_EQ(board.edges[static_cast<std::size_t>(a)].label, a);
  EXPECT_GE(board.edges[static_cast<std::size_t>(a)].belief, 0.9);
  EXPECT_TRUE(board.edges.back().label < 0 || board.edges.back().belief < kDetectionBelief)
      << board.edges.back().belief;
}

// One image edge along two collinear model edges (two slabs' borders in a row) is cut where
// one ends and the other begins, and each piece gets its own label.
TEST(Splitter, AnEdgeAlongTwoCollinearModelEdgesIsCutBetweenThem) {
  testing::TestScene test(testing::straight_down_camera());
  test.add("left", {0.2, 0.2, 0.02}, testing::at(-0.105, 0), {});
  test.add("right", {0.2, 0.2, 0.02}, testing::at(0.105, 0), {});
  test.uncertainty.noise_px = 0.5;
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  // The two slabs' edges at the same y, end to end: one image edge over both.
  int first = -1, second = -1;
  for (std::size_t a = 0; a < panel.edges().size(); ++a)
    for (std::size_t b = 0; b < panel.edges().size(); ++b) {
      const Segment& x = panel.edges()[a].span;
      const Segment& y = panel.edges()[b].span;
      if (panel.edges()[a].object == 0 && panel.edges()[b].object == 1 &&
          std::abs(x.direction().y()) < 1e-6 && std::abs(y.direction().y()) < 1e-6 &&
          std::abs(x.p0.y() - y.p0.y()) < 1e-6 && first < 0) {
        first = static_cast<int>(a);
        second = static_cast<int>(b);
      }
    }
  ASSERT_GE(first, 0);
  const Segment& x = panel.edges()[static_cast<std::size_t>(first)].span;
  const Segment& y = panel.edges()[static_cast<std::size_t>(second)].span;
  const double left = std::min({x.p0.x(), x.p1.x()}), right = std::max({y.p0.x(), y.p1.x()});
  const Segment joined{{left, x.p0.y()}, {right, x.p0.y()}};
  Blackboard board(panel, {{"border", joined}}, 1.0);
  const Labeler labeler;
  labeler.label(board);
  EXPECT_EQ(Splitter().split(board), 1);
  labeler.label(board);
  ASSERT_EQ(board.edges.size(), 3U);
  EXPECT_FALSE(board.edges[0].active);
  std::vector<int> labels = {board.edges[1].label, board.edges[2].label};
  std::sort(labels.begin(), labels.end());
  std::vector<int> expected = {first, second};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(labels, expected);
  EXPECT_EQ(board.edges[1].split_from, 0);
  EXPECT_EQ(board.edges[1].inputs, (std::vector<int>{0}));
}

TEST(Splitter, AnEdgeWithinOneModelEdgeIsLeftAlone) {
  const Fixture f;
  Blackboard board(f.panel, image_of(f.panel), 1.0);
  Labeler().label(board);
  EXPECT_EQ(Splitter().split(board), 0);
}

// Faces group the edges labelled with their edges; with the whole expected scene seen, every
// visible face and object is found and believed, and the scene accepted.
TEST(Grouper, TheWholeSceneGroupsIntoItsFacesAndObjects) {
  const Fixture f;
  Blackboard board(f.panel, image_of(f.panel), 1.0);
  Labeler().label(board);
  Grouper().group(board);
  EXPECT_EQ(board.faces.size(), f.panel.faces().size());
  for (const ImageFace& face : board.faces) {
    EXPECT_EQ(face.members.size(),
              f.panel.faces()[static_cast<std::size_t>(face.label)].edges.size());
    EXPECT_GT(face.belief, 0.9);
  }
  ASSERT_EQ(board.objects.size(), 2U);
  for (const ImageObject& object : board.objects) {
    EXPECT_NEAR(object.coverage, 1, 1e-9);
    EXPECT_GT(object.belief, 0.9);
    EXPECT_EQ(object.disbelief, 0);
  }
  EXPECT_GT(board.scene.belief, 0.9);
}

// An object of which nothing is seen is doubted as much as evidence allows, and so is the scene.
TEST(Grouper, AMissingObjectIsDoubtedAndSoIsTheScene) {
  const Fixture f;
  std::vector<ImageEdgeInput> image;  // the first object's edges only
  for (const PanelEdge& edge : f.panel.edges())
    if (edge.object == 0) image.push_back({edge.id, edge.pieces[0]});
  Blackboard board(f.panel, image, 1.0);
  Labeler().label(board);
  Grouper().group(board);
  ASSERT_EQ(board.objects.size(), 2U);
  EXPECT_GT(board.objects[0].belief, 0.9);
  EXPECT_EQ(board.objects[1].coverage, 0);
  EXPECT_NEAR(board.objects[1].disbelief, kMaxSupport, 1e-12);
  EXPECT_LT(board.scene.belief, 0.1);
}

// The survey's face-level incompatibility: an edge wrongly labelled with an edge of face F but
// lying across face G makes F's region overlap G's, and both faces are doubted.
TEST(Grouper, OverlappingFacesAreIncompatible) {
  const Fixture f;
  const auto belief_of = [](const Blackboard& board, int face) {
    for (const ImageFace& image_face : board.faces)
      if (image_face.label == face) return image_face.belief;
    return -1.0;
  };
  // Two faces of one object sharing an edge, and an edge of the second not on the first.
  const PanelFace& first = f.panel.faces()[0];
  int second = -1, far_edge = -1;
  for (std::size_t g = 1; g < f.panel.faces().size() && second < 0; ++g) {
    const PanelFace& face = f.panel.faces()[g];
    if (face.object != first.object) continue;
    for (const int e : face.edges)
      if (std::find(first.edges.begin(), first.edges.end(), e) == first.edges.end()) {
        second = static_cast<int>(g);
        far_edge = e;
      }
  }
  ASSERT_GE(second, 0);
  Blackboard clean(f.panel, image_of(f.panel), 1.0);
  Labeler().label(clean);
  Grouper().group(clean);
  std::vector<ImageEdgeInput> image = image_of(f.panel);
  image.push_back({"stray", f.panel.edges()[static_cast<std::size_t>(far_edge)].pieces[0]});
  Blackboard stray(f.panel, image, 1.0);
  Labeler().label(stray);
  stray.edges.back().label = first.edges[0];  // the stray edge claims to be on the first face
  stray.edges.back().belief = 0.9;
  Grouper().group(stray);
  EXPECT_LT(belief_of(stray, second), belief_of(clean, second));
  EXPECT_LT(belief_of(stray, 0), belief_of(clean, 0));
}

// The floor is the exact quantile of the coverage of independently found edges: against every
// subset of the edges enumerated, within the grid's rounding (each outcome moves by at most
// edges / 1024, so the quantile does too).
TEST(Grouper, TheCoverageFloorIsTheExactQuantileOfIndependentDetections) {
  const std::vector<std::vector<double>> objects{
      {455, 97, 25, 113, 76, 163, 400, 157}, {10, 10, 10, 10}, {3, 40, 41, 7, 90, 2, 60, 33, 12}};
  for (const std::vector<double>& lengths : objects) {
    for (const double p : {0.5, 0.8, 0.95}) {
      const double total = std::accumulate(lengths.begin(), lengths.end(), 0.0);
      std::vector<std::pair<double, double>> outcomes;  // (coverage, probability)
      for (unsigned subset = 0; subset < (1U << lengths.size()); ++subset) {
        double covered = 0, probability = 1;
        for (std::size_t m = 0; m < lengths.size(); ++m) {
          const bool found = (subset >> m & 1U) != 0;
          covered += found ? lengths[m] : 0;
          probability *= found ? p : 1 - p;
        }
        outcomes.emplace_back(covered / total, probability);
      }
      std::sort(outcomes.begin(), outcomes.end());
      double below = 0, quantile = 1;
      for (const auto& [coverage, probability] : outcomes) {
        below += probability;
        if (below >= kCoverageQuantile) {
          quantile = coverage;
          break;
        }
      }
      EXPECT_NEAR(coverage_floor(lengths, p), quantile, double(lengths.size()) / 1024)
          << lengths.size() << " edges, p = " << p;
    }
  }
  EXPECT_EQ(coverage_floor({}, 0.8), 0);
  EXPECT_EQ(coverage_floor({5, 7}, 1), 1);
}

// Many edges of one length: the binomial's quantile, close to the normal p - 2 sigma. Two long
// edges holding most of the length (the sidewalk's borders): missing both happens (1 - p)^2 = 4%
// of the time, and the rest's coverage stays above the floor, though below p - 2 sigma.
TEST(Grouper, TheCoverageFloorFollowsHowTheLengthIsShared) {
  const double p = 0.8;
  const std::vector<double> even(100, 20.0);
  EXPECT_NEAR(coverage_floor(even, p), p - 2 * std::sqrt(p * (1 - p) / 100), 0.01);
  const std::vector<double> walk{455, 97, 25, 113, 76, 163, 400, 157};
  const double total = std::accumulate(walk.begin(), walk.end(), 0.0);
  double squares = 0;
  for (const double l : walk) squares += l * l;
  const double normal_floor = p - 2 * std::sqrt(p * (1 - p) / (total * total / squares));
  const double without_borders = (total - 455 - 400) / total;  // 0.42
  EXPECT_GT(without_borders, coverage_floor(walk, p));
  EXPECT_LT(without_borders, normal_floor);
}

}  // namespace
}  // namespace spar::sensing::pseiki
