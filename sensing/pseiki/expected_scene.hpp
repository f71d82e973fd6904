// PSEIKI's model panel: "a graphic rendition of the expected scene" (survey seed 003, section 4),
// the scene's objects at their believed poses seen by a camera, on the five levels of PSEIKI's
// blackboard. Built on render.hpp (visible faces, exact hidden-line removal between objects).
//
// Levels, each element defined by elements of the level below (ids are what `spar vision render`
// prints and what image labels name):
//   scene    the expected scene: every object with something visible;
//   objects  one per scene object ("block"), defined by its visible faces;
//   faces    "block/f3": a visible model face (numbered as `spar object` numbers faces) that has a
//            visible edge, defined by its visible edges; its region is the convex hull of their
//            vertices and its area the pixels it covers (the renderer's item buffer);
//   edges    "block/e5": a visible model edge (model_features.hpp numbering), defined by its
//            visible pieces (several when something hides its middle), each between two vertices;
//   vertices the pieces' end points, pixels (end points closer than 0.5 pixel are one vertex).
//
// Resolution: the panel holds what an edge detector can report. A visible piece shorter than
// kMinimumPiece (3 pixels, splitter.hpp; an edge seen end-on is a point) is not in it, and an edge
// whose every piece lies on a piece of a longer edge (both ends within kResolvePixels of its line,
// and along it) is seen as that edge (distinct_edges): the top and bottom rims of a hole seen down
// its axis, a post's foot on a border behind it. The simulator (simulate.hpp) applies the same
// rules to the true scene, so an image's edges carry ids the panel has (unless the perturbed pose
// itself makes an edge resolvable that the believed one did not).
//
// Tolerances: how far each expected edge may be from where it is seen. The uncertainty of the
// poses (each object's and the camera's half-widths {dx, dy, dz, dtheta}, applied as SPAR's eq. 2:
// trans(dx, dy, dz) Tr rotz(dtheta) R) moves the expected edges in the image; the panel projects
// every edge at each corner of each uncertainty box (the camera's, and the edge's object's: 2^k
// poses for k uncertain components) and keeps, per edge, the largest change of its line's angle,
// of its distance from the line, and of its end points along it. An edge's tolerance is the sum of
// what its object and the camera can do, plus the noise (3 sigma); `relational(a, b)` is the same
// for the relation between two edges of one face (collinearity.hpp's T_{A->B}): the largest error
// of predicting a from b across the corners. `longest_px` is the largest length of the whole edge's
// image across the same corners. Corners, not the whole box: the displacement of a
// projected point is nearly linear in the small offsets of a pose box; this is the documented
// approximation.
//
// Cost: one render, plus (corners x edges) projections and (corners x edge pairs sharing a face)
// predictions.
//
// Example:
//   Scene scene;  scene.add("block", block, block_features, pose);
//   const ModelPanel panel(scene, camera,
//                          {.objects = {{.dx = 0.005, .dtheta = 0.02}}, .noise_px = 0.5});
//   panel.edges[panel.edge_index("block/e5")].pieces;   // where e5 should be seen, pixels
//   panel.edges[0].tolerance.offset;                    // how far it may be off, pixels
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "spar/kinematics/uncertain_pose.hpp"
#include "spar/sensing/camera.hpp"
#include "spar/sensing/pseiki/collinearity.hpp"
#include "spar/sensing/pseiki/internal/polygon.hpp"
#include "spar/sensing/scene.hpp"

