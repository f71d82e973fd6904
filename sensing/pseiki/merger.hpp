// The merger, PSEIKI's knowledge source that merges "multiple elements on a single level of the
// blackboard into an element at the same level" (survey seed 003, section 4): the survey's
// "top:38%" edge made of two segments.
//
// At the edge level: active elements with the same label A are taken in order along A's line;
// consecutive ones merge when they are collinear with each other (edge_collinearity under the
// image noise, at least kMergeCollinearity) and the merged edge still lies within A's extent (its
// overlap with A, under A's tolerance, at least kMergeOverlap) and is no longer than A's image can
// be (`PanelEdge::longest_px`), so pieces of two collinear model edges (two slabs of one sidewalk
// border) are not joined, nor a short edge and a shadow or clutter fragment continuing its line
// within the pose's tolerance of its end. A merged element lies on the
// total-least-squares line through its parts' end points (weighted by the parts' lengths),
// between their extreme projections; its parts become inactive and it has no candidates yet (the
// labeler labels it again, now with the overlap of the whole).
//
// Example:
//   Merger().merge(board);        // after Labeler::label
//   Labeler().label(board);       // candidates for the merged elements
#pragma once

#include "spar/sensing/pseiki/blackboard.hpp"

namespace spar::sensing::pseiki {

inline constexpr double kMergeCollinearity = 0.5;
inline constexpr double kMergeOverlap = 0.95;

class Merger {
 public:
  // Returns how many merged elements it made.
  int merge(Blackboard& board) const;
};

}  // namespace spar::sensing::pseiki
