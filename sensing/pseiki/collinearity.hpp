// PSEIKI's geometric measures between edges in the image plane (survey seed 003, section 4): the
// degree of collinearity of an image edge with a model edge (the initial label and its belief),
// collinearity and noncollinearity of two image edges with the same label, and compatibility of
// two image edges with different labels after the rigid motion T_{E_A->E_B}.
//
// Every measure is in [0, 1] and built from one kernel, closeness(x, t) = max(0, 1 - (x / t)^2):
// 1 at x = 0, 0 from x = t on, flat near 0 so that noise well inside the tolerance costs little.
//
// Degree of collinearity of an image edge e with a model edge m (its visible pieces, pixels):
//   angle    theta = the acute angle between the two lines (radians, in [0, pi/2]);
//   offset   d = the distance (pixels) of e's midpoint from m's line;
//   overlap  o = the fraction of e's length whose projection on m's line falls inside m's pieces,
//            each extended by the tolerance's margin at both ends (e may be a piece of m, so only
//            the part of e outside m counts against it);
//   collinearity(e, m) = closeness(theta, t_angle(e)) * closeness(d, t_offset) * o.
// It is 1 exactly when e lies on m's line inside m's extent. The tolerances are what the
// expected scene's pose uncertainty can move m by in the image (expected_scene.hpp works them out
// at the corners of the uncertainty box) plus the image noise: t_angle(e) = t.angle +
// atan(3 sqrt(2) noise / |e|) (a short edge's direction is less certain), t_offset = t.offset.
//
// Two image edges with the same label (both pieces of one model edge) lie on one line, whatever
// the misregistration: their tolerance is the noise's alone (Tolerance::noise_only). Angle theta
// between them, offset d = the larger distance of either midpoint from the other's line:
//   collinearity(e1, e2)    = closeness(theta, t_angle) * closeness(d, t_offset),
//   noncollinearity(e1, e2) = 1 - closeness(theta, 2 t_angle) * closeness(d, 2 t_offset):
// evidence for the shared label, against it, and between one and two tolerances neither in full
// (Dempster-Shafer's room for ignorance). Overlap is not used: two detections of one edge may
// overlap.
//
// Different labels: image edges e1 and e3 labelled with model edges A and B. T_{A->B} is the
// rigid motion of the image plane that makes B collinear with A. Applied in the image it must be
// conjugated by the misregistration G that carries B onto e3 (rotation by the angle from B to e3,
// then B's midpoint onto e3's midpoint): the survey's collinearity(e1, T(e3)) is then
// collinearity(e1, G(A)), "does e1 lie where A must be, if e3 is B?", with
// compatibility(e1, e3) = collinearity(e1, G(A)) under the pair's relational tolerance, and
// incompatibility = 1 - the same with doubled tolerances. G is exact when e3 is all of B; when
// e3 is shorter than B's expected image (a piece of it), where it sits along B is unknown by half
// the difference, s, which widens the offset tolerance by s |sin phi| and the margin by s
// |cos phi| (phi the angle between A and B). The relational tolerance is what the pose
// uncertainty can change of the relation (expected_scene.hpp), much less than what it can move
// either edge: the relation survives misregistration (any rigid motion of the image keeps it).
//
// Example:
//   const Segment model{{0, 0}, {100, 0}};
//   const Tolerance tolerance{.angle = 0.05, .offset = 4, .margin = 5, .noise_px = 0.5};
//   collinearity({{10, 1}, {60, 1}}, std::span(&model, 1), tolerance);   // (1 - 1/16) * 1 * 1
//   edge_collinearity({{0, 0}, {40, 0}}, {{60, 0.5}, {90, 0.5}}, Tolerance::noise_only(0.5));
#pragma once

#include <Eigen/Core>
#include <span>

namespace spar::sensing::pseiki {

// A straight edge in the image, pixels.
struct Segment {
  Eigen::Vector2d p0{Eigen::Vector2d::Zero()}, p1{Eigen::Vector2d::Zero()};
  [[nodiscard]] double length() const { return (p1 - p0).norm(); }
  [[nodiscard]] Eigen::Vector2d midpoint() const { return 0.5 * (p0 + p1); }
  // Unit direction p0 -> p1 (zero for a point).
  [[nodiscard]] Eigen::Vector2d direction() const;
  // The distance of `point` from this segment's line.
  [[nodiscard]] double line_distance(const Eigen::Vector2d& point) const;
};

// The acute angle between two segments' lines, radians in [0, pi/2].
[[nodiscard]] double line_angle(const Segment& a, const Segment& b);

// How far a measurement may stray: the lines' angle (radians), perpendicular offset and along-line
// margin (pixels), and the image noise (pixels, standard deviation of an end point).
struct Tolerance {
  double angle{0}, offset{0}, margin{0}, noise_px{0};
  // The tolerance of two edges of one image: noise alone (3 sigma of the offset, at least half a
  // pixel; the angle from the edges' lengths).
  [[nodiscard]] static Tolerance noise_only(double noise_px);
};

// The smallest tolerances used whatever the uncertainty: a perfect image still has its pixels.
inline constexpr double kMinimumOffsetPx = 0.5;
inline constexpr double kMinimumAngle = 0.0035;  // 0.2 degrees

[[nodiscard]] double closeness(double x, double tolerance);

struct CollinearityTerms {
  double angle{0}, offset{0}, overlap{0};  // each in [0, 1]
  [[nodiscard]] double value() const { return angle * offset * overlap; }
};

// Degree of collinearity of `image` with the model edge made of `model_pieces` (collinear, the
// first piece's line is the model line); 0 for an empty list or a degenerate image edge.
[[nodiscard]] CollinearityTerms collinearity_terms(const Segment& image,
                                                   std::span<const Segment> model_pieces,
                                                   const Tolerance& tolerance);
[[nodiscard]] double collinearity(const Segment& image, std::span<const Segment> model_pieces,
                                  const Tolerance& tolerance);

[[nodiscard]] double edge_collinearity(const Segment& a, const Segment& b,
                                       const Tolerance& tolerance);
[[nodiscard]] double edge_noncollinearity(const Segment& a, const Segment& b,
                                          const Tolerance& tolerance);

// G(A): where model edge `model_a` appears if image edge `image_b` is model edge `model_b`.
[[nodiscard]] Segment predicted_partner(const Segment& image_b, const Segment& model_a,
                                        const Segment& model_b);
// compatibility(e1, e3) for labels A (of e1) and B (of e3), and its incompatibility.
[[nodiscard]] double compatibility(const Segment& image_a, const Segment& image_b,
                                   const Segment& model_a, const Segment& model_b,
                                   const Tolerance& relational);
[[nodiscard]] double incompatibility(const Segment& image_a, const Segment& image_b,
                                     const Segment& model_a, const Segment& model_b,
                                     const Tolerance& relational);

}  // namespace spar::sensing::pseiki
