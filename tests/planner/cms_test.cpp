// Tests of planner/cms/: the ordering graph (acyclic, transitive closure, linearizations) and the
// binary constraint network (arc consistency, search within a budget, codesignation, labelings),
// each against brute force on small random instances.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <functional>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include "spar/planner/cms/constraint_network.hpp"
#include "spar/planner/cms/error.hpp"
#include "spar/planner/cms/internal/bitset.hpp"
#include "spar/planner/cms/ordering_graph.hpp"

namespace spar::planner::cms {
namespace {

using Arcs = std::vector<std::pair<int, int>>;
using Orders = std::vector<std::vector<int>>;

OrderingGraph graph_with(int steps, const Arcs& arcs) {
  OrderingGraph graph;
  for (int step = 0; step < steps; ++step) graph.add_step();
  for (const auto& [a, b] : arcs) EXPECT_TRUE(graph.add_before(a, b));
  return graph;
}

Orders all_orders(const OrderingGraph& graph) {
  Linearizations orders(graph);
  Orders result;
  while (std::optional<std::vector<int>> order = orders.next()) result.push_back(*order);
  return result;
}

// ---------------------------------------------------------------------------------------------
// OrderingGraph

TEST(OrderingGraph, AddStepReturnsConsecutiveIds) {
  OrderingGraph graph;
  EXPECT_EQ(graph.add_step(), 0);
  EXPECT_EQ(graph.add_step(), 1);
  EXPECT_EQ(graph.add_step(), 2);
  EXPECT_EQ(graph.step_count(), 3);
  EXPECT_FALSE(graph.precedes(0, 1));
}

TEST(OrderingGraph, PrecedesIsTransitiveAndStrict) {
  const OrderingGraph graph = graph_with(4, {{0, 1}, {1, 2}});
  EXPECT_TRUE(graph.precedes(0, 2));
  EXPECT_FALSE(graph.precedes(2, 0));
  EXPECT_FALSE(graph.precedes(1, 1));
  EXPECT_FALSE(graph.precedes(0, 3));
  EXPECT_EQ(graph.successors(0), (std::vector<int>{1, 2}));
  EXPECT_EQ(graph.predecessors(2), (std::vector<int>{0, 1}));
  graph.check_invariants();
}

TEST(OrderingGraph, CycleAndSelfLoopAreRefusedLeavingGraphUnchanged) {
  OrderingGraph graph = graph_with(3, {{0, 1}, {1, 2}});
  const OrderingGraph before = graph;
  EXPECT_FALSE(graph.add_before(2, 0));
  EXPECT_FALSE(graph.add_before(1, 1));
  EXPECT_EQ(graph, before);
}

TEST(OrderingGraph, ArcsAreKeptAsPostedOnceEachEvenWhenImplied) {
  OrderingGraph graph = graph_with(3, {{0, 1}, {1, 2}});
  EXPECT_TRUE(graph.add_before(0, 2));  // implied, still recorded
  EXPECT_TRUE(graph.add_before(0, 1));  // duplicate, recorded once
  EXPECT_EQ(graph.arcs(), (Arcs{{0, 1}, {1, 2}, {0, 2}}));
  EXPECT_EQ(graph.transitive_reduction(), (Arcs{{0, 1}, {1, 2}}));
  graph.check_invariants();
}

TEST(OrderingGraph, PossiblyBetweenIsTheThreatTest) {
  // 0 -> 1 -> 3, 2 unordered.
  const OrderingGraph graph = graph_with(4, {{0, 1}, {1, 3}});
  EXPECT_TRUE(graph.possibly_between(2, 0, 3));
  EXPECT_TRUE(graph.possibly_between(1, 0, 3));
  EXPECT_FALSE(graph.possibly_between(3, 0, 1));  // 3 is after 1
  EXPECT_FALSE(graph.possibly_between(0, 1, 3));  // 0 is before 1
  EXPECT_FALSE(graph.possibly_between(2, 3, 0));  // 3 cannot come before 0
  EXPECT_FALSE(graph.possibly_between(0, 0, 3));  // a step is not between itself and another
}

TEST(OrderingGraph, ClosureSurvivesGrowingPastWordBoundaries) {
  // A chain grown in two rounds across the 64- and 128-step row widths.
  OrderingGraph graph;
  for (int step = 0; step < 70; ++step) graph.add_step();
  for (int step = 0; step + 1 < 70; ++step) EXPECT_TRUE(graph.add_before(step, step + 1));
  for (int step = 70; step < 140; ++step) graph.add_step();
  for (int step = 69; step + 1 < 140; ++step) EXPECT_TRUE(graph.add_before(step, step + 1));
  EXPECT_TRUE(graph.precedes(0, 139));
  EXPECT_TRUE(graph.precedes(63, 64));
  EXPECT_FALSE(graph.precedes(139, 0));
  EXPECT_EQ(graph.successors(0).size(), 139U);
  EXPECT_EQ(graph.predecessors(139).size(), 139U);
  EXPECT_EQ(graph.transitive_reduction().size(), 139U);
  EXPECT_EQ(count_linearizations(graph, 5).count, 1U);
  graph.check_invariants();
}

TEST(OrderingGraph, UnknownStepThrowsNamingIt) {
  OrderingGraph graph = graph_with(2, {});
  try {
    (void)graph.add_before(0, 5);
    FAIL() << "no exception";
  } catch (const CmsError& error) {
    EXPECT_STREQ(error.what(), "ordering graph: step 5 does not exist (the graph has 2 steps)");
  }
  EXPECT_THROW((void)graph.precedes(-1, 0), spar::Error);
}

TEST(Linearizations, ChainHasOneOrder) {
  EXPECT_EQ(all_orders(graph_with(3, {{2, 1}, {1, 0}})), (Orders{{2, 1, 0}}));
}

TEST(Linearizations, UnorderedStepsGiveAllPermutationsInLexicographicOrder) {
  EXPECT_EQ(all_orders(graph_with(3, {})),
            (Orders{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}));
}

TEST(Linearizations, EmptyGraphHasTheEmptyOrder) {
  EXPECT_EQ(all_orders(OrderingGraph{}), (Orders{{}}));
}

TEST(Linearizations, EnumeratorIsIndependentOfLaterChangesAndStaysDone) {
  OrderingGraph graph = graph_with(2, {});
  Linearizations orders(graph);
  EXPECT_TRUE(graph.add_before(1, 0));
  EXPECT_EQ(orders.next(), (std::vector<int>{0, 1}));
  EXPECT_EQ(orders.next(), (std::vector<int>{1, 0}));
  EXPECT_EQ(orders.next(), std::nullopt);
  EXPECT_EQ(orders.next(), std::nullopt);
}

TEST(Linearizations, CountStopsAtTheLimit) {
  const OrderingGraph graph = graph_with(4, {{0, 1}});  // 4!/2 = 12 orders
  const LinearizationCount all = count_linearizations(graph, 100);
  EXPECT_EQ(all.count, 12U);
  EXPECT_FALSE(all.limit_reached);
  const LinearizationCount exact = count_linearizations(graph, 12);
  EXPECT_EQ(exact.count, 12U);
  EXPECT_FALSE(exact.limit_reached);
  const LinearizationCount limited = count_linearizations(graph, 5);
  EXPECT_EQ(limited.count, 5U);
  EXPECT_TRUE(limited.limit_reached);
}

// Random prior_to requests on up to 7 steps, checked against a reachability search over the
// accepted arcs after every request.
RC_GTEST_PROP(OrderingGraph, MatchesReachabilityAndStaysAcyclic, ()) {
  const int n = *rc::gen::inRange(1, 8);
  OrderingGraph graph;
  for (int step = 0; step < n; ++step) graph.add_step();
  Arcs accepted;
  const auto reaches = [&](int from, int to) {  // path of length >= 1 over accepted arcs
    std::vector<bool> seen(static_cast<std::size_t>(n), false);
    std::vector<int> stack{from};
    while (!stack.empty()) {
      const int x = stack.back();
      stack.pop_back();
      for (const auto& [a, b] : accepted) {
        if (a == x && !seen[static_cast<std::size_t>(b)]) {
          seen[static_cast<std::size_t>(b)] = true;
          stack.push_back(b);
        }
      }
    }
    return static_cast<bool>(seen[static_cast<std::size_t>(to)]);
  };
  const int requests = *rc::gen::inRange(0, 16);
  for (int request = 0; request < requests; ++request) {
    const int a = *rc::gen::inRange(0, n);
    const int b = *rc::gen::inRange(0, n);
    const bool cycle = a == b || reaches(b, a);
    const OrderingGraph before = graph;
    RC_ASSERT(graph.add_before(a, b) == !cycle);
    if (cycle) {
      RC_ASSERT(graph == before);
    } else {
      accepted.emplace_back(a, b);
    }
    graph.check_invariants();
    for (int x = 0; x < n; ++x) {
      for (int y = 0; y < n; ++y) RC_ASSERT(graph.precedes(x, y) == reaches(x, y));
    }
  }
  // possibly_between(c, a, b) says exactly whether prior_to(a, c) and prior_to(c, b) both fit.
  for (int c = 0; c < n; ++c) {
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        OrderingGraph trial = graph;
        const bool fits = trial.add_before(a, c) && trial.add_before(c, b);
        RC_ASSERT(graph.possibly_between(c, a, b) == fits);
      }
    }
  }
  // The transitive reduction has the same closure, and every arc of it is needed.
  const Arcs reduction = graph.transitive_reduction();
  for (std::size_t skip = 0; skip <= reduction.size(); ++skip) {
    OrderingGraph rebuilt;
    for (int step = 0; step < n; ++step) rebuilt.add_step();
    for (std::size_t i = 0; i < reduction.size(); ++i) {
      if (i != skip) RC_ASSERT(rebuilt.add_before(reduction[i].first, reduction[i].second));
    }
    bool same = true;
    for (int x = 0; x < n; ++x) {
      for (int y = 0; y < n; ++y) same = same && rebuilt.precedes(x, y) == graph.precedes(x, y);
    }
    RC_ASSERT(same == (skip == reduction.size()));
  }
}