namespace spar::sensing::pseiki {

// How uncertain the expected scene is.
struct ExpectationUncertainty {
  std::vector<kinematics::PoseUncertainty> objects;  // [scene object]; empty: all exact
  kinematics::PoseUncertainty camera{};
  double noise_px{0};  // image noise, standard deviation of an edge end point
};

// Ends of a piece closer than this to another edge's line cannot be told from it (pixels): 1.5,
// three times the half-pixel noise of an edge detector's end points.
inline constexpr double kResolvePixels = 1.5;

// Per edge (its visible pieces, pixels, each at least kMinimumPiece long), whether an edge
// detector reports it as an edge of its own: false when it has no piece, or every piece lies on a
// piece of an edge kept before it, longest first (ties: the earlier).
[[nodiscard]] std::vector<bool> distinct_edges(std::span<const std::vector<Segment>> edges);

// SPAR's eq. 2 offset of a pose: trans(dx, dy, dz) Tr rotz(dtheta) R.
struct PoseOffset {
  double dx{0}, dy{0}, dz{0}, dtheta{0};
};
[[nodiscard]] Eigen::Isometry3d offset_pose(const Eigen::Isometry3d& pose,
                                            const PoseOffset& offset);

struct PanelVertex {
  Eigen::Vector2d pixel{Eigen::Vector2d::Zero()};
  std::vector<int> edges;  // panel edges with a piece ending here
};

struct PanelEdge {
  std::string id;                            // "<object>/e<model edge id>"
  int object{0};                             // scene object index
  int model_edge{0};                         // model edge id (model_features.hpp)
  std::vector<int> faces;                    // panel faces it bounds (visible ones)
  std::vector<Segment> pieces;               // visible pieces, pixels, along the edge
  std::vector<std::array<int, 2>> vertices;  // [piece] -> its end points' panel vertices
  Segment span;                              // first piece's start to last piece's end
  Eigen::Vector3d p0{Eigen::Vector3d::Zero()}, p1{Eigen::Vector3d::Zero()};  // object frame
  double visible_length{0};                                                  // pixels
  // The longest its image can be: the whole edge (whatever hides part of it now may move away)
  // at the worst corner of the uncertainty, plus two noisy ends (3 sqrt(2) sigma). Pieces of it
  // together are no longer (merger, labeler).
  double longest_px{0};
  bool silhouette{false};
  Tolerance tolerance;  // where the pose uncertainty and the noise may put it
};

struct PanelFace {
  std::string id;  // "<object>/f<model face id>"
  int object{0};
  int model_face{0};
  std::vector<int> edges;  // panel edges
  double area_px{0};       // pixels it covers
  internal::Polygon region;
};

struct PanelObject {
  std::string name;
  std::vector<int> faces, edges;                          // panel faces and edges
  double visible_length{0};                               // pixels, its edges'
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  // the believed pose
};

struct ExpectedSceneOptions {
  int supersampling{2};  // item-buffer samples per pixel side for the faces' areas
};

class ModelPanel {
 public:
  ModelPanel(const Scene& scene, const Camera& camera, const ExpectationUncertainty& uncertainty,
             const ExpectedSceneOptions& options = {});

  [[nodiscard]] const Camera& camera() const { return camera_; }
  [[nodiscard]] const std::vector<PanelVertex>& vertices() const { return vertices_; }
  [[nodiscard]] const std::vector<PanelEdge>& edges() const { return edges_; }
  [[nodiscard]] const std::vector<PanelFace>& faces() const { return faces_; }
  [[nodiscard]] const std::vector<PanelObject>& objects() const { return objects_; }  // [scene]
  [[nodiscard]] const ExpectationUncertainty& uncertainty() const { return uncertainty_; }

  // The panel edge with this id, or -1.
  [[nodiscard]] int edge_index(std::string_view id) const;
  // Edges sharing a visible face with `edge` (ascending, without it).
  [[nodiscard]] const std::vector<int>& neighbours(int edge) const {
    return neighbours_.at(static_cast<std::size_t>(edge));
  }
  // The tolerance of predicting edge `a` from edge `b` (neighbours only; SensingError otherwise).
  [[nodiscard]] const Tolerance& relational(int a, int b) const;

 private:
  Camera camera_;
  ExpectationUncertainty uncertainty_;
  std::vector<PanelVertex> vertices_;
  std::vector<PanelEdge> edges_;
  std::vector<PanelFace> faces_;
  std::vector<PanelObject> objects_;
  std::vector<std::vector<int>> neighbours_;
  std::map<std::pair<int, int>, Tolerance> relational_;
};

}  // namespace spar::sensing::pseiki
