// Hypotheses about one object and the Dempster-Shafer evidence an observation gives them (the
// survey's section 3). A hypothesis says how the object is (its identity, its stable pose): under
// it the sensor should see the object's `Expectation`, rendered from the same sensor pose in the
// scene as it would then be (sensors.hpp's prediction, the object's features only, each with its
// prominence). An observation is matched against every hypothesis' expectation and yields three
// kinds of evidence, all on the frame of the hypotheses:
//
//   feature     one source per sensed feature s of the object. Its match quality under h is
//               q_h = max over h's expected features f of similarity(s, f) (below). The source is
//               consonant: with q sorted q(1) >= ... >= q(n) and A_k the k best hypotheses,
//               m(A_k) = κ (q(k) - q(k+1)) for k < n and m(frame) = 1 - κ (q(1) - q(n)), so
//               Pl({h}) = 1 - κ (q(1) - q_h): a feature that every hypothesis explains equally is
//               no evidence, one that only h explains supports h. A feature that no hypothesis
//               explains (best q < 0.05: clutter, another object) is no evidence either.
//   relation    one source per sensed feature s (with at least two features): the consistency of
//               s's relations to the other sensed features with the relations of their matched
//               model features under h, r_h = the mean over the others s' of
//               exp(-½ (Δangle/σ_angle)²) exp(-½ (Δdistance/σ_distance)²), where Δ compares the
//               angle between the two normals (faces) or lines (edges) and the distance between
//               the two positions (faces, metres) or midpoints (edges, pixels) with the model's;
//               two sensed features matched to one model feature are inconsistent (0);
//               σ_angle = √2 σ_normal and σ_distance = √2 σ_position (faces) or √2 σ_pixels
//               (edges). Consonant as above, on r_h. Relations do not move with the object, so they
//               keep working when absolute positions are blurred by its pose uncertainty.
//   expected    one source per feature f a hypothesis h expects (with n >= 2 hypotheses): a
//               prominent expected feature that was not observed is evidence against h, as
//               strong as the sensor's detection probability P_d makes a miss surprising:
//               m(frame \ {h}) = κ P_d (1 - max_s similarity(s, f)) p_f / max p (p the expected
//               features' prominences), m(frame) the rest; below 0.05 it is left out.
// κ = kMaxSupport = 0.9: no source is ever certain, so every source keeps mass on the whole frame
// and the combination never conflicts totally.
// Similarity: faces exp(-½ (θ/σ_normal)²) exp(-½ (d/σ_position)²) exp(-½ (ln(a_s/a_f)/0.25)²)
//   with θ the angle between the normals, d the distance between the visible centroids and a the
//   visible areas; edges exp(-½ (d/σ_pixels)²) with d the mean distance of the endpoints (paired
//   the nearer way).
// Segmentation: the sensed features of the object are those inside the region where some
//   hypothesis puts it (faces: its bounding sphere grown by 3 σ_position; edges: the image box of
//   that sphere grown by 3 σ_pixels); the sensor reports every object's features, and nothing
//   here reads their `truth_*` labels.
//
// Example:
//   const Frame frame({"P3", "P5"});
//   const std::vector<Expectation> expected = {expect(scene_p3, 0, scanner, pose),
//                                              expect(scene_p5, 0, scanner, pose)};
//   const Weighing weighed = weigh_evidence(measured, expected, tolerances, scanner,
//                                           MassFunction::vacuous(2));
//   weighed.combined.pignistic();   // BetP of P3 and P5
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "spar/sensing/evidence.hpp"
#include "spar/sensing/scene.hpp"
#include "spar/sensing/sensors.hpp"

namespace spar::sensing {

inline constexpr double kMaxSupport = 0.9;

// What one hypothesis predicts the sensor sees of the object, and where it puts the object.
struct Expectation {
  std::vector<SensedFace> faces;                    // the object's predicted faces (range scanner)
  std::vector<SensedEdge> edges;                    // the object's predicted edges (camera)
  Eigen::Vector3d centre{Eigen::Vector3d::Zero()};  // of the object's bounding sphere, world
  double radius{0};
  Eigen::AlignedBox2d image_box;  // the sphere's projection (pinhole: of its bounding box)
};

// The expectation of object `target` of `scene` for `sensor` at `sensor_pose`.
[[nodiscard]] Expectation expect(const Scene& scene, int target, const SensorModel& sensor,
                                 const Eigen::Isometry3d& sensor_pose);

// How far a sensed feature may lie from its model feature and still match (standard deviations).
struct MatchTolerances {
  double normal{0.05};     // rad
  double position{0.005};  // m
  double pixels{2.0};      // px
};
// The sensor's noise combined with the object's pose uncertainty: half-widths dx, dy, dz (m)
// and dθ (rad) of an object of bounding radius `radius` seen at `distance` (m) by the sensor.
// Floors: 2° for normals, 2 mm for positions, 1 px for pixels.
[[nodiscard]] MatchTolerances match_tolerances(const SensorModel& sensor, double dx, double dy,
                                               double dz, double dtheta, double radius,
                                               double distance);

struct Weighing {
  std::vector<MassFunction> sources;
  std::vector<std::string> kinds;  // "prior", "feature", "relation", "expected" per source
  MassFunction combined;           // Dempster's combination of all sources
  double conflict{0};
  int features{0};  // sensed features attributed to the object
};

// The evidence `observed` gives the hypotheses whose expectations are `expected` (one per
// hypothesis, the frame's order), combined with `prior` (first source). SensingError if the
// sizes disagree.
[[nodiscard]] Weighing weigh_evidence(const Observation& observed,
                                      const std::vector<Expectation>& expected,
                                      const MatchTolerances& tolerances, const SensorModel& sensor,
                                      const MassFunction& prior);

// The consonant mass function of possibilities `level` (one per hypothesis, in [0, 1]) scaled by
// kMaxSupport, as the feature source above builds it.
[[nodiscard]] MassFunction consonant_support(const std::vector<double>& level);

}  // namespace spar::sensing