// On up to 6 steps, the enumerator yields exactly the permutations that respect every arc, in
// lexicographic order (std::next_permutation's order, filtered).
RC_GTEST_PROP(Linearizations, AreExactlyTheTopologicalOrdersInLexicographicOrder, ()) {
  const int n = *rc::gen::inRange(0, 7);
  OrderingGraph graph;
  for (int step = 0; step < n; ++step) graph.add_step();
  const int requests = n == 0 ? 0 : *rc::gen::inRange(0, 10);
  for (int request = 0; request < requests; ++request) {
    (void)graph.add_before(*rc::gen::inRange(0, n), *rc::gen::inRange(0, n));
  }
  Orders expected;
  std::vector<int> permutation(static_cast<std::size_t>(n));
  std::iota(permutation.begin(), permutation.end(), 0);
  do {
    bool respects = true;
    for (const auto& [a, b] : graph.arcs()) {
      respects = respects && std::find(permutation.begin(), permutation.end(), a) <
                                 std::find(permutation.begin(), permutation.end(), b);
    }
    if (respects) expected.push_back(permutation);
  } while (std::next_permutation(permutation.begin(), permutation.end()));
  RC_ASSERT(all_orders(graph) == expected);
  const LinearizationCount count = count_linearizations(graph, 10);
  RC_ASSERT(count.count == std::min<std::size_t>(expected.size(), 10));
  RC_ASSERT(count.limit_reached == (expected.size() > 10));
}

