// Dempster's rule for hierarchical evidence (sensing/pseiki/hierarchical_evidence.hpp) against
// Dempster's rule on general sets: evidence.hpp's combine() over the same pieces as mass functions
// on the tree's leaves, and the dense brute force of tests/sensing/dense_evidence.hpp for frames of
// up to 6 leaves. Random trees and evidence come from RapidCheck (fixed seed).
#include "spar/sensing/pseiki/hierarchical_evidence.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <vector>

#include "spar/sensing/error.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/sensing/dense_evidence.hpp"

namespace spar::sensing::pseiki {
namespace {

constexpr double kBeliefTolerance = 1e-10;

// A random strict hierarchy with `leaves` leaves (the root has at least two children, so no node
// is the whole frame) and up to `pieces` pieces of evidence on random non-root nodes: simple
// support for, against, or both (dichotomous), strengths up to 0.95.
HypothesisTree random_tree(int leaves, int pieces) {
  HypothesisTree tree;
  std::vector<int> open = {tree.add_node(0, "n1"), tree.add_node(0, "n2")};
  // Grow by giving a random leaf two or more children until the frame is large enough.
  while (static_cast<int>(tree.leaves().size()) < leaves) {
    const std::vector<int> current = tree.leaves();
    const int at =
        current[static_cast<std::size_t>(*rc::gen::inRange(0, static_cast<int>(current.size())))];
    const int kids = *rc::gen::inRange(2, 4);
    for (int k = 0; k < kids; ++k)
      tree.add_node(at, std::string("n").append(std::to_string(tree.size())));
  }
  const int count = *rc::gen::inRange(0, pieces + 1);
  for (int i = 0; i < count; ++i) {
    const int node = *rc::gen::inRange(1, tree.size());
    const double s = *rc::gen::inRange(0, 951) / 1000.0;
    switch (*rc::gen::inRange(0, 3)) {
      case 0:
        tree.add_for(node, s);
        break;
      case 1:
        tree.add_against(node, s);
        break;
      default: {
        const double t = *rc::gen::inRange(0, 1001) / 1000.0 * (1 - s);
        tree.add_evidence(node, s, t);
      }
    }
  }
  return tree;
}

RC_GTEST_PROP(HierarchicalEvidence, EveryNodesBeliefAndPlausibilityAreDempstersRule, ()) {
  const HypothesisTree tree = random_tree(*rc::gen::inRange(2, 40), 30);
  const TreeBeliefs got = tree.combine();
  const std::vector<MassFunction> sources = tree.mass_functions();
  const Combination want = combine(sources, static_cast<int>(tree.leaves().size()));
  RC_ASSERT(std::abs(got.conflict - want.conflict) <= kBeliefTolerance);
  for (int node = 0; node < tree.size(); ++node) {
    const FocalSet set = tree.leaf_set(node);
    RC_ASSERT(std::abs(got.belief[static_cast<std::size_t>(node)] - want.mass.belief(set)) <=
              kBeliefTolerance);
    RC_ASSERT(std::abs(got.plausibility[static_cast<std::size_t>(node)] -
                       want.mass.plausibility(set)) <= kBeliefTolerance);
  }
}

RC_GTEST_PROP(HierarchicalEvidence, SmallFramesMatchTheDenseBruteForce, ()) {
  const HypothesisTree tree = random_tree(*rc::gen::inRange(2, 7), 12);
  const int n = static_cast<int>(tree.leaves().size());
  RC_PRE(n <= 6);
  const TreeBeliefs got = tree.combine();
  // Fold the dense rule over the pieces, tracking the unnormalised mass of the non-empty sets.
  Dense joint = dense(MassFunction::vacuous(n));
  double kept = 1;  // prod (1 - K_i)
  for (const MassFunction& source : tree.mass_functions()) {
    const DenseCombination step = brute_dempster(joint, dense(source));
    joint = step.mass;
    kept *= 1 - step.conflict;
  }
  RC_ASSERT(std::abs(got.conflict - (1 - kept)) <= kBeliefTolerance);
  for (int node = 0; node < tree.size(); ++node) {
    unsigned mask = 0;
    for (const int x : tree.leaf_set(node).members()) mask |= 1U << x;
    RC_ASSERT(std::abs(got.belief[static_cast<std::size_t>(node)] - brute_belief(joint, mask)) <=
              kBeliefTolerance);
    RC_ASSERT(std::abs(got.plausibility[static_cast<std::size_t>(node)] -
                       brute_plausibility(joint, mask)) <= kBeliefTolerance);
  }
}

// With evidence on singletons only (Barnett's case) a lone simple support gives its strength as
// the belief, and two competing ones share by Dempster's normalisation.
TEST(HierarchicalEvidence, BarnettsCaseByHand) {
  HypothesisTree tree;
  const int a = tree.add_node(0, "a"), b = tree.add_node(0, "b");
  tree.add_node(0, "none");
  tree.add_for(a, 0.6);
  EXPECT_NEAR(tree.combine().belief[static_cast<std::size_t>(a)], 0.6, 1e-15);
  tree.add_for(b, 0.5);
  const TreeBeliefs both = tree.combine();
  EXPECT_NEAR(both.conflict, 0.3, 1e-15);
  EXPECT_NEAR(both.belief[static_cast<std::size_t>(a)], 0.6 * 0.5 / 0.7, 1e-15);
  EXPECT_NEAR(both.belief[static_cast<std::size_t>(b)], 0.4 * 0.5 / 0.7, 1e-15);
  EXPECT_NEAR(both.plausibility[static_cast<std::size_t>(a)], 0.5 / 0.7, 1e-15);
}

// Doubt about an internal node (an object) lowers the belief in each of its leaves (its edges).
TEST(HierarchicalEvidence, DoubtAboutAParentLowersItsLeaves) {
  HypothesisTree tree;
  const int block = tree.add_node(0, "block");
  const int e1 = tree.add_node(block, "block/e1");
  tree.add_node(block, "block/e2");
  tree.add_node(0, "none");
  tree.add_for(e1, 0.8);
  const double before = tree.combine().belief[static_cast<std::size_t>(e1)];
  tree.add_against(block, 0.3);
  const TreeBeliefs after = tree.combine();
  EXPECT_NEAR(after.conflict, 0.24, 1e-15);
  EXPECT_NEAR(after.belief[static_cast<std::size_t>(e1)], 0.8 * 0.7 / 0.76, 1e-15);
  EXPECT_LT(after.belief[static_cast<std::size_t>(e1)], before);
}

TEST(HierarchicalEvidence, MistakesAreNamed) {
  HypothesisTree tree;
  const int a = tree.add_node(0, "a");
  tree.add_node(0, "b");
  EXPECT_THROW_MESSAGE(tree.add_for(a, 1.5),
                       "the support for node 1 ('a') must be in [0, 1], got 1.5");
  EXPECT_THROW_MESSAGE(tree.add_evidence(a, 0.5, 0.75),
                       "the supports for and against node 1 ('a') sum to 1.25 > 1");
  EXPECT_THROW_MESSAGE(tree.add_for(0, 0.5), "evidence about the whole frame says nothing");
  EXPECT_THROW_MESSAGE(tree.add_node(7, "x"), "no node 7 (it has 3)");
  tree.add_for(a, 1.0);
  tree.add_against(a, 1.0);
  EXPECT_THROW_MESSAGE((void)tree.combine(), "total conflict (K = 1)");
}

}  // namespace
}  // namespace spar::sensing::pseiki
