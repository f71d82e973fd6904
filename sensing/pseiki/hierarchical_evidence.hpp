// Dempster's rule for hierarchical evidence: the combination PSEIKI uses for the labels of its
// image elements (survey seed 003, section 4: "a computationally efficient variation of Dempster's
// rule ... [that] allows the reasoning process to exploit the hierarchical nature of the
// integration task").
//
// Which variation: Shafer and Logan's exact algorithm for hierarchical evidence (G. Shafer and R.
// Logan, "Implementing Dempster's rule for hierarchical evidence", Artificial Intelligence 33(3),
// 1987, pp. 271-298), which generalises Barnett's linear-time rule for evidence about singletons
// (J. A. Barnett, "Computational methods for a mathematical theory of evidence", IJCAI 1981) to a
// tree of hypotheses, and makes Gordon and Shortliffe's approximation (AI 26, 1985) unnecessary.
// The result is Dempster's rule itself, not an approximation; the two-pass bookkeeping below is
// ours (probabilities of a node's random-set type instead of their commonality ratios).
//
// Setting. The frame is the set of leaves of a tree (a strict hierarchy): each internal node is
// the set of the leaves below it and its children partition it; the root is the whole frame.
// Every piece of evidence bears on one non-root node A, for it or against it (a dichotomous belief
// function): m(A) = s_for, m(not A) = s_against, m(frame) = 1 - s_for - s_against. A simple
// support function is one with s_against = 0 (PSEIKI's confirmation, e.g. the degree of
// collinearity for the label "edge E_A"), and one with s_for = 0 its disconfirmation.
//
// Algorithm (Dempster's rule as a random set, R = the intersection of one focal set drawn from
// each piece of evidence, conditioned on R != {}). The pieces on one node combine into four
// probabilities: the node's draws give A, not A, the frame, or the empty set (some draw for and
// some against). Seen from its parent P, everything drawn in the subtree of a child C is, within
// P, "a subset I of C, plus all of P - C or none of it"; only the type of that (I empty or not,
// P - C kept or not) matters above C, so four numbers per node describe it.
//   upward pass (leaves first): each node's four type probabilities from its children's;
//   downward pass (root first): d(1 - K) / d(type probabilities) of each node (Z = 1 - K is
//     multilinear in them, since the nodes' draws are independent);
//   then Pl(A) = Z(with a certain piece for A) / Z and Bel(A) = 1 - Z(with a certain piece
//     against A) / Z for every node A at once, each from its own four numbers and derivatives.
// Total conflict (Z = 0, e.g. certainty for A and certainty against A) throws SensingError, as
// Dempster's rule does in evidence.hpp.
//
// Cost: O(N + E) for N nodes and E pieces of evidence, against O(products of the focal sets) for
// Dempster's rule on general sets (evidence.hpp's combine), whose focal sets multiply as pieces
// against different nodes intersect. tests/sensing/pseiki/hierarchical_evidence_test.cpp checks
// every node's belief, plausibility and the conflict against combine(); bench/pseiki_bench.cpp
// times both.
//
// Example:
//   HypothesisTree tree;                          // root 0
//   const int block = tree.add_node(0, "block");  // an object: the set of its edges
//   const int e1 = tree.add_node(block, "block/e1"), e2 = tree.add_node(block, "block/e2");
//   const int none = tree.add_node(0, "none");
//   tree.add_for(e1, 0.8);                        // collinearity of an image edge with e1
//   tree.add_against(block, 0.3);                 // the image object "block" is doubted
//   const TreeBeliefs beliefs = tree.combine();
//   beliefs.conflict;                             // 0.24 = 0.8 * 0.3: {e1} misses "not block"
//   beliefs.belief[e1];                           // 0.8 * 0.7 / (1 - 0.24)
#pragma once

#include <string>
#include <vector>

#include "spar/sensing/evidence.hpp"

namespace spar::sensing::pseiki {

struct TreeBeliefs {
  std::vector<double> belief;        // [node] Bel(node's set)
  std::vector<double> plausibility;  // [node] Pl(node's set)
  double conflict{0};                // K: the mass Dempster's rule normalises away
};

// A tree of hypotheses with dichotomous evidence on its nodes. Node 0 is the root (the frame);
// nodes are added below existing ones and never removed; a node without children is a leaf. Every
// strength is in [0, 1] and s_for + s_against <= 1 for one piece, and no piece is on the root
// (SensingError otherwise).
class HypothesisTree {
 public:
  HypothesisTree();
  // Adds a child of `parent` (an existing node) and returns its index.
  int add_node(int parent, std::string name);
  void add_for(int node, double support) { add_evidence(node, support, 0.0); }
  void add_against(int node, double support) { add_evidence(node, 0.0, support); }
  // One dichotomous piece: m(A) = support_for, m(not A) = support_against. Not on the root.
  void add_evidence(int node, double support_for, double support_against);
  // Removes every piece of evidence (the tree stays).
  void clear_evidence();

  [[nodiscard]] int size() const { return static_cast<int>(parent_.size()); }
  [[nodiscard]] int parent(int node) const { return parent_.at(node); }
  [[nodiscard]] const std::vector<int>& children(int node) const { return children_.at(node); }
  [[nodiscard]] const std::string& name(int node) const { return name_.at(node); }
  [[nodiscard]] bool is_leaf(int node) const { return children_.at(node).empty(); }
  // The leaves by node index: the frame of discernment, leaves()[i] = hypothesis i.
  [[nodiscard]] std::vector<int> leaves() const;

  // Dempster's combination of every piece, beliefs and plausibilities of every node.
  [[nodiscard]] TreeBeliefs combine() const;

  // The same evidence for the flat rule: the frame (leaf names), each node's set of leaves, and
  // one mass function per piece (evidence.hpp). Tests and the benchmark's peer use it.
  [[nodiscard]] Frame frame() const;
  [[nodiscard]] FocalSet leaf_set(int node) const;
  [[nodiscard]] std::vector<MassFunction> mass_functions() const;

 private:
  struct Piece {
    double support_for{0}, support_against{0};
  };
  void check_node(int node) const;  // throws SensingError for a node the tree lacks
  std::vector<int> parent_;
  std::vector<std::vector<int>> children_;
  std::vector<std::string> name_;
  std::vector<std::vector<Piece>> evidence_;
};

}  // namespace spar::sensing::pseiki
