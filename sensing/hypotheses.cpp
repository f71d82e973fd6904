#include "spar/sensing/hypotheses.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include "spar/sensing/error.hpp"

namespace spar::sensing {
namespace {

constexpr double kUnexplained = 0.05;  // a feature no hypothesis explains better is no evidence
constexpr double kAreaSigma = 0.25;    // of ln(area ratio)

double gauss(double value, double sigma) {
  const double z = value / sigma;
  return std::exp(-0.5 * z * z);
}

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double face_similarity(const SensedFace& s, const SensedFace& f, const MatchTolerances& t) {
  const double area =
      (s.area > 0 && f.area > 0) ? gauss(std::log(s.area / f.area), kAreaSigma) : 0.0;
  return gauss(angle_between(s.normal, f.normal), t.normal) *
         gauss((s.position - f.position).norm(), t.position) * area;
}

double endpoint_distance(const SensedEdge& s, const SensedEdge& f) {
  const double straight = ((s.u0 - f.u0).norm() + (s.u1 - f.u1).norm()) / 2;
  const double crossed = ((s.u0 - f.u1).norm() + (s.u1 - f.u0).norm()) / 2;
  return std::min(straight, crossed);
}

double edge_similarity(const SensedEdge& s, const SensedEdge& f, const MatchTolerances& t) {
  return gauss(endpoint_distance(s, f), t.pixels);
}

// The angle between two image lines, in [0, pi/2].
double line_angle(const SensedEdge& a, const SensedEdge& b) {
  const Eigen::Vector2d da = a.u1 - a.u0, db = b.u1 - b.u0;
  const double angle = std::atan2(std::abs(da.x() * db.y() - da.y() * db.x()), da.dot(db));
  return std::min(angle, std::numbers::pi - angle);
}

// The features of one kind as the matcher needs them: similarity of a sensed to an expected one,
// the relation of two features (an angle and a distance), and a prominence.
struct FaceKind {
  static const std::vector<SensedFace>& of(const Observation& o) { return o.faces; }
  static const std::vector<SensedFace>& of(const Expectation& e) { return e.faces; }
  static double similarity(const SensedFace& s, const SensedFace& f, const MatchTolerances& t) {
    return face_similarity(s, f, t);
  }
  static double angle(const SensedFace& a, const SensedFace& b) {
    return angle_between(a.normal, b.normal);
  }
  static double distance(const SensedFace& a, const SensedFace& b) {
    return (a.position - b.position).norm();
  }
  static double distance_sigma(const MatchTolerances& t) { return t.position; }
  static bool inside(const SensedFace& s, const Expectation& e, const MatchTolerances& t) {
    return (s.position - e.centre).norm() <= e.radius + 3 * t.position;
  }
};

struct EdgeKind {
  static const std::vector<SensedEdge>& of(const Observation& o) { return o.edges; }
  static const std::vector<SensedEdge>& of(const Expectation& e) { return e.edges; }
  static double similarity(const SensedEdge& s, const SensedEdge& f, const MatchTolerances& t) {
    return edge_similarity(s, f, t);
  }
  static double angle(const SensedEdge& a, const SensedEdge& b) { return line_angle(a, b); }
  static double distance(const SensedEdge& a, const SensedEdge& b) {
    return ((a.u0 + a.u1) / 2 - (b.u0 + b.u1) / 2).norm();
  }
  static double distance_sigma(const MatchTolerances& t) { return t.pixels; }
  static bool inside(const SensedEdge& s, const Expectation& e, const MatchTolerances& t) {
    const Eigen::Vector2d middle = (s.u0 + s.u1) / 2;
    const Eigen::Vector2d margin = Eigen::Vector2d::Constant(3 * t.pixels);
    return !e.image_box.isEmpty() &&
           Eigen::AlignedBox2d(e.image_box.min() - margin, e.image_box.max() + margin)
               .contains(middle);
  }
};

template <class Kind>
void weigh(const Observation& observed, const std::vector<Expectation>& expected,
           const MatchTolerances& t, double detection_probability, Weighing& out) {
  const int n = static_cast<int>(expected.size());
  // The object's sensed features: inside the region of some hypothesis.
  std::vector<const std::remove_cvref_t<decltype(Kind::of(observed)[0])>*> sensed;
  for (const auto& feature : Kind::of(observed))
    if (std::any_of(expected.begin(), expected.end(),
                    [&](const Expectation& e) { return Kind::inside(feature, e, t); }))
      sensed.push_back(&feature);
  out.features = static_cast<int>(sensed.size());
  // quality[s][h]: the best similarity of sensed feature s under hypothesis h, at match[s][h].
  std::vector<std::vector<double>> quality(sensed.size(), std::vector<double>(n, 0.0));
  std::vector<std::vector<int>> match(sensed.size(), std::vector<int>(n, -1));
  for (std::size_t s = 0; s < sensed.size(); ++s)
    for (int h = 0; h < n; ++h) {
      const auto& model = Kind::of(expected[static_cast<std::size_t>(h)]);
      for (std::size_t f = 0; f < model.size(); ++f)
        if (const double q = Kind::similarity(*sensed[s], model[f], t); q > quality[s][h]) {
          quality[s][h] = q;
          match[s][h] = static_cast<int>(f);
        }
    }
  // Feature matches.
  for (std::size_t s = 0; s < sensed.size(); ++s) {
    if (*std::max_element(quality[s].begin(), quality[s].end()) < kUnexplained) continue;
    out.sources.push_back(consonant_support(quality[s]));
    out.kinds.push_back("feature");
  }
  // Relational consistency.
  if (sensed.size() >= 2) {
    const double sigma_angle = std::numbers::sqrt2 * t.normal;
    const double sigma_distance = std::numbers::sqrt2 * Kind::distance_sigma(t);
    for (std::size_t s = 0; s < sensed.size(); ++s) {
      std::vector<double> consistency(static_cast<std::size_t>(n), 0.0);
      for (int h = 0; h < n; ++h) {
        const auto& model = Kind::of(expected[static_cast<std::size_t>(h)]);
        double total = 0;
        for (std::size_t other = 0; other < sensed.size(); ++other) {
          if (other == s) continue;
          const int a = match[s][h], b = match[other][h];
          if (a < 0 || b < 0 || a == b) continue;  // unmatched or matched twice: inconsistent
          const auto& fa = model[static_cast<std::size_t>(a)];
          const auto& fb = model[static_cast<std::size_t>(b)];
          total +=
              gauss(Kind::angle(*sensed[s], *sensed[other]) - Kind::angle(fa, fb), sigma_angle) *
              gauss(Kind::distance(*sensed[s], *sensed[other]) - Kind::distance(fa, fb),
                    sigma_distance);
        }
        consistency[static_cast<std::size_t>(h)] = total / static_cast<double>(sensed.size() - 1);
      }
      if (*std::max_element(consistency.begin(), consistency.end()) < kUnexplained) continue;
      out.sources.push_back(consonant_support(consistency));
      out.kinds.push_back("relation");
    }
  }
  // Expected against observed, weighted by prominence: each expected feature not found is
  // evidence against its hypothesis.
  if (n < 2) return;
  for (int h = 0; h < n; ++h) {
    const auto& model = Kind::of(expected[static_cast<std::size_t>(h)]);
    double strongest = 0;
    for (const auto& feature : model) strongest = std::max(strongest, feature.prominence);
    if (!(strongest > 0)) continue;
    const FocalSet others = FocalSet::of(n, {h}).complement();
    for (const auto& feature : model) {
      double found = 0;
      for (const auto* s : sensed) found = std::max(found, Kind::similarity(*s, feature, t));
      const double against = detection_probability * (1 - found) * feature.prominence / strongest;
      if (against < kUnexplained) continue;
      out.sources.push_back(MassFunction::simple_support(others, kMaxSupport * against));
      out.kinds.push_back("expected");
    }
  }
}

}  // namespace

Expectation expect(const Scene& scene, int target, const SensorModel& sensor,
                   const Eigen::Isometry3d& sensor_pose) {
  if (target < 0 || target >= static_cast<int>(scene.objects().size()))
    throw SensingError("expect: no object " + std::to_string(target) + " in the scene");
  const Observation all = predict(scene, sensor, sensor_pose);
  Expectation out;
  for (const SensedFace& face : all.faces)
    if (face.truth_object == target) out.faces.push_back(face);
  for (const SensedEdge& edge : all.edges)
    if (edge.truth_object == target) out.edges.push_back(edge);
  const SceneObject& object = scene.objects()[static_cast<std::size_t>(target)];
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& vertex : object.vertices) box.extend(vertex);
  out.centre = box.center();
  out.radius = box.diagonal().norm() / 2;
  const Camera camera = place(sensor, sensor_pose);
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d point =
        out.centre +
        out.radius * Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
    const std::optional<Eigen::Vector2d> uv = camera.project(point);
    if (!uv) {  // part of the object's sphere is behind the camera: the whole image
      out.image_box = Eigen::AlignedBox2d(
          Eigen::Vector2d::Zero(),
          Eigen::Vector2d(camera.intrinsics().width, camera.intrinsics().height));
      break;
    }
    out.image_box.extend(*uv);
  }
  return out;
}

