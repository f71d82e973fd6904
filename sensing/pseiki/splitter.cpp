#include "spar/sensing/pseiki/splitter.hpp"

#include <algorithm>
#include <utility>

namespace spar::sensing::pseiki {

int Splitter::split(Blackboard& board) const {
  const ModelPanel& model = board.model();
  int made = 0;
  const std::size_t existing = board.edges.size();
  for (std::size_t e = 0; e < existing; ++e) {
    if (!board.edges[e].active || board.edges[e].candidates.empty()) continue;
    const Segment segment = board.edges[e].segment;
    const PanelEdge& best =
        model.edges()[static_cast<std::size_t>(board.edges[e].candidates.front().edge)];
    if (collinearity_terms(segment, best.pieces, best.tolerance).overlap >= kSplitOverlap) continue;
    // Model edges along the element's line, as intervals of its own parameter (0 .. length).
    const Eigen::Vector2d origin = segment.p0, direction = segment.direction();
    const double length = segment.length();
    std::vector<std::pair<double, double>> extents;
    for (const PanelEdge& panel : model.edges()) {
      const CollinearityTerms terms = collinearity_terms(segment, panel.pieces, panel.tolerance);
      if (terms.angle * terms.offset < kSplitLine) continue;
      const double s0 = (panel.span.p0 - origin).dot(direction);
      const double s1 = (panel.span.p1 - origin).dot(direction);
      if (std::max(s0, s1) <= 0 || std::min(s0, s1) >= length) continue;  // not along it
      extents.emplace_back(std::min(s0, s1), std::max(s0, s1));
    }
    if (extents.size() < 2) continue;
    std::sort(extents.begin(), extents.end());
    std::vector<double> cuts = {0.0};
    for (std::size_t i = 1; i < extents.size(); ++i) {
      const double cut = 0.5 * (std::min(extents[i - 1].second, extents[i].first) +
                                std::max(extents[i - 1].second, extents[i].first));
      if (cut - cuts.back() >= kMinimumPiece && length - cut >= kMinimumPiece) cuts.push_back(cut);
    }
    if (cuts.size() < 2) continue;
    cuts.push_back(length);
    const std::vector<int> inputs = board.edges[e].inputs;
    board.edges[e].active = false;
    for (std::size_t i = 1; i < cuts.size(); ++i)
      board.add_edge({.segment = {origin + cuts[i - 1] * direction, origin + cuts[i] * direction},
                      .inputs = inputs,
                      .split_from = static_cast<int>(e)});
    ++made;
  }
  if (made > 0) board.connect_vertices();
  return made;
}

}  // namespace spar::sensing::pseiki