// ---------------------------------------------------------------------------------------------
// BitMatrix (the arcs' storage)

// The block transpose agrees with the definition on shapes that cut 64 x 64 blocks every way.
RC_GTEST_PROP(BitMatrix, TransposeSwapsEveryBit, ()) {
  const int rows = *rc::gen::inRange(1, 200);
  const int columns = *rc::gen::inRange(1, 200);
  internal::BitMatrix matrix(rows, columns);
  const int density = *rc::gen::inRange(1, 100);
  std::uint64_t state = *rc::gen::arbitrary<std::uint64_t>() | 1U;  // xorshift: cheap bits
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      state ^= state << 13;
      state ^= state >> 7;
      state ^= state << 17;
      if (static_cast<int>(state % 100) < density) matrix.set(row, column);
    }
  }
  const internal::BitMatrix transposed = matrix.transposed();
  RC_ASSERT(transposed.rows() == columns);
  RC_ASSERT(transposed.columns() == rows);
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      RC_ASSERT(transposed.test(column, row) == matrix.test(row, column));
    }
  }
  RC_ASSERT(transposed.transposed() == matrix);  // also: padding bits stay zero
}

// ---------------------------------------------------------------------------------------------
// ConstraintNetwork

AllowedPairs pairs_of(int rows, int columns, const Arcs& allowed) {
  AllowedPairs pairs(rows, columns);
  for (const auto& [row, column] : allowed) pairs.allow(row, column);
  return pairs;
}

AllowedPairs different(int domain) {
  AllowedPairs pairs(domain, domain);
  for (int x = 0; x < domain; ++x) {
    for (int y = 0; y < domain; ++y) {
      if (x != y) pairs.allow(x, y);
    }
  }
  return pairs;
}

// `count` variables over `domain` labels, pairwise different except the pair (count-2, count-1):
// arc consistent, and consistent iff count <= domain.
ConstraintNetwork nearly_all_different(int count, int domain) {
  ConstraintNetwork network;
  std::vector<int> all(static_cast<std::size_t>(domain));
  std::iota(all.begin(), all.end(), 0);
  for (int var = 0; var < count; ++var) network.add_variable("v", domain, all);
  for (int x = 0; x < count; ++x) {
    for (int y = x + 1; y < count; ++y) {
      if (x == count - 2 && y == count - 1) continue;
      EXPECT_EQ(network.post(x, y, different(domain)), Consistency::kConsistent);
    }
  }
  return network;
}

TEST(ConstraintNetwork, AddVariableKeepsItsInitialLabels) {
  ConstraintNetwork network;
  EXPECT_EQ(network.add_variable("?grasp", 5, {4, 1, 1}), 0);
  EXPECT_EQ(network.add_variable("?pose", 2, {0}), 1);
  EXPECT_EQ(network.labels(0), (std::vector<int>{1, 4}));
  EXPECT_EQ(network.name(1), "?pose");
  EXPECT_EQ(network.domain_size(0), 5);
  EXPECT_EQ(network.representative(1), 1);
  EXPECT_TRUE(network.has_label(0, 4));
  EXPECT_FALSE(network.has_label(0, 0));
  EXPECT_FALSE(network.has_label(0, 7));
  network.check_invariants();
}

TEST(ConstraintNetwork, MalformedRequestsThrowWithMessages) {
  ConstraintNetwork network;
  EXPECT_THROW(network.add_variable("?g", 0, {}), CmsError);
  try {
    network.add_variable("?g", 3, {3});
    FAIL() << "no exception";
  } catch (const CmsError& error) {
    EXPECT_STREQ(error.what(), "variable ?g: initial label 3 is outside its domain 0..2");
  }
  EXPECT_THROW(network.add_variable("?g", 3, {}), CmsError);
  const int grasp = network.add_variable("?grasp", 3, {0, 1, 2});
  const int pose = network.add_variable("?pose", 2, {0, 1});
  try {
    (void)network.post(grasp, pose, AllowedPairs(2, 3));
    FAIL() << "no exception";
  } catch (const CmsError& error) {
    EXPECT_STREQ(error.what(),
                 "post ?grasp, ?pose: allowed pairs are 2 x 3, the domains are 3 x 2");
  }
  try {
    (void)network.unify(grasp, pose);
    FAIL() << "no exception";
  } catch (const CmsError& error) {
    EXPECT_STREQ(error.what(), "unify ?grasp with ?pose: their domains differ (3 and 2 labels)");
  }
  EXPECT_THROW((void)network.restrict(pose, {2}), CmsError);
  EXPECT_THROW((void)network.labels(9), CmsError);
  EXPECT_THROW(AllowedPairs(2, 2).allow(2, 0), CmsError);
}

TEST(ConstraintNetwork, RestrictIntersectsTheLabelSet) {
  ConstraintNetwork network;
  const int pose = network.add_variable("?pose", 6, {0, 1, 2, 3});
  EXPECT_EQ(network.restrict(pose, {1, 3, 5}), Consistency::kConsistent);
  EXPECT_EQ(network.labels(pose), (std::vector<int>{1, 3}));
  network.check_invariants();
}

TEST(ConstraintNetwork, RestrictToNothingIsRefusedLeavingNetworkUnchanged) {
  ConstraintNetwork network;
  const int pose = network.add_variable("?pose", 6, {0, 1});
  const ConstraintNetwork before = network;
  EXPECT_EQ(network.restrict(pose, {4, 5}), Consistency::kInconsistent);
  EXPECT_EQ(network, before);
}

