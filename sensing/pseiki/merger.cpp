#include "spar/sensing/pseiki/merger.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>
#include <map>

namespace spar::sensing::pseiki {
namespace {

// The segment spanning `parts` on their common line: the total-least-squares line through their
// end points (each weighted by its part's length), between the extreme projections.
Segment spanning(const Blackboard& board, const std::vector<int>& parts) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double total = 0;
  for (const int e : parts) {
    const Segment& s = board.edges[static_cast<std::size_t>(e)].segment;
    centre += s.length() * (s.p0 + s.p1);
    total += 2 * s.length();
  }
  centre /= total;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const int e : parts) {
    const Segment& s = board.edges[static_cast<std::size_t>(e)].segment;
    for (const Eigen::Vector2d& p : {s.p0, s.p1})
      scatter += s.length() * (p - centre) * (p - centre).transpose();
  }
  // The eigenvector of the largest eigenvalue (Eigen sorts them increasing).
  const Eigen::Vector2d direction =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvectors().col(1);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const int e : parts)
    for (const Eigen::Vector2d& p : {board.edges[static_cast<std::size_t>(e)].segment.p0,
                                     board.edges[static_cast<std::size_t>(e)].segment.p1}) {
      const double t = (p - centre).dot(direction);
      lo = std::min(lo, t);
      hi = std::max(hi, t);
    }
  return {centre + lo * direction, centre + hi * direction};
}

}  // namespace

int Merger::merge(Blackboard& board) const {
  const ModelPanel& model = board.model();
  const Tolerance noise = Tolerance::noise_only(model.uncertainty().noise_px);
  // Active labelled elements by label, in order along the label's line.
  std::map<int, std::vector<int>> by_label;
  for (std::size_t e = 0; e < board.edges.size(); ++e)
    if (board.edges[e].active && board.edges[e].label >= 0)
      by_label[board.edges[e].label].push_back(static_cast<int>(e));
  int made = 0;
  for (auto& [label, elements] : by_label) {
    const PanelEdge& panel = model.edges()[static_cast<std::size_t>(label)];
    const Eigen::Vector2d origin = panel.span.p0, direction = panel.span.direction();
    const auto start = [&](int e) {
      const Segment& s = board.edges[static_cast<std::size_t>(e)].segment;
      return std::min((s.p0 - origin).dot(direction), (s.p1 - origin).dot(direction));
    };
    std::sort(elements.begin(), elements.end(), [&](int x, int y) { return start(x) < start(y); });
    std::vector<std::vector<int>> groups;
    for (const int e : elements) {
      if (!groups.empty()) {
        std::vector<int> joined = groups.back();
        joined.push_back(e);
        const Segment& last = board.edges[static_cast<std::size_t>(groups.back().back())].segment;
        const Segment whole = spanning(board, joined);
        if (edge_collinearity(last, board.edges[static_cast<std::size_t>(e)].segment, noise) >=
                kMergeCollinearity &&
            whole.length() <= panel.longest_px &&
            collinearity_terms(whole, panel.pieces, panel.tolerance).overlap >= kMergeOverlap) {
          groups.back() = std::move(joined);
          continue;
        }
      }
      groups.push_back({e});
    }
    for (const std::vector<int>& group : groups) {
      if (group.size() < 2) continue;
      ImageEdge merged{.segment = spanning(board, group)};
      for (const int e : group) {
        ImageEdge& part = board.edges[static_cast<std::size_t>(e)];
        part.active = false;
        merged.inputs.insert(merged.inputs.end(), part.inputs.begin(), part.inputs.end());
      }
      std::sort(merged.inputs.begin(), merged.inputs.end());
      board.add_edge(std::move(merged));
      ++made;
    }
  }
  if (made > 0) board.connect_vertices();
  return made;
}

}  // namespace spar::sensing::pseiki
