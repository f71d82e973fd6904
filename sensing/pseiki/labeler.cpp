#include "spar/sensing/pseiki/labeler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "spar/sensing/error.hpp"

namespace spar::sensing::pseiki {
namespace {

// Doubt about each panel face and object, from the last grouping (0 where none was formed).
struct Doubts {
  std::vector<double> face, object;
  explicit Doubts(const Blackboard& board)
      : face(board.model().faces().size(), 0.0), object(board.model().objects().size(), 0.0) {
    for (const ImageFace& f : board.faces) face[static_cast<std::size_t>(f.label)] = f.disbelief;
    for (const ImageObject& o : board.objects)
      object[static_cast<std::size_t>(o.label)] = o.disbelief;
  }
};

// The junction evidence for labelling `element` with `a` (labeler.hpp).
struct Junctions {
  double support{0}, against{0}, weight{0};
};
Junctions junctions_of(const Blackboard& board, int element, int a) {
  const ModelPanel& model = board.model();
  const PanelEdge& panel_a = model.edges()[static_cast<std::size_t>(a)];
  const Segment& own = board.edges[static_cast<std::size_t>(element)].segment;
  const double noise = model.uncertainty().noise_px;
  Junctions out;
  for (std::size_t k = 0; k < panel_a.pieces.size(); ++k)
    for (const int side : {0, 1}) {
      // At this end of the piece, A runs `inward`; b is every other edge with a piece ending here.
      const Segment& piece = panel_a.pieces[k];
      const Eigen::Vector2d inward = side == 0 ? piece.p1 - piece.p0 : piece.p0 - piece.p1;
      const PanelVertex& vertex =
          model.vertices()[static_cast<std::size_t>(panel_a.vertices[k][side])];
      for (const int b : vertex.edges) {
        if (b == a) continue;
        // The end q of an image edge labelled b nearest to an end p of the element.
        double gap = kJunctionGap, belief = 0;
        Eigen::Vector2d q = Eigen::Vector2d::Zero(), p = q, far = q;
        for (std::size_t other = 0; other < board.edges.size(); ++other) {
          const ImageEdge& neighbour = board.edges[other];
          if (static_cast<int>(other) == element || !neighbour.active || neighbour.label != b ||
              neighbour.belief < kMinimumNeighbourBelief)
            continue;
          for (const Eigen::Vector2d& end : {neighbour.segment.p0, neighbour.segment.p1})
            for (const bool first : {true, false}) {
              const Eigen::Vector2d& mine = first ? own.p0 : own.p1;
              if ((end - mine).norm() < gap) {
                gap = (end - mine).norm();
                q = end;
                p = mine;
                far = first ? own.p1 : own.p0;
                belief = neighbour.belief;
              }
            }
        }
        if (belief == 0) continue;  // nothing labelled b ends near the element
        const double t = std::max(1.0, 3 * std::sqrt(2.0) * noise * (1 + gap / own.length()));
        const double d = own.line_distance(q) / t;
        // The element must leave the junction along A, not run past it.
        const double junction = (far - p).dot(inward) > 0 ? std::max(0.0, 1 - d * d) : 0.0;
        out.support += junction * belief;
        out.against += (1 - junction) * belief;
        out.weight += belief;
      }
    }
  if (out.weight > 1) {
    out.support /= out.weight;
    out.against /= out.weight;
  }
  return out;
}

// How much of `e` duplicates `other` (labeler.hpp): the share of e's length that runs along
// other's extent less the noise at other's ends, at whatever offset from its line.
double duplicated_share(const Segment& e, const Segment& other, double noise) {
  const Eigen::Vector2d d = other.direction();
  const double length = e.length();
  if (length <= 0 || other.length() <= 0) return 0;
  const double s0 = (e.p0 - other.p0).dot(d), s1 = (e.p1 - other.p0).dot(d);
  const double slack = std::max(1.0, 3 * std::sqrt(2.0) * noise);  // two noisy ends
  // Two pieces of one edge may overlap by the noise where they meet, at other's ends only.
  const double lo = std::max(std::min(s0, s1), slack),
               hi = std::min(std::max(s0, s1), other.length() - slack);
  return hi <= lo ? 0.0 : (hi - lo) / length;
}

// How much of `e` would make A too long (labeler.hpp): the share of e's length by which e and
// `other` together, along A's line, exceed the longest A's image can be.
double excess_share(const Segment& e, const Segment& other, const PanelEdge& a) {
  const Eigen::Vector2d d = a.span.direction();
  const double length = e.length();
  if (length <= 0) return 0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Eigen::Vector2d& p : {e.p0, e.p1, other.p0, other.p1}) {
    lo = std::min(lo, p.dot(d));
    hi = std::max(hi, p.dot(d));
  }
  return std::min(1.0, std::max(0.0, hi - lo - a.longest_px) / length);
}

// The hypotheses of one element's labels: one node per object with a candidate, in candidate
// order, a leaf per candidate under it (ElementEvidence::candidate_leaves), a leaf for the
// object's other edges where the candidates do not cover it, and "none". Returns each object's
// node.
std::map<int, int> add_label_hypotheses(const ModelPanel& model, const ImageEdge& edge,
                                        ElementEvidence& out) {
  HypothesisTree& tree = out.tree;
  std::map<int, int> object_node;
  std::map<int, int> candidates_of_object;
  for (const LabelCandidate& candidate : edge.candidates)
    ++candidates_of_object[model.edges()[static_cast<std::size_t>(candidate.edge)].object];
  for (const LabelCandidate& candidate : edge.candidates) {
    const PanelEdge& panel = model.edges()[static_cast<std::size_t>(candidate.edge)];
    auto [it, inserted] = object_node.try_emplace(panel.object, 0);
    if (inserted) {
      it->second = tree.add_node(0, model.objects()[static_cast<std::size_t>(panel.object)].name);
    }
    out.candidate_leaves.push_back(tree.add_node(it->second, panel.id));
  }
  for (const auto& [object, node] : object_node)
    if (candidates_of_object[object] <
        static_cast<int>(model.objects()[static_cast<std::size_t>(object)].edges.size()))
      tree.add_node(node, model.objects()[static_cast<std::size_t>(object)].name + "/other");
  out.none_leaf = tree.add_node(0, "none");
  return object_node;
}

// The evidence on candidate c of `element` (labeler.hpp): its collinearity, the other pieces of
// its label, its label's neighbours and junctions, and the doubt about the label's faces.
void add_candidate_evidence(const Blackboard& board, int element, std::size_t c,
                            const Doubts& doubts, ElementEvidence& out) {
  const ModelPanel& model = board.model();
  const ImageEdge& edge = board.edges[static_cast<std::size_t>(element)];
  HypothesisTree& tree = out.tree;
  const Tolerance same_label = Tolerance::noise_only(model.uncertainty().noise_px);
  const int a = edge.candidates[c].edge;
  const int leaf = out.candidate_leaves[c];
  const PanelEdge& panel_a = model.edges()[static_cast<std::size_t>(a)];
  tree.add_for(leaf, capped(edge.candidates[c].collinearity));
  const std::vector<int>& related = model.neighbours(a);
  // A believed piece of A on e's line confirms e's line, not that e lies within A's extent.
  const double overlap =
      collinearity_terms(edge.segment, panel_a.pieces, panel_a.tolerance).overlap;
  // The relational pairs pooled: belief-weighted sums of (in)compatibility and of belief.
  double compatible = 0, incompatible = 0, weight = 0;
  // How far a believed piece of A that e runs along explains A's place already: the support
  // A's neighbours and junctions give for "A is here" is then that piece's, not e's.
  double explained = 0;
  for (std::size_t other = 0; other < board.edges.size(); ++other) {
    const ImageEdge& neighbour = board.edges[other];
    if (static_cast<int>(other) == element || !neighbour.active || neighbour.label < 0 ||
        neighbour.belief < kMinimumNeighbourBelief)
      continue;
    const int b = neighbour.label;
    if (b == a) {
      // Another piece of A confirms e, unless e runs along it or past where A can end: pieces
      // of one edge do not overlap (an edge detector reports one edge where two coincide) and
      // are together no longer than A, so the part of e that duplicates it or makes A too
      // long speaks against e.
      const double duplicate =
          duplicated_share(edge.segment, neighbour.segment, model.uncertainty().noise_px);
      const double excess = excess_share(edge.segment, neighbour.segment, panel_a);
      const double not_a = std::max(duplicate, excess);
      tree.add_evidence(leaf,
                        capped(edge_collinearity(edge.segment, neighbour.segment, same_label) *
                               neighbour.belief * overlap * (1 - not_a)),
                        capped(edge_noncollinearity(edge.segment, neighbour.segment, same_label) *
                               neighbour.belief));
      if (not_a > 0) tree.add_against(leaf, capped(not_a * neighbour.belief));
      explained = std::max(explained, not_a * neighbour.belief);
    } else if (std::binary_search(related.begin(), related.end(), b)) {
      const PanelEdge& panel_b = model.edges()[static_cast<std::size_t>(b)];
      const Tolerance& relational = model.relational(a, b);
      compatible += neighbour.belief * compatibility(edge.segment, neighbour.segment, panel_a.span,
                                                     panel_b.span, relational);
      incompatible += neighbour.belief * incompatibility(edge.segment, neighbour.segment,
                                                         panel_a.span, panel_b.span, relational);
      weight += neighbour.belief;
    }
  }
  if (weight > 0) {
    const double scale = 1 / std::max(1.0, weight);
    tree.add_evidence(leaf, capped(kRelationalWeight * compatible * scale * (1 - explained)),
                      capped(incompatible * scale));
  }
  const Junctions junctions = junctions_of(board, element, a);
  if (junctions.weight > 0)
    tree.add_evidence(leaf, capped(junctions.support * (1 - explained)), capped(junctions.against));
  for (const int face : panel_a.faces)
    if (doubts.face[static_cast<std::size_t>(face)] > 0)
      tree.add_against(leaf, capped(doubts.face[static_cast<std::size_t>(face)]));
}

ElementEvidence evidence_of(const Blackboard& board, int element, const Doubts& doubts) {
  const ImageEdge& edge = board.edges[static_cast<std::size_t>(element)];
  ElementEvidence out;
  const std::map<int, int> object_node = add_label_hypotheses(board.model(), edge, out);
  for (std::size_t c = 0; c < edge.candidates.size(); ++c)
    add_candidate_evidence(board, element, c, doubts, out);
  for (const auto& [object, node] : object_node)
    if (doubts.object[static_cast<std::size_t>(object)] > 0)
      out.tree.add_against(node, capped(doubts.object[static_cast<std::size_t>(object)]));
  return out;
}

}  // namespace