TEST(ConstraintNetwork, PostPrunesBothEndsByArcConsistency) {
  ConstraintNetwork network;
  const int grasp = network.add_variable("?grasp", 4, {0, 1, 2, 3});
  const int pose = network.add_variable("?pose", 3, {0, 1, 2});
  EXPECT_EQ(network.post(grasp, pose, pairs_of(4, 3, {{1, 2}, {3, 2}})), Consistency::kConsistent);
  EXPECT_EQ(network.labels(grasp), (std::vector<int>{1, 3}));
  EXPECT_EQ(network.labels(pose), (std::vector<int>{2}));
  network.check_invariants();
}

TEST(ConstraintNetwork, RestrictPropagatesAlongAChainAndPrunesArcPairs) {
  // x - y - z with equality arcs: restricting x reaches z.
  ConstraintNetwork network;
  for (int var = 0; var < 3; ++var) network.add_variable("v", 3, {0, 1, 2});
  const AllowedPairs equal = pairs_of(3, 3, {{0, 0}, {1, 1}, {2, 2}});
  EXPECT_EQ(network.post(0, 1, equal), Consistency::kConsistent);
  EXPECT_EQ(network.post(2, 1, equal), Consistency::kConsistent);
  EXPECT_EQ(network.restrict(0, {1, 2}), Consistency::kConsistent);
  EXPECT_EQ(network.labels(2), (std::vector<int>{1, 2}));
  const std::vector<ArcPairs> arcs = network.arcs();
  ASSERT_EQ(arcs.size(), 2U);
  EXPECT_EQ(arcs[0], (ArcPairs{0, 1, {{1, 1}, {2, 2}}}));
  EXPECT_EQ(arcs[1], (ArcPairs{1, 2, {{1, 1}, {2, 2}}}));
  network.check_invariants();
}

TEST(ConstraintNetwork, SecondArcBetweenTheSameVariablesIntersects) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 2, {0, 1});
  const int b = network.add_variable("b", 3, {0, 1, 2});
  EXPECT_EQ(network.post(a, b, pairs_of(2, 3, {{0, 0}, {0, 1}, {1, 2}})), Consistency::kConsistent);
  // Posted the other way round: (b, a).
  EXPECT_EQ(network.post(b, a, pairs_of(3, 2, {{1, 0}, {2, 1}, {2, 0}})), Consistency::kConsistent);
  const std::vector<ArcPairs> arcs = network.arcs();
  ASSERT_EQ(arcs.size(), 1U);
  EXPECT_EQ(arcs[0], (ArcPairs{a, b, {{0, 1}, {1, 2}}}));
  EXPECT_EQ(network.labels(b), (std::vector<int>{1, 2}));
  network.check_invariants();
}

TEST(ConstraintNetwork, InconsistentPostIsRefusedLeavingNetworkUnchanged) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 2, {0, 1});
  const int b = network.add_variable("b", 2, {0, 1});
  EXPECT_EQ(network.post(a, b, pairs_of(2, 2, {{0, 0}, {1, 1}})), Consistency::kConsistent);
  EXPECT_EQ(network.restrict(a, {0}), Consistency::kConsistent);
  const ConstraintNetwork before = network;
  EXPECT_EQ(network.post(a, b, pairs_of(2, 2, {{0, 1}, {1, 0}})), Consistency::kInconsistent);
  EXPECT_EQ(network, before);
  // A refused new arc leaves no trace either.
  const int c = network.add_variable("c", 2, {1});
  const ConstraintNetwork with_c = network;
  EXPECT_EQ(network.post(c, b, pairs_of(2, 2, {{1, 1}})), Consistency::kInconsistent);
  EXPECT_EQ(network, with_c);
}

TEST(ConstraintNetwork, SearchFindsWhatArcConsistencyCannotSee) {
  // Three variables over two labels, pairwise different: every arc is consistent on its own.
  ConstraintNetwork network = nearly_all_different(3, 2);
  const ConstraintNetwork before = network;
  EXPECT_EQ(network.post(1, 2, different(2)), Consistency::kInconsistent);
  EXPECT_EQ(network, before);
}

TEST(ConstraintNetwork, BudgetExhaustionIsItsOwnVerdictAndChangesNothing) {
  // Pigeonhole: 7 variables, 6 labels; proving it needs far more than 10 nodes.
  ConstraintNetwork network = nearly_all_different(7, 6);
  const ConstraintNetwork before = network;
  EXPECT_EQ(network.post(5, 6, different(6), SearchBudget{10}), Consistency::kBudgetExhausted);
  EXPECT_EQ(network, before);
  EXPECT_EQ(network.post(5, 6, different(6), SearchBudget{1'000'000}), Consistency::kInconsistent);
  EXPECT_EQ(network, before);
  EXPECT_EQ(network.consistent(SearchBudget{1'000'000}), Consistency::kConsistent);
  EXPECT_EQ(network.consistent(SearchBudget{0}), Consistency::kBudgetExhausted);
}

// p - v - q, witness (0, 0, 0). The new arc v-p forbids (0, 0); v's other label 1 breaks the
// equality with q, so no single-variable repair works, yet the network is consistent: (1, 0, 1).
// `cycle` adds an arc p-q that allows everything.
ConstraintNetwork unrepairable(bool cycle) {
  ConstraintNetwork network;
  const int v = network.add_variable("v", 2, {0, 1});
  const int p = network.add_variable("p", 2, {0, 1});
  const int q = network.add_variable("q", 2, {0, 1});
  EXPECT_EQ(network.post(v, q, pairs_of(2, 2, {{0, 0}, {1, 1}})), Consistency::kConsistent);
  if (cycle) {
    EXPECT_EQ(network.post(p, q, pairs_of(2, 2, {{0, 0}, {0, 1}, {1, 0}, {1, 1}})),
              Consistency::kConsistent);
  }
  return network;
}

