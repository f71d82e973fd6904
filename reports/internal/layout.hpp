// Graph layouts for the report's SVG drawings (reports/ only), readable for 10-50 nodes.
//
// layered_layout: a directed acyclic graph drawn in layers (Sugiyama-style, simplified). A node's
// layer is the length of the longest path reaching it, so every edge points to a later layer;
// within a layer, nodes are ordered by the mean position of their predecessors (one sweep from the
// first layer down), which removes most crossings of plan-like graphs. Nodes on a cycle (not a
// DAG) are put in one last layer rather than refused.
// circular_layout: n points evenly on the unit circle, the first at the top, clockwise.
// circle_order: the order in which to put the nodes of an undirected graph on a circle so that
// neighbours sit side by side: a depth-first walk (neighbours in node order) of each connected
// component in turn, so a chain or tree is drawn without long chords.
//
// Example:
//   const LayeredLayout layout = layered_layout(4, {{0, 1}, {0, 2}, {1, 3}, {2, 3}});
//   // layout.layer == {0, 1, 1, 2}; layout.position[1] == 0, layout.position[2] == 1
//   const std::vector<Point> ring = circular_layout(6);   // ring[0] == {0, -1}
//   const std::vector<int> slot = circle_order(3, {{0, 2}, {2, 1}});   // {0, 2, 1}
#pragma once

#include <utility>
#include <vector>

namespace spar::reports::internal {

struct LayeredLayout {
  std::vector<int> layer;     // per node: 0 for sources; layer[b] > layer[a] for every edge a->b
  std::vector<int> position;  // per node: its index within its layer (0, 1, ...)
  int layers{0};              // number of layers
  int widest{0};              // most nodes in one layer
};

[[nodiscard]] LayeredLayout layered_layout(int nodes,
                                           const std::vector<std::pair<int, int>>& edges);

struct Point {
  double x{0.0}, y{0.0};
};

[[nodiscard]] std::vector<Point> circular_layout(int nodes);

// slot[node]: the node's place on the circle (0 .. nodes-1), a permutation.
[[nodiscard]] std::vector<int> circle_order(int nodes,
                                            const std::vector<std::pair<int, int>>& edges);

}  // namespace spar::reports::internal
