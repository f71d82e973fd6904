// The labeler, PSEIKI's knowledge source that "establish[es] correspondences between image
// elements and model elements and ... accumulate[s] evidence on the validity of those labels"
// (survey seed 003, section 4), at the edge level.
//
// label(): initial labels. Each active image edge without candidates gets the model edges it is
//   collinear with (collinearity.hpp, under each model edge's tolerance), best first, at most
//   `max_candidates`; its label is the most collinear one and its belief that degree.
// update(): one round of constraint-based updates, every element at once from the previous
//   round's labels and beliefs (so the order of the elements does not matter). For an element e
//   and each candidate label A, the pieces of evidence are
//     for A              collinearity(e, A)                       (the initial measure)
//     for / against A    collinearity(e, e2) x Bel(e2) x overlap(e, A), noncollinearity(e, e2) x
//                        Bel(e2) for every other element e2 labelled A (one piece each, as the
//                        survey writes them; overlap: collinearity.hpp's share of e within A's
//                        extent, because a believed piece of A on e's line confirms the line,
//                        not that e lies where A is: clutter along a border, past A's end, is
//                        not confirmed by it);
//     against A          duplicate(e, e2) x Bel(e2) for the same e2, where duplicate is the share
//                        of e's length that runs along e2's extent less its ends' noise
//                        (3 sqrt(2) sigma, at least 1 px, at each end of e2: two pieces of A may
//                        overlap that much where they meet, and nowhere else), at whatever
//                        offset from e2's line: A is one line in the image and an edge detector
//                        reports one edge where two coincide, so pieces of A do not run side by
//                        side, and the overlapping part of e is not A (a shadow 4-10 px beside
//                        A's piece is exactly this; with a fade by offset it escaped);
//                        likewise excess(e, e2), the share of e's length by which e and e2
//                        together, along A, exceed the longest A's image can be
//                        (PanelEdge::longest_px): a fragment continuing A's line past e2's end,
//                        within the pose's margin there (a shadow of the next edge, clutter),
//                        is no piece of A when e2 already is most of it. With
//                        not_A = max(duplicate, excess), the support above is taken times
//                        (1 - not_A), not_A x Bel(e2) is a piece against A, and the relational
//                        and junction support below is taken times (1 - the largest not_A x
//                        Bel(e2)): A's place is then explained by e2, not by e;
//     for / against A    compatibility(e, e2) x Bel(e2), incompatibility(e, e2) x Bel(e2) for
//                        the elements e2 labelled with an edge B sharing a visible face with A
//                        (collinearity.hpp: after the rigid motion T_{A->B}), pooled into one
//                        piece: their sums divided by max(1, sum of their beliefs), the support
//                        further weighed by kRelationalWeight. Pooled, because neighbours agree
//                        for one reason (the relation survives the same misregistration) and
//                        Dempster's rule would count that reason once per neighbour; weighed,
//                        because a relation cannot tell an edge from a parallel one a few pixels
//                        off (a shadow), which only the edge's own collinearity and its rivals
//                        for the same label can;
//     for / against A    junctions: at each vertex of the expected scene where A meets a model
//                        edge B (a piece of each ends there), the end q of an image edge e2
//                        labelled B nearest to an end p of e (within kJunctionGap pixels); with d
//                        the distance of q from e's line and t = max(1, 3 sqrt(2) noise (1 +
//                        |q - p| / |e|)) (two noisy end points, e's line extrapolated over the
//                        gap), junction = closeness(d, t) when e leaves p along A (toward A's
//                        other end, not past the vertex), else 0; pieces junction x Bel(e2) for
//                        and (1 - junction) x Bel(e2) against, pooled like the relational pairs.
//                        Where two edges meet is a fact of the image alone, kept by any
//                        misregistration, so its tolerance is the noise's: it tells an edge from
//                        a shadow or clutter a few pixels beside it, which its collinearity
//                        with A (under the pose's tolerance) and the symmetric rival evidence
//                        cannot (the grouping level's cue, used at the edge level);
//     against A          Bel(not F) of each image face F labelled with a face of A: "if a face is
//                        mislabeled, then all its constituent edges are also most likely
//                        mislabeled" (the survey's downward flow);
//     against A's object Bel(not O) of the image object labelled with A's object.
//   Every strength is at most kMaxSupport. The hypotheses of e form a tree: root -> one node per
//   object with a candidate -> its candidates (and one leaf for its other edges), plus a leaf
//   "none" (clutter, shadow); the pieces combine by Dempster's rule for hierarchical evidence
//   (hierarchical_evidence.hpp), so the object-level doubt bears on all of that object's
//   candidates at once. The combined beliefs (each candidate's and none's) are then discounted by
//   the element's reliability r = min(1, length / kReliableLength), Shafer's discounting of a
//   source (G. Shafer, A Mathematical Theory of Evidence, 1976, p. 252: Bel_r(A) = r Bel(A)): a
//   segment L pixels long shows its direction only to about sqrt(2) noise / L radians, so a
//   fragment of clutter or shadow a few pixels long near a model edge passes the collinearity
//   test far more often than a long one; at 10 px, 0.5 px of end-point noise leaves 4 degrees.
//   The new label is the candidate of highest discounted belief if that is at least
//   kMinimumLabelBelief, else none (and the element's belief is then Bel(none), discounted).
//   Neighbours count only from kMinimumNeighbourBelief: an element nobody believes says nothing.
//
// Example:
//   const Labeler labeler;
//   labeler.label(board);
//   for (int round = 0; round < 4; ++round) { labeler.update(board); Grouper().group(board); }
#pragma once

#include <vector>

#include "spar/sensing/pseiki/blackboard.hpp"
#include "spar/sensing/pseiki/hierarchical_evidence.hpp"

namespace spar::sensing::pseiki {

inline constexpr double kMinimumLabelBelief = 0.1;
inline constexpr double kMinimumNeighbourBelief = 0.05;
inline constexpr double kRelationalWeight = 0.5;
inline constexpr double kJunctionGap = 12;     // pixels between the ends of a junction's two edges
inline constexpr double kReliableLength = 10;  // pixels: an element this long is not discounted

// One element's hypotheses and evidence: the tree, the leaf of each candidate (in the element's
// candidate order) and the leaf "none".
struct ElementEvidence {
  HypothesisTree tree;
  std::vector<int> candidate_leaves;
  int none_leaf{-1};
};

class Labeler {
 public:
  explicit Labeler(int max_candidates = 4);
  void label(Blackboard& board) const;
  void update(Blackboard& board) const;
  // The evidence update() combines for `element`.
  [[nodiscard]] ElementEvidence evidence(const Blackboard& board, int element) const;

 private:
  int max_candidates_;
};

}  // namespace spar::sensing::pseiki