TEST(ConstraintNetwork, TreesAreDecidedWithoutSearchBudget) {
  ConstraintNetwork tree = unrepairable(false);
  EXPECT_EQ(tree.post(0, 1, pairs_of(2, 2, {{1, 0}, {0, 1}}), SearchBudget{0}),
            Consistency::kConsistent);
  tree.check_invariants();
  // With the cycle the same change needs the search.
  ConstraintNetwork cyclic = unrepairable(true);
  const ConstraintNetwork before = cyclic;
  EXPECT_EQ(cyclic.post(0, 1, pairs_of(2, 2, {{1, 0}, {0, 1}}), SearchBudget{0}),
            Consistency::kBudgetExhausted);
  EXPECT_EQ(cyclic, before);
  EXPECT_EQ(cyclic.post(0, 1, pairs_of(2, 2, {{1, 0}, {0, 1}}), SearchBudget{10}),
            Consistency::kConsistent);
  cyclic.check_invariants();
}

TEST(ConstraintNetwork, PredicateIsAskedOnlyForPairsOfCurrentLabels) {
  ConstraintNetwork network;
  const int grasp = network.add_variable("?grasp", 5, {0, 2, 4});
  const int pose = network.add_variable("?pose", 4, {1, 3});
  int calls = 0;
  const auto reachable = [&calls](int g, int p) {
    ++calls;
    return g + p == 5;
  };
  EXPECT_EQ(network.post(grasp, pose, reachable), Consistency::kConsistent);
  EXPECT_EQ(calls, 6);
  EXPECT_EQ(network.labels(grasp), (std::vector<int>{2, 4}));
  EXPECT_EQ(network.labels(pose), (std::vector<int>{1, 3}));
}

TEST(ConstraintNetwork, UnifyIntersectsLabelsAndMergesArcs) {
  ConstraintNetwork network;
  const int put_position = network.add_variable("?put", 3, {0, 1, 2});
  const int grasp = network.add_variable("?grasp", 2, {0, 1});
  const int pick_position = network.add_variable("?pick", 3, {1, 2});
  // grasp 0 works only in position 2, grasp 1 only in position 0.
  EXPECT_EQ(network.post(grasp, pick_position, pairs_of(2, 3, {{0, 2}, {1, 0}, {1, 1}})),
            Consistency::kConsistent);
  EXPECT_EQ(network.labels(grasp), (std::vector<int>{0, 1}));
  EXPECT_EQ(network.unify(pick_position, put_position), Consistency::kConsistent);
  EXPECT_EQ(network.representative(pick_position), put_position);
  EXPECT_EQ(network.representative(put_position), put_position);
  EXPECT_EQ(network.labels(pick_position), (std::vector<int>{1, 2}));
  EXPECT_EQ(network.labels(put_position), (std::vector<int>{1, 2}));
  // Restricting through either id acts on the merged variable, and its arc moved along.
  EXPECT_EQ(network.restrict(put_position, {2}), Consistency::kConsistent);
  EXPECT_EQ(network.labels(grasp), (std::vector<int>{0}));
  const std::vector<ArcPairs> arcs = network.arcs();
  ASSERT_EQ(arcs.size(), 1U);
  EXPECT_EQ(arcs[0], (ArcPairs{put_position, grasp, {{2, 0}}}));
  network.check_invariants();
  EXPECT_EQ(first_labelings(network, 10).labelings, (std::vector<Labeling>{{2, 0, 2}}));
}

TEST(ConstraintNetwork, UnifyMergesParallelArcsByIntersection) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 2, {0, 1});
  const int b = network.add_variable("b", 2, {0, 1});
  const int c = network.add_variable("c", 3, {0, 1, 2});
  EXPECT_EQ(network.post(a, c, pairs_of(2, 3, {{0, 0}, {0, 1}, {1, 2}})), Consistency::kConsistent);
  EXPECT_EQ(network.post(b, c, pairs_of(2, 3, {{0, 1}, {1, 0}, {1, 2}})), Consistency::kConsistent);
  EXPECT_EQ(network.unify(b, a), Consistency::kConsistent);
  const std::vector<ArcPairs> arcs = network.arcs();
  ASSERT_EQ(arcs.size(), 1U);
  EXPECT_EQ(arcs[0], (ArcPairs{a, c, {{0, 1}, {1, 2}}}));
  EXPECT_EQ(network.labels(c), (std::vector<int>{1, 2}));
  network.check_invariants();
}

TEST(ConstraintNetwork, ArcBetweenUnifiedVariablesKeepsOnlyItsDiagonal) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 3, {0, 1, 2});
  const int b = network.add_variable("b", 3, {0, 1, 2});
  EXPECT_EQ(network.post(a, b, pairs_of(3, 3, {{0, 0}, {1, 2}, {2, 2}})), Consistency::kConsistent);
  EXPECT_EQ(network.unify(a, b), Consistency::kConsistent);
  EXPECT_EQ(network.labels(b), (std::vector<int>{0, 2}));
  EXPECT_TRUE(network.arcs().empty());
  // A post between codesignated ids is the same diagonal restriction.
  EXPECT_EQ(network.post(b, a, pairs_of(3, 3, {{2, 2}, {0, 1}})), Consistency::kConsistent);
  EXPECT_EQ(network.labels(a), (std::vector<int>{2}));
  network.check_invariants();
}

