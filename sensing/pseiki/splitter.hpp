// The splitter, PSEIKI's knowledge source that "splits a single element on the blackboard into
// multiple smaller elements" (survey seed 003, section 4): at the edge level, an image edge that
// runs along two or more collinear model edges (the border of a sidewalk across two slabs, seen
// as one line) becomes one piece per model edge.
//
// An active element whose best candidate covers less than kSplitOverlap of it (the overlap term
// of collinearity.hpp) is split when at least two model edges lie along its line (angle and offset
// terms of their collinearity with it, under their tolerances, both at least kSplitLine) and
// their extents, projected on it, leave cut points inside it: midway between one model edge's end
// and the next one's start (or the middle of their overlap). Pieces shorter than kMinimumPiece
// pixels are dropped. The pieces keep the element's inputs and point back at it (split_from); the
// element becomes inactive. The labeler labels the pieces.
//
// Example:
//   Splitter().split(board);      // after Labeler::label
//   Labeler().label(board);       // candidates for the pieces
#pragma once

#include "spar/sensing/pseiki/blackboard.hpp"

namespace spar::sensing::pseiki {

inline constexpr double kSplitOverlap = 0.9;
inline constexpr double kSplitLine = 0.5;
inline constexpr double kMinimumPiece = 3.0;  // pixels

class Splitter {
 public:
  // Returns how many elements it split.
  int split(Blackboard& board) const;
};

}  // namespace spar::sensing::pseiki
