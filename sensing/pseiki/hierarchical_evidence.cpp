#include "spar/sensing/pseiki/hierarchical_evidence.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "spar/common/number.hpp"
#include "spar/sensing/error.hpp"

namespace spar::sensing::pseiki {
namespace {

// What the draws of a node's subtree leave inside its parent P, for a child C (header): a subset
// I of C, and all of P - C ("kept") or none of it. Indices of the four types:
constexpr int kKeptSome = 0;  // P - C kept, I not empty
constexpr int kKeptNone = 1;  // P - C kept, I empty
constexpr int kLostSome = 2;  // P - C lost, I not empty
constexpr int kLostNone = 3;  // P - C lost, I empty
using Types = std::array<double, 4>;

// A node's own draws combined: the probabilities that they intersect to the node's set, its
// complement, the frame, or the empty set.
struct OwnDraw {
  double for_set{0}, against{0}, neither{1}, empty{0};
};

// The types a node shows its parent, from the types of what its strict subtree draws (`below`,
// in the same four classes with the node itself in place of the parent) and its own draw.
Types shown(const Types& below, const OwnDraw& own) {
  const double n = own.neither, f = own.for_set, a = own.against, z = own.empty;
  return {n * below[kKeptSome], n * below[kKeptNone] + a * (below[kKeptSome] + below[kKeptNone]),
          f * (below[kKeptSome] + below[kLostSome]) + n * below[kLostSome],
          f * (below[kKeptNone] + below[kLostNone]) + n * below[kLostNone] +
              a * (below[kLostSome] + below[kLostNone]) + z};
}

// d(shown) / d(below) applied to the derivatives `outer` of Z with respect to the shown types:
// Z's derivatives with respect to the types below.
Types pull_back(const Types& outer, const OwnDraw& own) {
  const double n = own.neither, f = own.for_set, a = own.against, z = own.empty;
  return {n * outer[kKeptSome] + a * outer[kKeptNone] + f * outer[kLostSome] + z * outer[kLostNone],
          (n + a) * outer[kKeptNone] + (f + z) * outer[kLostNone],
          (f + n) * outer[kLostSome] + (a + z) * outer[kLostNone], outer[kLostNone]};
}

// For the children's shown types: the products over all children but one of "kept" (T = kept
// some or none), of "kept none" (N), and S = sum over l of lost-some(l) * prod over the others of
// T. They give the node's `below` types: kept some = prod T - prod N, kept none = prod N, lost
// some = S, lost none = the rest.
struct Partial {
  double kept{1}, kept_none{1}, one_lost{0};
  [[nodiscard]] Partial with(const Types& child) const {
    const double t = child[kKeptSome] + child[kKeptNone];
    return {kept * t, kept_none * child[kKeptNone], one_lost * t + kept * child[kLostSome]};
  }
  [[nodiscard]] Partial with(const Partial& other) const {
    return {kept * other.kept, kept_none * other.kept_none,
            one_lost * other.kept + kept * other.one_lost};
  }
  [[nodiscard]] Types below() const {
    const double some = kept - kept_none;
    return {some, kept_none, one_lost, 1.0 - some - kept_none - one_lost};
  }
};

// A node's pieces of evidence as one draw (header): A if some piece drew A and none "not A", ...
// (`Pieces`: HypothesisTree's, each with support_for and support_against.)
template <class Pieces>
OwnDraw own_draw(const Pieces& pieces) {
  double none_against = 1, none_for = 1, neither = 1;
  for (const auto& piece : pieces) {
    none_against *= 1 - piece.support_against;
    none_for *= 1 - piece.support_for;
    neither *= 1 - piece.support_for - piece.support_against;
  }
  return {.for_set = none_against - neither,
          .against = none_for - neither,
          .neither = neither,
          .empty = 1 - none_against - none_for + neither};
}

// The upward sweep: per node, the types of what its strict subtree draws and the types it shows
// its parent. Nodes are added below existing ones, so every child has a larger index than its
// parent and a reverse sweep visits children first.
struct Upward {
  std::vector<Types> below, shown;
};
Upward upward(const std::vector<std::vector<int>>& children, const std::vector<OwnDraw>& own) {
  const Types leaf_below = {1, 0, 0, 0};  // a leaf's strict subtree draws nothing: I = {leaf}
  Upward out{std::vector<Types>(own.size()), std::vector<Types>(own.size())};
  for (std::size_t node = own.size(); node-- > 0;) {
    if (children[node].empty()) {
      out.below[node] = leaf_below;
    } else {
      Partial all;
      for (const int child : children[node])
        all = all.with(out.shown[static_cast<std::size_t>(child)]);
      out.below[node] = all.below();
    }
    out.shown[node] = shown(out.below[node], own[node]);
  }
  return out;
}

// The downward sweep: d Z / d shown[node] for every node but the root (Z = the root's below
// "kept some" + "lost some"), each child's through the products of its siblings (prefix and
// suffix products, no division).
std::vector<Types> downward(const std::vector<std::vector<int>>& children,
                            const std::vector<OwnDraw>& own, const Upward& up) {
  std::vector<Types> d_below(own.size()), d_shown(own.size());
  d_below[0] = {1, 0, 1, 0};
  for (std::size_t node = 0; node < own.size(); ++node) {
    const std::vector<int>& kids = children[node];
    if (kids.empty()) continue;
    std::vector<Partial> prefix(kids.size() + 1), suffix(kids.size() + 1);
    for (std::size_t i = 0; i < kids.size(); ++i)
      prefix[i + 1] = prefix[i].with(up.shown[static_cast<std::size_t>(kids[i])]);
    for (std::size_t i = kids.size(); i-- > 0;)
      suffix[i] = suffix[i + 1].with(up.shown[static_cast<std::size_t>(kids[i])]);
    const Types& outer = d_below[node];
    for (std::size_t i = 0; i < kids.size(); ++i) {
      const Partial others = prefix[i].with(suffix[i + 1]);
      // d(kept some, kept none, lost some) / d(child's four types); lost none = 1 - the others.
      const std::array<Types, 3> rows = {Types{others.kept, others.kept - others.kept_none, 0, 0},
                                         Types{0, others.kept_none, 0, 0},
                                         Types{others.one_lost, others.one_lost, others.kept, 0}};
      Types d{};
      for (int t = 0; t < 4; ++t) {
        const double lost_none = 1 - rows[0][t] - rows[1][t] - rows[2][t];
        d[t] = outer[kKeptSome] * rows[0][t] + outer[kKeptNone] * rows[1][t] +
               outer[kLostSome] * rows[2][t] + outer[kLostNone] * lost_none;
      }
      const auto child = static_cast<std::size_t>(kids[i]);
      d_shown[child] = d;
      d_below[child] = pull_back(d, own[child]);
    }
  }
  return d_shown;
}

void check_strength(double value, const char* what, int node, const std::string& name) {
  if (!(value >= 0 && value <= 1))
    throw SensingError(std::string("hypothesis tree: the support ") + what + " node " +
                       std::to_string(node) + " ('" + name + "') must be in [0, 1], got " +
                       format_number(value));
}

}  // namespace

HypothesisTree::HypothesisTree() : parent_{-1}, children_(1), name_{"frame"}, evidence_(1) {}

void HypothesisTree::check_node(int node) const {
  if (node < 0 || node >= size())
    throw SensingError("hypothesis tree: no node " + std::to_string(node) + " (it has " +
                       std::to_string(size()) + ")");
}

int HypothesisTree::add_node(int parent, std::string name) {
  check_node(parent);
  const int node = size();
  parent_.push_back(parent);
  children_.emplace_back();
  children_[static_cast<std::size_t>(parent)].push_back(node);
  name_.push_back(std::move(name));
  evidence_.emplace_back();
  return node;
}

void HypothesisTree::add_evidence(int node, double support_for, double support_against) {
  check_node(node);
  if (node == 0) throw SensingError("hypothesis tree: evidence about the whole frame says nothing");
  check_strength(support_for, "for", node, name(node));
  check_strength(support_against, "against", node, name(node));
  if (support_for + support_against > 1 + 1e-12)
    throw SensingError("hypothesis tree: the supports for and against node " +
                       std::to_string(node) + " ('" + name(node) + "') sum to " +
                       format_number(support_for + support_against) + " > 1");
  evidence_[static_cast<std::size_t>(node)].push_back({support_for, support_against});
}

void HypothesisTree::clear_evidence() {
  for (std::vector<Piece>& pieces : evidence_) pieces.clear();
}

std::vector<int> HypothesisTree::leaves() const {
  std::vector<int> out;
  for (int node = 0; node < size(); ++node)
    if (is_leaf(node)) out.push_back(node);
  return out;
}

TreeBeliefs HypothesisTree::combine() const {
  const auto count = static_cast<std::size_t>(size());
  std::vector<OwnDraw> own;
  for (const std::vector<Piece>& pieces : evidence_) own.push_back(own_draw(pieces));
  const Upward up = upward(children_, own);
  // The root draws nothing of its own: R is not empty when its "below" I is not.
  const double z = up.below[0][kKeptSome] + up.below[0][kLostSome];
  if (!(z > 0))
    throw SensingError(
        "Dempster's rule: total conflict (K = 1): the evidence for and against the hypotheses "
        "contradicts itself outright");
  const std::vector<Types> d_shown = downward(children_, own, up);

  TreeBeliefs out;
  out.conflict = 1 - z;
  out.belief.assign(count, 1.0);
  out.plausibility.assign(count, 1.0);
  // Z with the node's own draw replaced (Z is linear in the types the node shows).
  const auto z_with = [&](std::size_t node, const OwnDraw& draw) {
    const Types types = shown(up.below[node], draw);
    double sum = 0;
    for (int t = 0; t < 4; ++t) sum += d_shown[node][t] * types[t];
    return sum;
  };
  for (std::size_t node = 1; node < count; ++node) {
    const OwnDraw& draw = own[node];
    // A certain piece for the node: its draws A or "frame" become A, the others empty.
    const OwnDraw certain_for{.for_set = draw.for_set + draw.neither,
                              .against = 0,
                              .neither = 0,
                              .empty = draw.against + draw.empty};
    const OwnDraw certain_against{.for_set = 0,
                                  .against = draw.against + draw.neither,
                                  .neither = 0,
                                  .empty = draw.for_set + draw.empty};
    out.plausibility[node] = std::clamp(z_with(node, certain_for) / z, 0.0, 1.0);
    out.belief[node] = std::clamp(1 - z_with(node, certain_against) / z, 0.0, 1.0);
  }
  return out;
}

Frame HypothesisTree::frame() const {
  std::vector<std::string> names;
  for (const int leaf : leaves()) names.push_back(name(leaf));
  return Frame(std::move(names));
}

FocalSet HypothesisTree::leaf_set(int node) const {
  check_node(node);
  const std::vector<int> all = leaves();
  FocalSet set(static_cast<int>(all.size()));
  for (std::size_t i = 0; i < all.size(); ++i) {
    // A leaf belongs to `node` when `node` is on its path to the root.
    for (int up = all[i]; up >= 0; up = parent_[static_cast<std::size_t>(up)])
      if (up == node) {
        set.insert(static_cast<int>(i));
        break;
      }
  }
  return set;
}

std::vector<MassFunction> HypothesisTree::mass_functions() const {
  const int frame_size = static_cast<int>(leaves().size());
  std::vector<MassFunction> out;
  for (int node = 1; node < size(); ++node) {
    const FocalSet set = leaf_set(node);
    for (const Piece& piece : evidence_[static_cast<std::size_t>(node)]) {
      std::vector<FocalElement> elements;
      if (piece.support_for > 0) elements.push_back({set, piece.support_for});
      if (piece.support_against > 0) elements.push_back({set.complement(), piece.support_against});
      const double rest = 1 - piece.support_for - piece.support_against;
      if (rest > 0) elements.push_back({FocalSet::whole(frame_size), rest});
      out.push_back(MassFunction::from_elements(frame_size, std::move(elements)));
    }
  }
  return out;
}

}  // namespace spar::sensing::pseiki