TEST(ConstraintNetwork, ChainedUnifiesKeepTheSmallestIdAsTheOneRepresentative) {
  ConstraintNetwork network;
  for (int var = 0; var < 5; ++var) network.add_variable("p", 4, {0, 1, 2, 3});
  EXPECT_EQ(network.unify(4, 3), Consistency::kConsistent);
  EXPECT_EQ(network.unify(2, 1), Consistency::kConsistent);
  EXPECT_EQ(network.restrict(4, {1, 2, 3}), Consistency::kConsistent);  // through a member id
  EXPECT_EQ(network.restrict(1, {0, 1, 2}), Consistency::kConsistent);
  EXPECT_EQ(network.unify(4, 2), Consistency::kConsistent);  // merges the classes {3, 4}, {1, 2}
  for (const int var : {1, 2, 3, 4}) {
    EXPECT_EQ(network.representative(var), 1);
    EXPECT_EQ(network.labels(var), (std::vector<int>{1, 2}));
  }
  EXPECT_EQ(network.representative(0), 0);
  network.check_invariants();
  EXPECT_EQ(first_labelings(network, 10).labelings, (std::vector<Labeling>{{0, 1, 1, 1, 1},
                                                                           {0, 2, 2, 2, 2},
                                                                           {1, 1, 1, 1, 1},
                                                                           {1, 2, 2, 2, 2},
                                                                           {2, 1, 1, 1, 1},
                                                                           {2, 2, 2, 2, 2},
                                                                           {3, 1, 1, 1, 1},
                                                                           {3, 2, 2, 2, 2}}));
}

TEST(ConstraintNetwork, CouldUnifyNeedsASharedLabelOfTheSameDomain) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 4, {0, 1});
  const int b = network.add_variable("b", 4, {1, 2});
  const int c = network.add_variable("c", 4, {2, 3});
  const int d = network.add_variable("d", 3, {1});
  EXPECT_TRUE(network.could_unify(a, b));
  EXPECT_FALSE(network.could_unify(a, c));
  EXPECT_FALSE(network.could_unify(a, d));  // different domains
  EXPECT_EQ(network.unify(b, c), Consistency::kConsistent);
  EXPECT_FALSE(network.could_unify(a, c));  // c is now b's class, label 2 only
  EXPECT_TRUE(network.could_unify(c, b));
}

TEST(ConstraintNetwork, InconsistentUnifyIsRefusedLeavingNetworkUnchanged) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 3, {0, 1});
  const int b = network.add_variable("b", 3, {1, 2});
  const int c = network.add_variable("c", 2, {0, 1});
  EXPECT_EQ(network.post(a, c, pairs_of(3, 2, {{0, 0}, {1, 1}})), Consistency::kConsistent);
  EXPECT_EQ(network.post(b, c, pairs_of(3, 2, {{1, 0}, {2, 1}})), Consistency::kConsistent);
  const ConstraintNetwork before = network;
  // Shared label 1 needs c = 1 through a and c = 0 through b.
  EXPECT_EQ(network.unify(a, b), Consistency::kInconsistent);
  EXPECT_EQ(network, before);
  EXPECT_EQ(network.representative(b), b);
}

TEST(Labelings, AreEnumeratedLexicographicallyWithCodesignatedIdsFilledIn) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 3, {0, 1, 2});
  const int b = network.add_variable("b", 2, {0, 1});
  const int c = network.add_variable("c", 3, {0, 2});
  EXPECT_EQ(network.post(b, a, pairs_of(2, 3, {{0, 1}, {1, 0}, {1, 2}})), Consistency::kConsistent);
  EXPECT_EQ(network.unify(c, a), Consistency::kConsistent);
  const std::vector<Labeling> expected{{0, 1, 0}, {2, 1, 2}};
  EXPECT_EQ(first_labelings(network, 10).labelings, expected);
  EXPECT_EQ(first_labelings(network, 10).stop, LabelingBatch::Stop::kAll);
  const LabelingBatch one = first_labelings(network, 1);
  EXPECT_EQ(one.labelings, (std::vector<Labeling>{{0, 1, 0}}));
  EXPECT_EQ(one.stop, LabelingBatch::Stop::kLimitReached);
  EXPECT_EQ(first_labelings(network, 2).stop, LabelingBatch::Stop::kAll);
  const LabelingBatch starved = first_labelings(network, 10, SearchBudget{1});
  EXPECT_EQ(starved.stop, LabelingBatch::Stop::kBudgetExhausted);
  EXPECT_TRUE(starved.labelings.empty());
}

TEST(Labelings, BudgetCanRunOutMidwayAndStaysOut) {
  // Three free variables of two labels: eight labelings, a search tree of 2 + 4 + 8 = 14 nodes.
  // The first three labelings cost 3, 1 and 2 nodes.
  ConstraintNetwork network;
  for (int var = 0; var < 3; ++var) network.add_variable("v", 2, {0, 1});
  Labelings enumeration(network, SearchBudget{6});
  std::vector<Labeling> seen;
  while (std::optional<Labeling> labeling = enumeration.next()) seen.push_back(*labeling);
  EXPECT_TRUE(enumeration.budget_exhausted());
  EXPECT_EQ(seen, (std::vector<Labeling>{{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}));
  EXPECT_EQ(enumeration.next(), std::nullopt);
  EXPECT_EQ(first_labelings(network, 100, SearchBudget{14}).stop, LabelingBatch::Stop::kAll);
  const LabelingBatch short_one = first_labelings(network, 100, SearchBudget{13});
  EXPECT_EQ(short_one.stop, LabelingBatch::Stop::kBudgetExhausted);
  EXPECT_EQ(short_one.labelings.size(), 7U);
}

TEST(ConstraintNetwork, CopiesAreIndependentValues) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 3, {0, 1, 2});
  const int b = network.add_variable("b", 3, {0, 1, 2});
  EXPECT_EQ(network.post(a, b, pairs_of(3, 3, {{0, 1}, {1, 2}, {2, 0}})), Consistency::kConsistent);
  ConstraintNetwork branch = network;
  EXPECT_EQ(branch.restrict(a, {0}), Consistency::kConsistent);
  EXPECT_EQ(branch.unify(a, b), Consistency::kInconsistent);
  EXPECT_EQ(network.labels(a), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(network.arcs().front().pairs.size(), 3U);
  EXPECT_EQ(branch.labels(b), (std::vector<int>{1}));
  EXPECT_EQ(branch.arcs().front().pairs, (std::vector<std::pair<int, int>>{{0, 1}}));
}

