// Every directed edge of a triangle mesh with the triangle running it, sorted by (from, to,
// triangle): equal edges are neighbours and an edge is found by binary search. O(n log n) over one
// flat array; std::map made mesh validation a third of `spar object`'s time on a 300k-triangle
// mesh. Used by validate_closed_mesh (mesh.cpp) and face merging (object.cpp).
//
// Example:
//   const EdgeIndex edges(mesh.triangles);
//   const int across = edges.owner(b, a);   // the triangle running b -> a, or -1
//   for (const auto& [key, t] : edges.edges()) use(EdgeIndex::from(key), EdgeIndex::to(key), t);
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace spar::geometry::internal {

class EdgeIndex {
 public:
  explicit EdgeIndex(const std::vector<std::array<int, 3>>& triangles) {
    edges_.reserve(3 * triangles.size());
    for (int t = 0; t < static_cast<int>(triangles.size()); ++t)
      for (int c = 0; c < 3; ++c)
        edges_.push_back({key(triangles[t][c], triangles[t][(c + 1) % 3]), t});
    std::sort(edges_.begin(), edges_.end());
  }
  // Vertex indices are >= 0 and fit 32 bits.
  static std::uint64_t key(int from, int to) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>(from)) << 32 |
           static_cast<std::uint32_t>(to);
  }
  static int from(std::uint64_t key) { return static_cast<int>(key >> 32); }
  static int to(std::uint64_t key) { return static_cast<int>(key & 0xFFFFFFFFu); }
  // (key, triangle), sorted.
  [[nodiscard]] const std::vector<std::pair<std::uint64_t, int>>& edges() const { return edges_; }
  // The lowest triangle running from -> to, or -1.
  [[nodiscard]] int owner(int from, int to) const {
    const std::uint64_t wanted = key(from, to);
    const auto it = std::lower_bound(edges_.begin(), edges_.end(), std::pair{wanted, -1});
    return it != edges_.end() && it->first == wanted ? it->second : -1;
  }

 private:
  std::vector<std::pair<std::uint64_t, int>> edges_;
};

}  // namespace spar::geometry::internal
