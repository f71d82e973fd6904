// How well a verification labelled a simulated image, issue 27's criteria: the share of surviving
// edges (those with a truth) that got their true label, and the clutter and shadow edges (no
// truth) labelled with a belief of at least kDetectionBelief. matcher_test asserts them;
// bench/pseiki_bench.cpp reports them over many seeds.
#pragma once

#include <string>
#include <vector>

#include "spar/sensing/pseiki/matcher.hpp"
#include "spar/sensing/pseiki/simulate.hpp"

namespace spar::sensing::pseiki::testing {

// The issue's simulated image: pose within its uncertainty, 20% of the edges dropped, 10% split,
// 10% with a shadow, clutter and 0.5 px of noise.
inline constexpr ImagePerturbation kIssuePerturbation{.pose_scale = 1,
                                                      .noise_px = 0.5,
                                                      .drop = 0.2,
                                                      .split = 0.1,
                                                      .join = 0,
                                                      .shadow = 0.1,
                                                      .clutter = 8};

inline std::vector<ImageEdgeInput> inputs_of(const SimulatedImage& image) {
  std::vector<ImageEdgeInput> out;
  for (const SimulatedEdge& edge : image.edges) out.push_back(edge.edge);
  return out;
}

struct LabelScore {
  int surviving{0}, right{0}, clutter{0}, clutter_believed{0};
  [[nodiscard]] double accuracy() const { return surviving == 0 ? 1.0 : double(right) / surviving; }
};

// Each input edge is judged by the label of the element holding it (a merged or split edge's).
inline LabelScore score(const Verification& result, const SimulatedImage& image) {
  LabelScore out;
  for (std::size_t i = 0; i < image.edges.size(); ++i) {
    const int element = result.board.element_of(static_cast<int>(i));
    const ImageEdge& edge = result.board.edges[static_cast<std::size_t>(element)];
    const std::string label =
        edge.label < 0 ? "" : result.expected->edges()[static_cast<std::size_t>(edge.label)].id;
    if (image.edges[i].truth.empty()) {
      ++out.clutter;
      if (!label.empty() && edge.belief >= kDetectionBelief) ++out.clutter_believed;
    } else {
      ++out.surviving;
      if (label == image.edges[i].truth) ++out.right;
    }
  }
  return out;
}

}  // namespace spar::sensing::pseiki::testing