TEST(Labelings, EnumeratorIsIndependentOfLaterChanges) {
  ConstraintNetwork network;
  const int a = network.add_variable("a", 2, {0, 1});
  Labelings enumeration(network);
  EXPECT_EQ(network.restrict(a, {1}), Consistency::kConsistent);
  EXPECT_EQ(enumeration.next(), (Labeling{0}));
  EXPECT_EQ(enumeration.next(), (Labeling{1}));
  EXPECT_EQ(enumeration.next(), std::nullopt);
  EXPECT_FALSE(enumeration.budget_exhausted());
}

TEST(Labelings, EmptyNetworkHasTheEmptyLabeling) {
  EXPECT_EQ(first_labelings(ConstraintNetwork{}, 5).labelings, (std::vector<Labeling>{{}}));
  EXPECT_EQ(ConstraintNetwork{}.consistent(), Consistency::kConsistent);
}

// The brute-force model of a network: every variable id with its domain and the constraints
// accepted so far, solved by plain depth-first search over all ids in id order, checking each
// constraint once both its ids are assigned (no propagation, no codesignation: independent of
// the code under test).
struct Model {
  std::vector<int> domains;
  std::vector<std::vector<int>> allowed_labels;  // per id: initial labels ∩ restrictions
  struct Binary {
    int a, b;
    AllowedPairs pairs;
  };
  std::vector<Binary> binaries;
  std::vector<std::pair<int, int>> equal;  // unified ids

  // Up to `limit` solutions, lexicographically.
  [[nodiscard]] std::vector<Labeling> solutions(std::size_t limit = SIZE_MAX) const {
    std::vector<Labeling> result;
    Labeling labeling(domains.size(), -1);
    extend(labeling, 0, limit, result);
    return result;
  }

 private:
  // True if every constraint among ids 0..last holds (those not involving `last` already did).
  [[nodiscard]] bool holds_up_to(const Labeling& labeling, int last) const {
    const auto at = [&](int var) { return labeling[static_cast<std::size_t>(var)]; };
    const std::vector<int>& labels = allowed_labels[static_cast<std::size_t>(last)];
    if (std::find(labels.begin(), labels.end(), at(last)) == labels.end()) return false;
    for (const Binary& binary : binaries) {
      if (std::max(binary.a, binary.b) == last &&
          !binary.pairs.allowed(at(binary.a), at(binary.b))) {
        return false;
      }
    }
    for (const auto& [a, b] : equal) {
      if (std::max(a, b) == last && at(a) != at(b)) return false;
    }
    return true;
  }
  void extend(Labeling& labeling, int depth, std::size_t limit, std::vector<Labeling>& out) const {
    if (out.size() >= limit) return;
    if (depth == static_cast<int>(domains.size())) {
      out.push_back(labeling);
      return;
    }
    for (int label = 0; label < domains[static_cast<std::size_t>(depth)]; ++label) {
      labeling[static_cast<std::size_t>(depth)] = label;
      if (holds_up_to(labeling, depth)) extend(labeling, depth + 1, limit, out);
    }
  }
};

std::vector<int> random_labels(int domain) {
  std::vector<int> labels;
  for (int label = 0; label < domain; ++label) {
    if (*rc::gen::inRange(0, 3) != 0) labels.push_back(label);
  }
  return labels;
}

AllowedPairs random_pairs(int rows, int columns) {
  AllowedPairs pairs(rows, columns);
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      if (*rc::gen::inRange(0, 3) != 0) pairs.allow(row, column);
    }
  }
  return pairs;
}