Labeler::Labeler(int max_candidates) : max_candidates_(max_candidates) {
  if (max_candidates < 1)
    throw SensingError("labeler: at least one candidate label per edge, got " +
                       std::to_string(max_candidates));
}

void Labeler::label(Blackboard& board) const {
  const ModelPanel& model = board.model();
  for (ImageEdge& edge : board.edges) {
    if (!edge.active || !edge.candidates.empty()) continue;
    for (std::size_t m = 0; m < model.edges().size(); ++m) {
      const PanelEdge& panel = model.edges()[m];
      const double degree = collinearity(edge.segment, panel.pieces, panel.tolerance);
      if (degree > 0) edge.candidates.push_back({static_cast<int>(m), degree, degree});
    }
    std::stable_sort(edge.candidates.begin(), edge.candidates.end(),
                     [](const LabelCandidate& x, const LabelCandidate& y) {
                       return x.collinearity > y.collinearity;
                     });
    if (static_cast<int>(edge.candidates.size()) > max_candidates_)
      edge.candidates.resize(static_cast<std::size_t>(max_candidates_));
    edge.label = edge.candidates.empty() ? -1 : edge.candidates.front().edge;
    edge.belief = edge.candidates.empty() ? 0.0 : capped(edge.candidates.front().collinearity);
  }
}

