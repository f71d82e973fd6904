// Simulated edge images for PSEIKI: what an edge-based preprocessor would report for a scene whose
// true poses differ from the believed ones, for tests, demos and users without a camera.
//
// The true poses: each object's and the camera's believed pose offset by eq. 2 offsets (dx, dy,
// dz, dtheta) drawn uniformly within `pose_scale` times the half-widths. The true scene is
// rendered (render.hpp: exact hidden-line removal); the edge pieces an edge detector resolves
// (expected_scene.hpp's Resolution: none under kMinimumPiece pixels, an edge lying on a longer one
// is seen as that one) go through, in this order:
//   drop     a share `drop` of the pieces, chosen at random, is lost (exactly round(drop n) of
//            the n pieces);
//   split    a share `split` of the others is cut in two at a uniform point of its middle 40%,
//            with a gap of 1-4 pixels;
//   join     two pieces of different model edges that continue each other (end points within 1.5
//            pixels, lines within 0.6 degrees) come as one edge with probability `join`, as an
//            edge detector sees the border of a sidewalk across its slabs;
//   noise    every end point moves by N(0, noise_px^2) in u and in v;
//   shadow   a share `shadow` of the pieces gets a parallel edge 4-10 pixels to one side, half to
//            all of its length (a cast shadow's border);
//   clutter  `clutter` segments of 10-60 pixels, uniform in position and direction;
// (a shadow or clutter edge that would lie on a true edge, both ends within 3 pixels of its line
// and along it, is drawn again, up to 20 times: an edge detector reports one edge where two
// coincide), then everything is clipped to the image and shuffled. Each edge keeps its truth: the
// model-panel id of the edge it came from ("block/e5"), ids joined by "+" for a joined edge, "" for
// shadows and clutter. A std::mt19937_64 seeded with `seed` draws everything, so a seed gives one
// image.
//
// Example:
//   const SimulatedImage image = simulate(scene, camera, uncertainty,
//                                         {.noise_px = 0.5, .drop = 0.2, .clutter = 10}, 7);
//   image.edges[0].truth;   // "block/e5", or "" for clutter
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spar/sensing/pseiki/blackboard.hpp"
#include "spar/sensing/pseiki/expected_scene.hpp"

namespace spar::sensing::pseiki {

struct ImagePerturbation {
  double pose_scale{1};  // of the half-widths; 0 keeps the believed poses
  double noise_px{0};
  double drop{0};
  double split{0};
  double join{0};
  double shadow{0};
  int clutter{0};
};

struct SimulatedEdge {
  ImageEdgeInput edge;
  std::string truth;
};

struct SimulatedImage {
  std::vector<SimulatedEdge> edges;
  std::vector<PoseOffset> object_offsets;  // [scene object]: true pose = offset_pose(believed, .)
  PoseOffset camera_offset;
};

// SensingError for a share or probability outside [0, 1], a negative noise, scale or clutter count,
// or more than kMaxClutter clutter edges. `uncertainty.objects` is empty or one per scene object.
[[nodiscard]] SimulatedImage simulate(const Scene& scene, const Camera& camera,
                                      const ExpectationUncertainty& uncertainty,
                                      const ImagePerturbation& perturbation, std::uint64_t seed);

inline constexpr int kMaxClutter = 100000;

}  // namespace spar::sensing::pseiki
