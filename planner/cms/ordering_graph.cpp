#include "spar/planner/cms/ordering_graph.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "spar/planner/cms/error.hpp"

namespace spar::planner::cms {

namespace {

using internal::span_find_next;

std::vector<int> members(std::span<const std::uint64_t> row, int bits) {
  std::vector<int> result;
  for (int bit = span_find_next(row, bits, 0); bit >= 0; bit = span_find_next(row, bits, bit + 1)) {
    result.push_back(bit);
  }
  return result;
}

}  // namespace

int OrderingGraph::add_step() {
  const int step = step_count();
  successors_.grow(step + 1, step + 1);
  predecessors_.grow(step + 1, step + 1);
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
  if (a == b || successors_.test(b, a)) return false;
  if (std::find(arcs_.begin(), arcs_.end(), std::pair{a, b}) != arcs_.end()) return true;
  arcs_.emplace_back(a, b);
  if (successors_.test(a, b)) return true;  // already implied: the closure is unchanged
  // Every step up to and including a now precedes every step from b on.
  const int n = step_count();
  internal::Bitset from_b(n, successors_.row(b));
  from_b.set(b);
  internal::Bitset up_to_a(n, predecessors_.row(a));
  up_to_a.set(a);
  for (int x = up_to_a.find_first(); x >= 0; x = up_to_a.find_next(x + 1)) {
    internal::span_unite(successors_.row(x), from_b.words());
  }
  for (int y = from_b.find_first(); y >= 0; y = from_b.find_next(y + 1)) {
    internal::span_unite(predecessors_.row(y), up_to_a.words());
  }
  return true;
}

bool OrderingGraph::precedes(int a, int b) const {
  check_step(a);
  check_step(b);
  return successors_.test(a, b);
}

bool OrderingGraph::possibly_before(int a, int b) const { return a != b && !precedes(b, a); }

bool OrderingGraph::possibly_between(int c, int a, int b) const {
  // Adding a -> c and c -> b closes a cycle iff c reaches a, b reaches c, or b reaches a.
  return possibly_before(a, c) && possibly_before(c, b) && possibly_before(a, b);
}

std::vector<int> OrderingGraph::predecessors(int step) const {
  check_step(step);
  return members(predecessors_.row(step), step_count());
}

std::vector<int> OrderingGraph::successors(int step) const {
  check_step(step);
  return members(successors_.row(step), step_count());
}

std::vector<std::pair<int, int>> OrderingGraph::transitive_reduction() const {
  std::vector<std::pair<int, int>> result;
  for (int a = 0; a < step_count(); ++a) {
    const auto after_a = successors_.row(a);
    for (const int b : members(after_a, step_count())) {
      if (!internal::spans_intersect(after_a, predecessors_.row(b))) result.emplace_back(a, b);
    }
  }
  return result;
}

void OrderingGraph::check_invariants() const {
  const int n = step_count();
  if (successors_.columns() != n || predecessors_.rows() != n || predecessors_.columns() != n) {
    throw std::logic_error("ordering graph: closure matrices are not square step_count()");
  }
  // Reachability over the posted arcs by depth-first search from every step.
  std::vector<std::vector<int>> out(static_cast<std::size_t>(n));
  for (const auto& [a, b] : arcs_) {
    if (a < 0 || a >= n || b < 0 || b >= n)
      throw std::logic_error("ordering graph: arc out of range");
    out[static_cast<std::size_t>(a)].push_back(b);
  }
  for (int a = 0; a < n; ++a) {
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
      if (successors_.test(a, b) != reached[static_cast<std::size_t>(b)]) {
        throw std::logic_error(
            "ordering graph: closure says " + std::to_string(a) +
            (reached[static_cast<std::size_t>(b)] ? " does not precede " : " precedes ") +
            std::to_string(b) + ", the arcs say otherwise");
      }
      if (successors_.test(a, b) != predecessors_.test(b, a)) {
        throw std::logic_error("ordering graph: predecessor rows are not the transpose");
      }
    }
  }
}

Linearizations::Linearizations(const OrderingGraph& graph)
    : predecessors_{graph.predecessors_}, placed_(graph.step_count()) {}

int Linearizations::next_available(int from) const {
  for (int step = from; step < predecessors_.rows(); ++step) {
    if (!placed_.test(step) && internal::span_is_subset(predecessors_.row(step), placed_.words())) {
      return step;
    }
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
  while (static_cast<int>(order_.size()) < predecessors_.rows()) {
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