MatchTolerances match_tolerances(const SensorModel& sensor, double dx, double dy, double dz,
                                 double dtheta, double radius, double distance) {
  const double displacement =
      std::sqrt(dx * dx + dy * dy + dz * dz + radius * dtheta * radius * dtheta);
  MatchTolerances out;
  out.normal = std::max(std::hypot(sensor.normal_noise, dtheta), 2 * std::numbers::pi / 180);
  out.position = std::max(std::hypot(sensor.position_noise, displacement), 0.002);
  const double pixels_per_metre = sensor.projection == Projection::kPinhole
                                      ? sensor.intrinsics.fx / std::max(distance, 1e-3)
                                      : sensor.intrinsics.fx;
  out.pixels = std::max(std::hypot(sensor.noise_px, pixels_per_metre * displacement), 1.0);
  return out;
}

MassFunction consonant_support(const std::vector<double>& level) {
  const int n = static_cast<int>(level.size());
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return level[a] > level[b]; });
  std::vector<FocalElement> elements;
  FocalSet best(n);
  for (int k = 0; k + 1 < n; ++k) {
    best.insert(order[static_cast<std::size_t>(k)]);
    const double step = level[order[k]] - level[order[k + 1]];
    if (step > 0) elements.push_back({best, kMaxSupport * step});
  }
  elements.push_back(
      {FocalSet::whole(n), 1 - kMaxSupport * (level[order.front()] - level[order.back()])});
  return MassFunction::from_elements(n, std::move(elements));
}

Weighing weigh_evidence(const Observation& observed, const std::vector<Expectation>& expected,
                        const MatchTolerances& tolerances, const SensorModel& sensor,
                        const MassFunction& prior) {
  if (static_cast<int>(expected.size()) != prior.frame_size())
    throw SensingError("weigh_evidence: " + std::to_string(expected.size()) +
                       " expectations for a frame of " + std::to_string(prior.frame_size()) +
                       " hypotheses");
  Weighing out{
      .sources = {prior}, .kinds = {"prior"}, .combined = prior, .conflict = 0, .features = 0};
  if (observed.kind == SensorKind::kRangeScanner) {
    weigh<FaceKind>(observed, expected, tolerances, sensor.detection_probability, out);
  } else {
    weigh<EdgeKind>(observed, expected, tolerances, sensor.detection_probability, out);
  }
  const Combination combination = combine(out.sources, prior.frame_size());
  out.combined = combination.mass;
  out.conflict = combination.conflict;
  return out;
}

}  // namespace spar::sensing
