// OrderingGraph: SPAR's ordering constraints (seed 001, "Ordering Constraints in Operational
// Planning"): one node per plan step, an arc a -> b for each prior_to(a, b). The ordering is
// consistent exactly when the graph is acyclic, and the graph never holds a cycle: add_before
// refuses (returns false, graph unchanged) an arc that would close one.
//
// The transitive closure is kept incrementally as bit rows (successors and predecessors of every
// step), so precedes() is O(1) and adding an arc costs O(n²/64). The graph is a plain copyable
// value (the planner copies it for every branch of its search): two flat bit matrices and the
// arc list, about 1 µs to copy at 100 steps.
//
// Linearizations enumerates the total orders compatible with the graph lazily, lexicographically
// smallest first (comparing step ids position by position).
//
// Example:
//   OrderingGraph graph;
//   const int start = graph.add_step(), pick = graph.add_step(), place = graph.add_step();
//   graph.add_before(start, pick);                 // true
//   graph.add_before(pick, place);                 // true
//   assert(graph.precedes(start, place) && !graph.add_before(place, start));
//   Linearizations orders(graph);  // orders.next() == {0, 1, 2}, then std::nullopt
#pragma once

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "spar/planner/cms/internal/bitset.hpp"

namespace spar::planner::cms {

class OrderingGraph {
 public:
  // Adds an unordered step and returns its id (0, 1, 2, ... in order of addition).
  int add_step();
  [[nodiscard]] int step_count() const { return successors_.rows(); }

  // SPAR's prior_to(a, b): a must be executed before b. Returns false and leaves the graph
  // unchanged if that would create a cycle (b already precedes a, or a == b). Posting an arc
  // that is already implied is accepted and recorded. Throws CmsError for an unknown step id.
  bool add_before(int a, int b);

  // a is ordered strictly before b (through any chain of arcs).
  [[nodiscard]] bool precedes(int a, int b) const;
  // a could still be ordered before b: a != b and b does not precede a.
  [[nodiscard]] bool possibly_before(int a, int b) const;
  // c could be ordered after a and before b at once (prior_to(a, c) and prior_to(c, b) can both
  // be added): the threat test of goal protection when a establishes a condition b needs.
  [[nodiscard]] bool possibly_between(int c, int a, int b) const;

  // Steps ordered before / after `step`, ascending.
  [[nodiscard]] std::vector<int> predecessors(int step) const;
  [[nodiscard]] std::vector<int> successors(int step) const;

  // The arcs as posted (duplicates once), in posting order: for printing the plan's constraints.
  [[nodiscard]] const std::vector<std::pair<int, int>>& arcs() const { return arcs_; }
  // The fewest arcs with the same ordering (a -> b where nothing lies between), sorted: for
  // drawing.
  [[nodiscard]] std::vector<std::pair<int, int>> transitive_reduction() const;

  // Checks the representation invariants below (closure = reachability over arcs_, irreflexive,
  // predecessor rows the transpose of successor rows); throws std::logic_error naming the first
  // broken one. O(n³/64); for tests.
  void check_invariants() const;

  friend bool operator==(const OrderingGraph&, const OrderingGraph&) = default;

 private:
  friend class Linearizations;
  void check_step(int step) const;

  // arcs_: every accepted prior_to(a, b), each pair once, in posting order.
  std::vector<std::pair<int, int>> arcs_;
  // Square step_count() x step_count() bit matrices (flat, so a copy is two memcpys): row a of
  // successors_ holds b iff a path a -> ... -> b of arcs_ exists (length >= 1); never a itself
  // (acyclic). Row b of predecessors_ holds a iff row a of successors_ holds b.
  internal::BitMatrix successors_;
  internal::BitMatrix predecessors_;
};

// Lazy, deterministic enumeration of the graph's topological orders (its linearizations),
// lexicographically smallest first. Holds its own copy of what it needs: the graph may change or
// die while this lives (later changes are not seen). A graph with n unordered steps has n!
// orders: stop early (count_linearizations takes a limit).
class Linearizations {
 public:
  explicit Linearizations(const OrderingGraph& graph);

  // The next order (each step id once, every arc respected), or std::nullopt after the last.
  [[nodiscard]] std::optional<std::vector<int>> next();

 private:
  // Index of the smallest step >= from that may come next when `placed_` are already placed, or -1.
  [[nodiscard]] int next_available(int from) const;

  internal::BitMatrix predecessors_;  // the graph's closure, copied
  std::vector<int> order_;            // the order returned last (empty before the first)
  internal::Bitset placed_;           // members of order_
  bool started_{false};
  bool finished_{false};
};

struct LinearizationCount {
  std::size_t count{0};       // the number of linearizations, or `limit` if there are more
  bool limit_reached{false};  // true iff there are more than `limit`
};

// Counts the linearizations by enumerating up to limit + 1 of them.
[[nodiscard]] LinearizationCount count_linearizations(const OrderingGraph& graph,
                                                      std::size_t limit);

}  // namespace spar::planner::cms