void check_against_model(int max_variables, int max_domain, int max_operations,
                         std::size_t compared_labelings) {
  const int variables = *rc::gen::inRange(3, max_variables + 1);
  ConstraintNetwork network;
  Model model;
  for (int var = 0; var < variables; ++var) {
    const int domain = *rc::gen::inRange(1, max_domain + 1);
    std::vector<int> labels = random_labels(domain);
    if (labels.empty()) labels.push_back(*rc::gen::inRange(0, domain));
    RC_ASSERT(network.add_variable("v" + std::to_string(var), domain, labels) == var);
    model.domains.push_back(domain);
    model.allowed_labels.push_back(labels);
  }
  const int operations = *rc::gen::inRange(1, max_operations + 1);
  for (int operation = 0; operation < operations; ++operation) {
    const SearchBudget budget{*rc::gen::element<std::uint64_t>(0, 2, 100'000)};
    const int a = *rc::gen::inRange(0, variables);
    const int b = *rc::gen::inRange(0, variables);
    Model next = model;
    const ConstraintNetwork before = network;
    Consistency verdict = Consistency::kInconsistent;
    switch (*rc::gen::inRange(0, 3)) {
      case 0: {
        const std::vector<int> labels = random_labels(model.domains[static_cast<std::size_t>(a)]);
        std::vector<int>& kept = next.allowed_labels[static_cast<std::size_t>(a)];
        std::erase_if(kept, [&](int label) {
          return std::find(labels.begin(), labels.end(), label) == labels.end();
        });
        verdict = network.restrict(a, labels, budget);
        break;
      }
      case 1: {
        AllowedPairs pairs = random_pairs(model.domains[static_cast<std::size_t>(a)],
                                          model.domains[static_cast<std::size_t>(b)]);
        verdict = network.post(a, b, pairs, budget);
        next.binaries.push_back({a, b, std::move(pairs)});
        break;
      }
      default: {
        if (model.domains[static_cast<std::size_t>(a)] !=
            model.domains[static_cast<std::size_t>(b)]) {
          RC_ASSERT_THROWS_AS((void)network.unify(a, b), CmsError);
          continue;
        }
        verdict = network.unify(a, b, budget);
        next.equal.emplace_back(a, b);
        break;
      }
    }
    const bool solvable = !next.solutions(1).empty();
    if (verdict == Consistency::kConsistent) {
      RC_ASSERT(solvable);
      model = std::move(next);
    } else {
      RC_ASSERT(network == before);
      RC_ASSERT(verdict == Consistency::kBudgetExhausted || !solvable);
      RC_ASSERT(verdict == Consistency::kInconsistent || budget.nodes < 100'000);
    }
    network.check_invariants();
    for (const Labeling& solution : model.solutions(compared_labelings)) {
      for (int var = 0; var < variables; ++var) {
        RC_ASSERT(network.has_label(var, solution[static_cast<std::size_t>(var)]));
      }
    }
  }
  RC_ASSERT(network.consistent() == Consistency::kConsistent);
  const LabelingBatch batch = first_labelings(network, compared_labelings);
  const std::vector<Labeling> expected = model.solutions(compared_labelings + 1);
  RC_ASSERT(batch.stop == (expected.size() > compared_labelings ? LabelingBatch::Stop::kLimitReached
                                                                : LabelingBatch::Stop::kAll));
  RC_ASSERT(batch.labelings ==
            std::vector<Labeling>(expected.begin(),
                                  expected.begin() + static_cast<std::ptrdiff_t>(std::min(
                                                         expected.size(), compared_labelings))));
}

// Random networks of 3-6 variables over domains of 1-5 labels, grown by random restricts, posts
// and unifies (some with a starvation budget). After every operation: its verdict agrees with
// brute force on the network with the operation applied (kBudgetExhausted is allowed only to
// refuse), a refused operation leaves the network equal to before, the invariants hold, and no
// label of any solution was pruned. At the end the labelings are exactly brute force's, in order.
RC_GTEST_PROP(ConstraintNetwork, AgreesWithBruteForce, ()) {
  check_against_model(6, 5, 9, 100'000);
}

// The same on larger networks (up to 10 variables, 20 operations), where arc consistency and the
// witness repair leave more to the search; the first 30 labelings are compared.
RC_GTEST_PROP(ConstraintNetwork, LargerNetworksAgreeWithBruteForce, ()) {
  check_against_model(10, 4, 20, 30);
}

// Domains past one 64-bit word (3 variables of up to 70 labels), so that arc consistency
// and the search's revisions read multi-word rows both ways (by rows of u, by the union of v's).
RC_GTEST_PROP(ConstraintNetwork, MultiWordDomainsAgreeWithBruteForce, ()) {
  check_against_model(3, 70, 4, 10);
}

// Tree-structured networks (each variable's arcs go to one earlier variable) are decided by arc
// consistency: with no search budget at all, posts and restricts are never kBudgetExhausted, and
// their verdicts agree with brute force.
RC_GTEST_PROP(ConstraintNetwork, TreesNeverExhaustTheBudget, ()) {
  const int variables = *rc::gen::inRange(2, 9);
  ConstraintNetwork network;
  Model model;
  std::vector<int> parent(static_cast<std::size_t>(variables), -1);
  for (int var = 0; var < variables; ++var) {
    const int domain = *rc::gen::inRange(2, 4);
    std::vector<int> labels = random_labels(domain);
    if (labels.empty()) labels.push_back(0);
    network.add_variable("v", domain, labels);
    model.domains.push_back(domain);
    model.allowed_labels.push_back(labels);
    // Few hubs, so variables have several neighbours whose labels a repair must all respect.
    if (var > 0) parent[static_cast<std::size_t>(var)] = *rc::gen::inRange(0, std::min(var, 2));
  }
  const int operations = *rc::gen::inRange(1, 16);
  for (int operation = 0; operation < operations; ++operation) {
    const int var = *rc::gen::inRange(0, variables);
    const int domain = model.domains[static_cast<std::size_t>(var)];
    Model next = model;
    Consistency verdict = Consistency::kInconsistent;
    if (var > 0 && *rc::gen::inRange(0, 3) != 0) {
      const int up = parent[static_cast<std::size_t>(var)];
      AllowedPairs pairs = random_pairs(domain, model.domains[static_cast<std::size_t>(up)]);
      verdict = network.post(var, up, pairs, SearchBudget{0});
      next.binaries.push_back({var, up, std::move(pairs)});
    } else {
      const std::vector<int> labels = random_labels(domain);
      std::erase_if(next.allowed_labels[static_cast<std::size_t>(var)], [&](int label) {
        return std::find(labels.begin(), labels.end(), label) == labels.end();
      });
      verdict = network.restrict(var, labels, SearchBudget{0});
    }
    RC_ASSERT(verdict != Consistency::kBudgetExhausted);
    RC_ASSERT((verdict == Consistency::kConsistent) == !next.solutions(1).empty());
    if (verdict == Consistency::kConsistent) model = std::move(next);
    network.check_invariants();
  }
}

}  // namespace
}  // namespace spar::planner::cms
