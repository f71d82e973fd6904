#include "spar/sensing/pseiki/collinearity.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace spar::sensing::pseiki {
namespace {

// Factor of the tolerances beyond which two edges count as not collinear (header).
constexpr double kLoose = 2.0;

// The angle uncertainty (radians, three standard deviations) of an edge of `length` pixels whose
// end points have `noise_px` of noise.
double direction_noise(double length, double noise_px) {
  return std::atan(3 * std::numbers::sqrt2 * noise_px / std::max(length, 1e-9));
}

double angle_tolerance(const Tolerance& tolerance, double length) {
  return std::max(kMinimumAngle, tolerance.angle + direction_noise(length, tolerance.noise_px));
}

// The fraction of `image`'s projection on the line (origin, unit direction) inside the union of
// `pieces`' projections, each widened by `margin` at both ends.
double overlap_fraction(const Segment& image, std::span<const Segment> pieces,
                        const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                        double margin) {
  const double a0 = (image.p0 - origin).dot(direction), a1 = (image.p1 - origin).dot(direction);
  const double lo = std::min(a0, a1), hi = std::max(a0, a1);
  std::vector<std::pair<double, double>> spans;
  for (const Segment& piece : pieces) {
    const double s0 = (piece.p0 - origin).dot(direction), s1 = (piece.p1 - origin).dot(direction);
    spans.emplace_back(std::min(s0, s1) - margin, std::max(s0, s1) + margin);
  }
  std::sort(spans.begin(), spans.end());
  if (hi - lo < 1e-9)  // an edge across the line: inside or not
    return std::any_of(spans.begin(), spans.end(),
                       [&](const auto& s) { return s.first <= lo && lo <= s.second; })
               ? 1.0
               : 0.0;
  double covered = 0, reach = lo;
  for (const auto& [from, to] : spans) {
    const double start = std::max(from, reach), end = std::min(to, hi);
    if (end > start) covered += end - start;
    reach = std::max(reach, to);
  }
  return std::clamp(covered / (hi - lo), 0.0, 1.0);
}

// The three terms with every tolerance multiplied by `factor`.
CollinearityTerms terms(const Segment& image, std::span<const Segment> pieces,
                        const Tolerance& tolerance, double factor) {
  if (pieces.empty() || image.length() < 1e-9) return {};
  const Segment& line = pieces.front();
  const Eigen::Vector2d direction = line.direction();
  CollinearityTerms out;
  out.angle =
      closeness(line_angle(image, line), factor * angle_tolerance(tolerance, image.length()));
  out.offset = closeness(line.line_distance(image.midpoint()),
                         factor * std::max(tolerance.offset, kMinimumOffsetPx));
  out.overlap = overlap_fraction(image, pieces, line.p0, direction, factor * tolerance.margin);
  return out;
}

// Angle and offset closeness of two image edges (header): the shorter's midpoint against the
// longer's line, whose extrapolation error grows with the distance between them.
double pair_closeness(const Segment& a, const Segment& b, const Tolerance& tolerance,
                      double factor) {
  const Segment& longer = a.length() >= b.length() ? a : b;
  const Segment& shorter = a.length() >= b.length() ? b : a;
  if (shorter.length() < 1e-9) return 0;
  const double reach = (shorter.midpoint() - longer.midpoint()).norm();
  const double offset_tolerance =
      std::max(tolerance.offset, kMinimumOffsetPx) +
      std::tan(direction_noise(longer.length(), tolerance.noise_px)) * reach;
  return closeness(line_angle(a, b), factor * angle_tolerance(tolerance, shorter.length())) *
         closeness(longer.line_distance(shorter.midpoint()), factor * offset_tolerance);
}

// The relational tolerance widened by what e3 leaves unknown of G (header): its angle error turns
// G about e3's midpoint, and a piece of B may sit anywhere along B.
Tolerance widened(const Tolerance& relational, const Segment& image_b, const Segment& model_a,
                  const Segment& model_b, const Segment& predicted) {
  const double turn = direction_noise(image_b.length(), relational.noise_px);
  const double slide = std::max(0.0, model_b.length() - image_b.length()) / 2;
  const double phi = line_angle(model_a, model_b);
  Tolerance out = relational;
  out.angle += turn;
  out.offset +=
      std::tan(turn) * (predicted.midpoint() - image_b.midpoint()).norm() + slide * std::sin(phi);
  out.margin += slide * std::cos(phi);
  return out;
}

}  // namespace

