// What a camera sees of a scene, with occlusion between objects: the visible faces (and how much
// of each), and the visible pieces of the model edges (hidden-line removal), each labelled with
// its object and model face or edge id. The simulated sensors (sensors.hpp), the aspects of
// objects (aspects.hpp) and PSEIKI's expected scene are built on it.
//
// Turned toward the camera: the eye lies in front of the face's plane by more than 1e-9 of the
//   scene's scale (pinhole), or the view direction makes a cosine above 1e-9 with the face's
//   normal (orthographic); a face seen edge-on to rounding is turned away.
// Faces: an item buffer (z-buffer holding the nearest triangle at each sample) of the camera's
//   own resolution times `supersampling` per side, sampled at sample centres; triangles turned
//   away from the camera are not drawn (the objects are closed, so the nearest surface along any
//   ray faces the camera). A face is visible when it holds at least one sample; its visible area
//   is the sum of its samples' footprints on the face's plane (so it converges to the exact area
//   as the resolution grows: one sample's footprint is the error bound per boundary sample), and
//   its visible centroid the footprint-weighted mean of the samples' surface points. Faces
//   smaller than a sample can be missed: that is the documented resolution.
// Edges: exact segment clipping in 3D, no raster. An edge is a candidate when at least one of its
//   two faces is turned toward the camera (a silhouette when exactly one is). It is clipped to the
//   view volume (the image rectangle and, for a pinhole, the near plane), then against the shadow
//   volume of every front-facing triangle of every object whose screen box meets it: the points
//   behind the triangle's plane (by more than 1e-9 of the scene's scale, so edges on the
//   triangle's own plane are never hidden by it) and inside the three planes through the eye
//   (pinhole) or along the view direction (orthographic) and the triangle's sides. What no
//   shadow volume covers is visible; pieces shorter than 1e-9 of the scene's scale are dropped.
//   A screen grid of 16-pixel tiles finds the triangles that can cover a segment.
// Contrast of an edge piece: 1 on a silhouette (the object against what lies behind), else the
//   difference of the two faces' Lambertian shading under a light at the camera,
//   |n_a · t - n_b · t| with t the unit direction toward the viewer at the piece's midpoint.
//
// Cost: faces O(T + samples) per render for T triangles; edges O(E k) for E candidate edges and k
// triangles per tile they cross.
//
// Example:
//   Scene scene;  scene.add("block", block, block_features, pose);
//   const Rendering seen = render(scene, camera);
//   for (const FaceView& face : seen.faces) std::cout << face.face << ' ' << face.visible_area;
//   for (const EdgeView& edge : seen.edges) std::cout << edge.edge << ' ' << edge.u0.transpose();
#pragma once

#include <Eigen/Core>
#include <vector>

#include "spar/sensing/camera.hpp"
#include "spar/sensing/scene.hpp"

namespace spar::sensing {

struct RenderOptions {
  bool faces{true};      // the item buffer and the visible faces
  bool edges{true};      // the visible edge pieces
  int supersampling{1};  // item-buffer samples per pixel side, 1 to 8
};

struct FaceView {
  int object{0};  // index in the scene
  int face{0};    // model face id
  int samples{0};
  double visible_area{0};      // m², on the face's plane
  double visible_fraction{0};  // visible_area / the face's area (may exceed 1 by the resolution)
  double angle{0};  // between the outward normal and the direction to the viewer at the centroid
  Eigen::Vector3d centroid{Eigen::Vector3d::Zero()};  // of the visible part, world frame
};

// One visible piece of a model edge; an edge partly hidden gives several pieces.
struct EdgeView {
  int object{0};
  int edge{0};                                                               // model edge id
  Eigen::Vector3d p0{Eigen::Vector3d::Zero()}, p1{Eigen::Vector3d::Zero()};  // world frame
  Eigen::Vector2d u0{Eigen::Vector2d::Zero()}, u1{Eigen::Vector2d::Zero()};  // pixels
  bool silhouette{false};
  double contrast{0};  // in [0, 1]
};

struct Rendering {
  std::vector<FaceView> faces;  // visible faces, by (object, face)
  std::vector<EdgeView> edges;  // visible pieces, by (object, edge, position along the edge)
};

[[nodiscard]] Rendering render(const Scene& scene, const Camera& camera,
                               const RenderOptions& options = {});

}  // namespace spar::sensing
