// The grouper, PSEIKI's knowledge source that "determines which image elements in the lower
// levels of the hierarchy should be grouped to form an image element on a higher level" (survey
// seed 003, section 4): compatibly labelled edges into faces, faces into objects, objects into the
// scene, each with the belief in its label. Beliefs flow up ("any evidence confirming a data
// element's label should also provide evidence that its parent's label is correct"); doubt flows
// down through the labeler's next round.
//
// Faces. For every visible model face F, the image face F' is the set of active edges labelled
//   with F's edges (none: no image face). Its region is the convex hull of its members' vertices.
//   Evidence, combined by Dempster's rule for hierarchical evidence (root -> F's object -> F and
//   the object's other faces; "none"):
//     for F        support(F') = min(kMaxSupport, sum over F's edges m of w_m c_m b_m / p), with
//                  w_m m's share of F's visible edge length, c_m the fraction of m's visible
//                  length its members cover (their projections on m's line, merged), b_m their
//                  length-weighted mean belief, p the camera's detection probability: a face
//                  seen as well as the camera can see it gets full support;
//     against F    for every other image face G': the survey's face-level incompatibility, the
//                  overlap of the two regions normalised by their mean area, less the same
//                  quantity of the two model faces (faces of a non-convex object overlap in the
//                  expected scene too), times support(G');
//     against F's object   Bel(not O) of its image object from the previous round.
// Objects. For every visible model object O, the image object O' (made of the image faces with
//   O's faces; it exists even with none, so that a missing object counts against the scene):
//     for O        sum over O's faces F of a_F Bel(F'), a_F F's share of O's visible area;
//     against O    the deficit of seen edges: coverage(O') = the fraction of O's visible edge
//                  length covered by its edges' members of belief >= kDetectionBelief. A camera
//                  that finds each edge with probability p, independently, gives an object that
//                  is where it was believed a coverage sum_m l_m X_m / sum_m l_m (X_m Bernoulli
//                  p, l_m the visible lengths); coverage below floor = that distribution's
//                  kCoverageQuantile quantile (coverage_floor, exact) says the object is not
//                  where it was believed to be (missing, moved, another object): deficit =
//                  (floor - coverage) / floor, clamped to [0, kMaxSupport]. Exact, not the
//                  normal approximation p - 2 sigma: an object whose length is in a few long
//                  edges (the sidewalk's two borders hold 58% of it) loses both together with
//                  probability (1 - p)^2 = 4%, far more often than a normal tail says.
// Scene. Evidence for "the image is the expected scene": for it, the mean over the visible
//   objects of Bel(O'), each object one vote (verification asks whether every object is where it
//   was believed: weighted by visible length, a sidewalk's borders outvoted a lamp replaced by a
//   bench, 7 of 200 such images accepted); against it, each object's Bel(not O') as a piece of
//   its own (one missing object contradicts the scene).
//
// Example:
//   Grouper().group(board);
//   board.scene.belief;             // the top of the hierarchy: accept above the threshold
//   board.faces[0].members;         // image edges of the first face found
#pragma once

#include <vector>

#include "spar/sensing/pseiki/blackboard.hpp"

namespace spar::sensing::pseiki {

// The tail of an object's coverage distribution below its floor: that of 2 standard deviations
// of a normal (the level of the approximation the exact floor replaced).
inline constexpr double kCoverageQuantile = 0.0228;

// The kCoverageQuantile quantile of the coverage of an object with edges of these visible
// lengths, each found with probability `detection_probability`, independently; built exactly on
// a grid of about 1/1024 (each edge's share rounded to it), O(edges x 1024). 0 when there is no
// length; 1 when p = 1.
[[nodiscard]] double coverage_floor(const std::vector<double>& lengths,
                                    double detection_probability);

class Grouper {
 public:
  void group(Blackboard& board) const;
  // The three levels separately (group() runs them in order).
  void group_faces(Blackboard& board) const;
  void group_objects(Blackboard& board) const;
  void group_scene(Blackboard& board) const;
};

}  // namespace spar::sensing::pseiki
