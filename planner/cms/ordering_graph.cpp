#include "planner/cms/ordering_graph.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "planner/cms/error.hpp"

namespace spar::planner::cms {

namespace {

std::vector<int> members(const internal::Bitset& set) {
  std::vector<int> result;
  for (int bit = set.find_first(); bit >= 0; bit = set.find_next(bit + 1)) result.push_back(bit);
  return result;
}

}  // namespace

int OrderingGraph::add_step() {
  const int step = step_count();
  for (internal::Bitset& row : successors_) row.resize(step + 1);
  for (internal::Bitset& row : predecessors_) row.resize(step + 1);
  successors_.emplace_back(step + 1);
  predecessors_.emplace_back(step + 1);
  return step;
}

void OrderingGraph::check_step(int step) const {
  if (step < 0 || step >= step_count()) {
    throw CmsError("ordering graph: step " + std::to_string(step) +
                   " does not exist (the graph has " + std::to_string(step_count()) + " steps)");
  }
}

bool OrderingGraph::add_before(int a, int b) {
  check_step(a);
  check_step(b);
  if (a == b || successors_[b].test(a)) return false;
  if (std::find(arcs_.begin(), arcs_.end(), std::pair{a, b}) != arcs_.end()) return true;
  arcs_.emplace_back(a, b);
  if (successors_[a].test(b)) return true;  // already implied: the closure is unchanged
  // Every step up to and including a now precedes every step from b on.
  internal::Bitset from_b = successors_[b];
  from_b.set(b);
  internal::Bitset up_to_a = predecessors_[a];
  up_to_a.set(a);
  for (int x = up_to_a.find_first(); x >= 0; x = up_to_a.find_next(x + 1)) {
    successors_[x].unite_with(from_b);
  }
  for (int y = from_b.find_first(); y >= 0; y = from_b.find_next(y + 1)) {
    predecessors_[y].unite_with(up_to_a);
  }
  return true;
}

bool OrderingGraph::precedes(int a, int b) const {
  check_step(a);
  check_step(b);
  return successors_[a].test(b);
}

bool OrderingGraph::possibly_before(int a, int b) const { return a != b && !precedes(b, a); }

bool OrderingGraph::possibly_between(int c, int a, int b) const {
  // Adding a -> c and c -> b closes a cycle iff c reaches a, b reaches c, or b reaches a.
  return possibly_before(a, c) && possibly_before(c, b) && possibly_before(a, b);
}

std::vector<int> OrderingGraph::predecessors(int step) const {
  check_step(step);
  return members(predecessors_[step]);
}

std::vector<int> OrderingGraph::successors(int step) const {
  check_step(step);
  return members(successors_[step]);
}

std::vector<std::pair<int, int>> OrderingGraph::transitive_reduction() const {
  std::vector<std::pair<int, int>> result;
  for (int a = 0; a < step_count(); ++a) {
    const internal::Bitset& after_a = successors_[a];
    for (int b = after_a.find_first(); b >= 0; b = after_a.find_next(b + 1)) {
      if (!after_a.intersects(predecessors_[b])) result.emplace_back(a, b);
    }
  }
  return result;
}

void OrderingGraph::check_invariants() const {
  const int n = step_count();
  if (predecessors_.size() != successors_.size()) {
    throw std::logic_error("ordering graph: successor and predecessor tables differ in size");
  }
  // Reachability over the posted arcs by depth-first search from every step.
  std::vector<std::vector<int>> out(static_cast<std::size_t>(n));
  for (const auto& [a, b] : arcs_) {
    if (a < 0 || a >= n || b < 0 || b >= n)
      throw std::logic_error("ordering graph: arc out of range");
    out[static_cast<std::size_t>(a)].push_back(b);
  }
  for (int a = 0; a < n; ++a) {
    if (successors_[a].size() != n || predecessors_[a].size() != n) {
      throw std::logic_error("ordering graph: closure row of step " + std::to_string(a) +
                             " has the wrong width");
    }
    std::vector<bool> reached(static_cast<std::size_t>(n), false);
    std::vector<int> stack = out[static_cast<std::size_t>(a)];
    while (!stack.empty()) {
      const int x = stack.back();
      stack.pop_back();
      if (reached[static_cast<std::size_t>(x)]) continue;
      reached[static_cast<std::size_t>(x)] = true;
      for (const int y : out[static_cast<std::size_t>(x)]) stack.push_back(y);
    }
    if (reached[static_cast<std::size_t>(a)]) {
      throw std::logic_error("ordering graph: cycle through step " + std::to_string(a));
    }
    for (int b = 0; b < n; ++b) {
      if (successors_[a].test(b) != reached[static_cast<std::size_t>(b)]) {
        throw std::logic_error(
            "ordering graph: closure says " + std::to_string(a) +
            (reached[static_cast<std::size_t>(b)] ? " does not precede " : " precedes ") +
            std::to_string(b) + ", the arcs say otherwise");
      }
      if (successors_[a].test(b) != predecessors_[b].test(a)) {
        throw std::logic_error("ordering graph: predecessor rows are not the transpose");
      }
    }
  }
}

Linearizations::Linearizations(const OrderingGraph& graph)
    : predecessors_{graph.predecessors_}, placed_(graph.step_count()) {}

int Linearizations::next_available(int from) const {
  for (int step = from; step < static_cast<int>(predecessors_.size()); ++step) {
    if (!placed_.test(step) && predecessors_[step].is_subset_of(placed_)) return step;
  }
  return -1;
}

std::optional<std::vector<int>> Linearizations::next() {
  if (finished_) return std::nullopt;
  if (started_) {
    // Find the last position whose step can be replaced by a larger available one.
    while (true) {
      if (order_.empty()) {
        finished_ = true;
        return std::nullopt;
      }
      const int last = order_.back();
      order_.pop_back();
      placed_.reset(last);
      const int replacement = next_available(last + 1);
      if (replacement >= 0) {
        order_.push_back(replacement);
        placed_.set(replacement);
        break;
      }
    }
  }
  started_ = true;
  // Complete with the smallest available step at each position: a set of placed steps closed
  // under predecessors always extends to a full order, so this never gets stuck.
  while (order_.size() < predecessors_.size()) {
    const int step = next_available(0);
    order_.push_back(step);
    placed_.set(step);
  }
  return order_;
}

LinearizationCount count_linearizations(const OrderingGraph& graph, std::size_t limit) {
  Linearizations orders(graph);
  LinearizationCount result;
  while (orders.next()) {
    if (result.count == limit) {
      result.limit_reached = true;
      return result;
    }
    ++result.count;
  }
  return result;
}

}  // namespace spar::planner::cms
