#include "spar/reports/internal/layout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace spar::reports::internal {

LayeredLayout layered_layout(int nodes, const std::vector<std::pair<int, int>>& edges) {
  LayeredLayout layout;
  layout.layer.assign(nodes, 0);
  layout.position.assign(nodes, 0);
  std::vector<std::vector<int>> successors(nodes), predecessors(nodes);
  std::vector<int> pending(nodes, 0);
  for (const auto& [from, to] : edges) {
    if (from < 0 || to < 0 || from >= nodes || to >= nodes || from == to) continue;
    successors[from].push_back(to);
    predecessors[to].push_back(from);
    ++pending[to];
  }
  // Kahn's order; the layer of a node is 1 + the largest layer of its predecessors.
  std::vector<int> order;
  for (int node = 0; node < nodes; ++node)
    if (pending[node] == 0) order.push_back(node);
  for (std::size_t next = 0; next < order.size(); ++next)
    for (const int successor : successors[order[next]]) {
      layout.layer[successor] = std::max(layout.layer[successor], layout.layer[order[next]] + 1);
      if (--pending[successor] == 0) order.push_back(successor);
    }
  int last = 0;
  for (const int node : order) last = std::max(last, layout.layer[node] + 1);
  for (int node = 0; node < nodes; ++node)
    if (pending[node] > 0) layout.layer[node] = last;  // on a cycle
  layout.layers = nodes == 0 ? 0 : *std::max_element(layout.layer.begin(), layout.layer.end()) + 1;

  // Order each layer by the mean position of its predecessors (ties: node number).
  std::vector<std::vector<int>> members(layout.layers);
  for (int node = 0; node < nodes; ++node) members[layout.layer[node]].push_back(node);
  for (std::vector<int>& layer : members) {
    std::vector<double> key(layer.size(), 0.0);
    for (std::size_t i = 0; i < layer.size(); ++i) {
      const std::vector<int>& from = predecessors[layer[i]];
      key[i] = from.empty()
                   ? static_cast<double>(layer[i]) * 1e-6
                   : std::accumulate(from.begin(), from.end(), 0.0, [&](double sum, int p) {
                       return sum + layout.position[p];
                     }) / static_cast<double>(from.size());
    }
    std::vector<std::size_t> index(layer.size());
    std::iota(index.begin(), index.end(), std::size_t{0});
    std::stable_sort(index.begin(), index.end(),
                     [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
    std::vector<int> sorted;
    for (const std::size_t i : index) sorted.push_back(layer[i]);
    layer = sorted;
    for (std::size_t i = 0; i < layer.size(); ++i) layout.position[layer[i]] = static_cast<int>(i);
    layout.widest = std::max(layout.widest, static_cast<int>(layer.size()));
  }
  return layout;
}

std::vector<Point> circular_layout(int nodes) {
  std::vector<Point> points;
  for (int i = 0; i < nodes; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / nodes;
    points.push_back({std::sin(angle), -std::cos(angle)});
  }
  return points;
}

std::vector<int> circle_order(int nodes, const std::vector<std::pair<int, int>>& edges) {
  std::vector<std::vector<int>> neighbours(nodes);
  for (const auto& [a, b] : edges) {
    if (a < 0 || b < 0 || a >= nodes || b >= nodes || a == b) continue;
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  for (std::vector<int>& list : neighbours) std::sort(list.begin(), list.end());
  std::vector<int> slot(nodes, -1);
  int next = 0;
  std::vector<int> stack;  // explicit: no recursion on the C++ stack
  for (int root = 0; root < nodes; ++root) {
    if (slot[root] >= 0) continue;
    stack.push_back(root);
    while (!stack.empty()) {
      const int node = stack.back();
      stack.pop_back();
      if (slot[node] >= 0) continue;
      slot[node] = next++;
      // Push in reverse so the smallest neighbour is visited first.
      for (auto it = neighbours[node].rbegin(); it != neighbours[node].rend(); ++it)
        if (slot[*it] < 0) stack.push_back(*it);
    }
  }
  return slot;
}

}  // namespace spar::reports::internal