ElementEvidence Labeler::evidence(const Blackboard& board, int element) const {
  return evidence_of(board, element, Doubts(board));
}

void Labeler::update(Blackboard& board) const {
  const Doubts doubts(board);
  // All from the previous round: compute every element's new beliefs, then assign.
  std::vector<std::vector<double>> beliefs(board.edges.size());
  std::vector<double> none(board.edges.size(), 0.0);
  for (std::size_t e = 0; e < board.edges.size(); ++e) {
    const ImageEdge& edge = board.edges[e];
    if (!edge.active || edge.candidates.empty()) continue;
    const ElementEvidence evidence = evidence_of(board, static_cast<int>(e), doubts);
    const TreeBeliefs combined = evidence.tree.combine();
    const double reliability = std::min(1.0, edge.segment.length() / kReliableLength);
    for (const int leaf : evidence.candidate_leaves)
      beliefs[e].push_back(reliability * combined.belief[static_cast<std::size_t>(leaf)]);
    none[e] = reliability * combined.belief[static_cast<std::size_t>(evidence.none_leaf)];
  }
  for (std::size_t e = 0; e < board.edges.size(); ++e) {
    ImageEdge& edge = board.edges[e];
    if (!edge.active || edge.candidates.empty()) continue;
    std::size_t best = 0;
    for (std::size_t c = 0; c < edge.candidates.size(); ++c) {
      edge.candidates[c].belief = beliefs[e][c];
      if (beliefs[e][c] > beliefs[e][best]) best = c;
    }
    if (beliefs[e][best] >= kMinimumLabelBelief) {
      edge.label = edge.candidates[best].edge;
      edge.belief = beliefs[e][best];
    } else {
      edge.label = -1;
      edge.belief = none[e];
    }
  }
}

}  // namespace spar::sensing::pseiki
