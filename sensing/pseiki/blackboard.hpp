// PSEIKI's blackboard (survey seed 003, section 4, Fig. 10): two panels of five levels each. The
// model panel (expected_scene.hpp) holds the expected scene; the image panel, here, holds the
// image data and what the knowledge sources build from it:
//   vertices  end points of the image edges (end points within 2 sigma + 1 pixel are one vertex);
//   edges     elements made of the input edges: one each at first, then merged (merger.hpp: two
//             pieces of one edge) or split (splitter.hpp: one edge across two model edges). Each
//             carries its label (a model-panel edge or none) and Bel(label);
//   faces     groups of edges labelled with edges of one model face (grouper.hpp), labelled with
//             that face;
//   objects   groups of faces labelled with faces of one model object;
//   scene     the whole interpretation, labelled "the expected scene", whose belief decides.
// Knowledge sources (labeler.hpp, merger.hpp, splitter.hpp, grouper.hpp) read and write it; the
// matcher (matcher.hpp) schedules them.
//
// Invariants: an element that was merged or split stays in `edges` (its index is its identity)
// with active == false; every input edge is in exactly one active element, or in the pieces of
// one split element; labels index model().edges() (or are -1); beliefs are in [0, 1].
//
// Example:
//   Blackboard board(panel, {{"e1", {{10, 20}, {90, 20}}}}, 0.9);
//   Labeler().label(board);
//   board.edges[0].label;   // the panel edge e1 is most collinear with
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "spar/sensing/pseiki/collinearity.hpp"
#include "spar/sensing/pseiki/expected_scene.hpp"
#include "spar/sensing/pseiki/internal/polygon.hpp"

namespace spar::sensing::pseiki {

// An edge as the low-level vision system reports it.
struct ImageEdgeInput {
  std::string id;
  Segment segment;
};

struct LabelCandidate {
  int edge{-1};            // panel edge
  double collinearity{0};  // with the element, under the edge's tolerance
  double belief{0};        // Bel after the last update
};

struct ImageEdge {
  Segment segment;
  std::vector<int> inputs{};  // input edges it is made of (several once merged)
  int split_from{-1};         // the element this is a piece of, -1 if none
  bool active{true};          // false once merged into another element or split into pieces
  std::vector<LabelCandidate> candidates{};  // most collinear first
  int label{-1};                             // panel edge, or -1 (none)
  double belief{0};                          // Bel(label); for no label, Bel(none)
  std::array<int, 2> vertices{-1, -1};
};

struct ImageVertex {
  Eigen::Vector2d pixel{Eigen::Vector2d::Zero()};
  std::vector<int> edges;
};

struct ImageFace {
  int label{-1};               // panel face
  std::vector<int> members{};  // image edges
  internal::Polygon region{};  // convex hull of the members' vertices
  double support{0};           // what its members say for its label (grouper.hpp)
  double belief{0}, disbelief{0};
};

struct ImageObject {
  int label{-1};             // panel object (= scene object index)
  std::vector<int> faces{};  // image faces
  double coverage{0};        // fraction of its expected edge length seen and labelled
  double belief{0}, disbelief{0};
};

struct ImageScene {
  double belief{0}, disbelief{0};
};

class Blackboard {
 public:
  // `detection_probability`: the share of the expected edges the camera finds (in (0, 1]).
  Blackboard(const ModelPanel& model, std::vector<ImageEdgeInput> image,
             double detection_probability);

  [[nodiscard]] const ModelPanel& model() const { return *model_; }
  [[nodiscard]] const std::vector<ImageEdgeInput>& inputs() const { return inputs_; }
  [[nodiscard]] double detection_probability() const { return detection_probability_; }

  // Adds an element and returns its index.
  int add_edge(ImageEdge edge);
  // The vertex level again from the active elements' end points.
  void connect_vertices();
  // The active element holding input `input` (for a split input: the longest piece), or -1.
  [[nodiscard]] int element_of(int input) const;

  std::vector<ImageVertex> vertices;
  std::vector<ImageEdge> edges;
  std::vector<ImageFace> faces;
  std::vector<ImageObject> objects;  // one per visible model object, found or not
  ImageScene scene;

 private:
  const ModelPanel* model_;  // not owned: outlives the blackboard
  std::vector<ImageEdgeInput> inputs_;
  double detection_probability_{1};
};

// The largest support one piece of evidence may give: a measured degree of collinearity never
// proves a label, and two certain pieces for and against would conflict totally.
inline constexpr double kMaxSupport = 0.99;
[[nodiscard]] inline double capped(double support) { return std::clamp(support, 0.0, kMaxSupport); }
// An image edge counts as a detection of its label from this belief on (the deficit of objects,
// grouper.hpp), and below it clutter counts as unlabelled.
inline constexpr double kDetectionBelief = 0.2;

}  // namespace spar::sensing::pseiki
