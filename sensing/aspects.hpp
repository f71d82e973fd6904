// Aspects of an object (the survey's section 3): the view directions from which a sensor sees the
// same set of faces, grouped. An aspect is that set of faces; its viewpoints are every direction
// that sees exactly it (possibly several separate regions of the view sphere), so aspects
// quantise the space of sensing operations, and looking up the aspect of a direction tells which
// features a sensor observes from there.
//
// Viewing is orthographic: a direction d (unit, object frame, from the object toward the viewer)
// sees face f when some part of f is unoccluded along d and the angle between d and f's outward
// normal is below `max_angle` (default 75°; in (0°, 90°]): a face seen edge-on yields no data, so
// face-on and edge-on views have finite extent.
//
// Methods (AspectSet::method says which one ran):
//   exact arrangement  for a convex object (every vertex on or behind every face's plane) of at
//     most kExactFaceLimit faces. Nothing occludes, so d sees f iff d · n_f > cos(max_angle): the
//     aspects are the cells of the arrangement of those circles on the sphere. A sweep in height
//     z along a fixed generic axis finds them: between consecutive critical heights (the circles'
//     highest and lowest points and their pairwise crossings) the cells met by every circle of
//     latitude are the same, and each latitude's cells are exact intervals of longitude. A solid
//     angle is the integral over z of the longitude the cell takes (Archimedes: dA = dz dφ), by
//     20-point Gauss-Legendre per band after the substitution z = a + (b - a)(1 - cos t)/2, which
//     absorbs the square-root behaviour at a circle's extreme; solid angles are good to ~1e-9 sr.
//     Cells below 1e-10 sr (degenerate arrangements, e.g. three circles through one point) are
//     dropped. Cost O(n^3 log n) for n faces.
//   view sphere  otherwise: the icosahedron subdivided `view_sphere_level` times (20 · 4^L
//     spherical triangles; L = 3: 1280 cells about 6° apart), each cell seen along its centre
//     direction through an orthographic item buffer (render.hpp) of `resolution` x `resolution`
//     samples across the object's bounding sphere; a face holding at least one sample and within
//     `max_angle` is seen. An aspect's solid angle is the sum of its cells' exact spherical areas.
//     Faces or regions smaller than a sample or a cell can be missed (a face seen only as a sliver
//     near the edge of its visibility region is seen over a slightly smaller region): that is the
//     documented resolution. Cost O(cells · (T + resolution²)) for T triangles.
// Both: the empty set is an aspect when some directions see no face (only for small max_angle).
// Aspects are ordered by their face lists (ascending ids, compared lexicographically) and
// labelled "A1", "A2", ... in that order; solid angles sum to 4π. The representative direction
// is the normalised mean of the aspect's directions when it sees the aspect, else (exact) the
// middle of the aspect's longest latitude interval or (view sphere) its cell nearest that mean.
//
// Prominence (aspect_features): what a sensor at the representative direction gets of each
// feature, as sensors.hpp defines it: a face is fully prominent when it fills a tenth of the
// object's image, an edge when it is a tenth of the object's diameter long with full contrast.
//
// Example:
//   const ObjectModel cube("cube", make_box({1, 1, 1}));
//   const AspectSet aspects = compute_aspects(cube);
//   aspects.aspects.size();                           // 26: 6 faces, 12 pairs, 8 corners
//   aspects.aspects[0].solid_angle;                   // sr
//   aspects.aspect_at({0, 0, 1});                     // index of the aspect {top face}
#pragma once

#include <Eigen/Core>
#include <numbers>
#include <string>
#include <vector>

#include "spar/geometry/object.hpp"
#include "spar/sensing/model_features.hpp"

namespace spar::sensing {

inline constexpr int kExactFaceLimit = 64;

struct AspectOptions {
  double max_angle{75 * std::numbers::pi / 180};  // radians, in (0, pi/2]
  int view_sphere_level{3};                       // 0 to 6
  int resolution{128};                            // item-buffer samples across, 16 to 1024
  bool force_view_sphere{false};                  // the view sphere even for a convex object
};

enum class AspectMethod { kExactArrangement, kViewSphere };
[[nodiscard]] const char* to_string(AspectMethod method);  // "exact arrangement", "view sphere"

struct Aspect {
  std::string label;          // "A1", "A2", ...
  std::vector<int> faces;     // face ids seen, ascending
  double solid_angle{0};      // sr
  Eigen::Vector3d direction;  // representative, unit, object frame, toward the viewer
};

struct ViewCell {
  Eigen::Vector3d direction;  // unit, the cell's centre
  double solid_angle{0};
  int aspect{0};  // index into AspectSet::aspects
};

struct AspectSet {
  AspectMethod method{AspectMethod::kExactArrangement};
  double max_angle{0};
  std::vector<Aspect> aspects;
  std::vector<ViewCell> cells;           // the view sphere's cells (empty for the exact method)
  std::vector<Eigen::Vector3d> normals;  // the faces' outward normals (exact method lookups)
  double cos_max_angle{0};
  // The index of the aspect seen from `direction` (any non-zero vector, object frame), or -1 when
  // it sees a set of faces no aspect has (the exact method on a boundary of measure zero).
  [[nodiscard]] int aspect_at(const Eigen::Vector3d& direction) const;
};

// The unit directions of the view sphere's cells at `level` (0 to 6): the centres of the
// icosphere's 20 · 4^level spherical triangles, the view sphere method's directions.
[[nodiscard]] std::vector<Eigen::Vector3d> view_directions(int level);

// SensingError for options out of range.
[[nodiscard]] AspectSet compute_aspects(const geometry::ObjectModel& model,
                                        const AspectOptions& options = {});

// The faces seen from `direction` by the definition above: exact for a convex object, else an
// item buffer of `options.resolution` samples across.
[[nodiscard]] std::vector<int> faces_seen(const geometry::ObjectModel& model,
                                          const Eigen::Vector3d& direction,
                                          const AspectOptions& options = {});

struct FaceProminence {
  int face{0};
  double visible_area{0};  // m², projected on the image plane
  double prominence{0};    // in [0, 1]
};
struct EdgeProminence {
  int edge{0};
  double visible_length{0};  // m, projected on the image plane
  double contrast{0};
  double prominence{0};
};
struct AspectFeatures {
  std::vector<FaceProminence> faces;  // the aspect's faces, ascending
  std::vector<EdgeProminence> edges;  // visible edges, ascending id
};

// The features seen from the aspect's representative direction, with their prominence.
[[nodiscard]] AspectFeatures aspect_features(const geometry::ObjectModel& model,
                                             const ObjectFeatures& features, const Aspect& aspect,
                                             const AspectOptions& options = {});

}  // namespace spar::sensing