Eigen::Vector2d Segment::direction() const {
  const double n = length();
  return n > 0 ? Eigen::Vector2d((p1 - p0) / n) : Eigen::Vector2d::Zero();
}

double Segment::line_distance(const Eigen::Vector2d& point) const {
  const Eigen::Vector2d d = direction();
  const Eigen::Vector2d r = point - p0;
  return std::abs(d.x() * r.y() - d.y() * r.x());
}

double line_angle(const Segment& a, const Segment& b) {
  const Eigen::Vector2d u = a.direction(), v = b.direction();
  return std::atan2(std::abs(u.x() * v.y() - u.y() * v.x()), std::abs(u.dot(v)));
}

Tolerance Tolerance::noise_only(double noise_px) {
  return {.angle = kMinimumAngle,
          .offset = std::max(kMinimumOffsetPx, 3 * noise_px),
          .margin = 0,
          .noise_px = noise_px};
}

double closeness(double x, double tolerance) {
  if (!(tolerance > 0)) return x == 0 ? 1.0 : 0.0;
  const double r = x / tolerance;
  return std::max(0.0, 1 - r * r);
}

CollinearityTerms collinearity_terms(const Segment& image, std::span<const Segment> model_pieces,
                                     const Tolerance& tolerance) {
  return terms(image, model_pieces, tolerance, 1.0);
}

double collinearity(const Segment& image, std::span<const Segment> model_pieces,
                    const Tolerance& tolerance) {
  return collinearity_terms(image, model_pieces, tolerance).value();
}

double edge_collinearity(const Segment& a, const Segment& b, const Tolerance& tolerance) {
  return pair_closeness(a, b, tolerance, 1.0);
}

double edge_noncollinearity(const Segment& a, const Segment& b, const Tolerance& tolerance) {
  return 1 - pair_closeness(a, b, tolerance, kLoose);
}

Segment predicted_partner(const Segment& image_b, const Segment& model_a, const Segment& model_b) {
  const Eigen::Vector2d from = model_b.direction(), to = image_b.direction();
  // The rotation from B's line to e3's (lines have no direction: within (-pi/2, pi/2]).
  double rho = std::atan2(from.x() * to.y() - from.y() * to.x(), from.dot(to));
  if (rho > std::numbers::pi / 2) rho -= std::numbers::pi;
  if (rho <= -std::numbers::pi / 2) rho += std::numbers::pi;
  const Eigen::Rotation2Dd rotation(rho);
  const Eigen::Vector2d anchor = model_b.midpoint(), target = image_b.midpoint();
  const auto moved = [&](const Eigen::Vector2d& x) -> Eigen::Vector2d {
    return rotation * (x - anchor) + target;
  };
  return {moved(model_a.p0), moved(model_a.p1)};
}

double compatibility(const Segment& image_a, const Segment& image_b, const Segment& model_a,
                     const Segment& model_b, const Tolerance& relational) {
  const Segment predicted = predicted_partner(image_b, model_a, model_b);
  return terms(image_a, std::span(&predicted, 1),
               widened(relational, image_b, model_a, model_b, predicted), 1.0)
      .value();
}

double incompatibility(const Segment& image_a, const Segment& image_b, const Segment& model_a,
                       const Segment& model_b, const Tolerance& relational) {
  const Segment predicted = predicted_partner(image_b, model_a, model_b);
  return 1 - terms(image_a, std::span(&predicted, 1),
                   widened(relational, image_b, model_a, model_b, predicted), kLoose)
                 .value();
}

}  // namespace spar::sensing::pseiki
