#include "spar/sensing/pseiki/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>

#include "spar/common/number.hpp"
#include "spar/sensing/error.hpp"
#include "spar/sensing/pseiki/splitter.hpp"
#include "spar/sensing/render.hpp"

namespace spar::sensing::pseiki {
namespace {

constexpr double kJoinGap = 1.5;       // pixels between the ends of joined pieces
constexpr double kJoinAngle = 0.0105;  // radians (0.6 degrees)
// A shadow or clutter edge whose ends are this close to a true edge's line, along it, would be
// that edge.
constexpr double kCoincidentOffset = 3.0;  // pixels
constexpr int kRedraws = 20;

void check_probability(double value, const char* name) {
  if (!(value >= 0 && value <= 1))
    throw SensingError(std::string("simulated image: ") + name +
                       " must be a probability in [0, 1], got " + format_number(value));
}

// The part of `s` inside [0, width] x [0, height] (Liang-Barsky), if any is left.
std::optional<Segment> clipped(const Segment& s, double width, double height) {
  double t0 = 0, t1 = 1;
  const Eigen::Vector2d d = s.p1 - s.p0;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {s.p0.x(), width - s.p0.x(), s.p0.y(), height - s.p0.y()};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0) {
      if (q[k] < 0) return std::nullopt;
      continue;
    }
    const double t = q[k] / p[k];
    if (p[k] < 0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
  }
  if (t1 - t0 <= 0) return std::nullopt;
  return Segment{s.p0 + t0 * d, s.p0 + t1 * d};
}

// If `a` and `b` continue each other along one line, the segment over both, ordered a then b.
std::optional<Segment> continued(const Segment& a, const Segment& b) {
  if (line_angle(a, b) > kJoinAngle) return std::nullopt;
  for (const auto& [a_far, a_near] : {std::pair{a.p0, a.p1}, std::pair{a.p1, a.p0}})
    for (const auto& [b_near, b_far] : {std::pair{b.p0, b.p1}, std::pair{b.p1, b.p0}})
      if ((a_near - b_near).norm() <= kJoinGap &&
          (a_far - b_far).norm() >= a.length() + b.length() - kJoinGap)
        return Segment{a_far, b_far};
  return std::nullopt;
}

void check_perturbation(const Scene& scene, const ExpectationUncertainty& uncertainty,
                        const ImagePerturbation& perturbation) {
  check_probability(perturbation.drop, "drop");
  check_probability(perturbation.split, "split");
  check_probability(perturbation.join, "join");
  check_probability(perturbation.shadow, "shadow");
  if (!(perturbation.noise_px >= 0 && std::isfinite(perturbation.noise_px)))
    throw SensingError("simulated image: noise must be >= 0 pixels, got " +
                       format_number(perturbation.noise_px));
  if (!(perturbation.pose_scale >= 0 && std::isfinite(perturbation.pose_scale)))
    throw SensingError("simulated image: the pose scale must be >= 0, got " +
                       format_number(perturbation.pose_scale));
  if (perturbation.clutter < 0 || perturbation.clutter > kMaxClutter)
    throw SensingError("simulated image: clutter must be 0 to " + std::to_string(kMaxClutter) +
                       " edges, got " + std::to_string(perturbation.clutter));
  if (!uncertainty.objects.empty() && uncertainty.objects.size() != scene.objects().size())
    throw SensingError("simulated image: one uncertainty per object");
}

struct Piece {
  Segment segment;
  std::string truth;  // "<object>/e<edge>", "a+b" for joined edges, "" for a shadow or clutter
};

// The pieces of the rendered edges an edge detector resolves (the model panel's Resolution: no
// piece under kMinimumPiece, no edge another one hides, distinct_edges), in the renderer's order
// (an edge's pieces together).
std::vector<Piece> resolved_pieces(const Rendering& seen, const Scene& scene) {
  std::vector<Piece> resolved;
  std::vector<std::vector<Segment>> edge_pieces;
  for (const EdgeView& view : seen.edges) {
    if ((view.u1 - view.u0).norm() < kMinimumPiece) continue;
    std::string id = scene.objects()[static_cast<std::size_t>(view.object)].name + "/e" +
                     std::to_string(view.edge);
    if (resolved.empty() || resolved.back().truth != id) edge_pieces.emplace_back();
    edge_pieces.back().push_back({view.u0, view.u1});
    resolved.push_back({{view.u0, view.u1}, std::move(id)});
  }
  const std::vector<bool> distinct = distinct_edges(edge_pieces);
  std::vector<Piece> out;
  for (std::size_t i = 0, edge = 0; i < resolved.size(); ++i) {
    if (i > 0 && resolved[i].truth != resolved[i - 1].truth) ++edge;
    if (distinct[edge]) out.push_back(resolved[i]);
  }
  return out;
}

// Whether `candidate` would lie on one of the rendered `true_edges` (both ends within
// kCoincidentOffset of its line, overlapping it along the line): an edge detector would report
// the two as one edge.
bool on_a_true_edge(const Segment& candidate, const std::vector<Segment>& true_edges) {
  return std::any_of(true_edges.begin(), true_edges.end(), [&](const Segment& edge) {
    const Eigen::Vector2d d = edge.direction();
    const double s0 = (candidate.p0 - edge.p0).dot(d), s1 = (candidate.p1 - edge.p0).dot(d);
    return edge.line_distance(candidate.p0) < kCoincidentOffset &&
           edge.line_distance(candidate.p1) < kCoincidentOffset && std::max(s0, s1) > 0 &&
           std::min(s0, s1) < edge.length();
  });
}

// One image's random choices. Every step draws from one generator, and simulate() runs the steps
// in one order, so one seed gives one image (the tests and benchmarks name seeds).
class Simulation {
 public:
  Simulation(const ImagePerturbation& perturbation, std::uint64_t seed)
      : perturbation_(perturbation), random_(seed) {}

  // The camera's pose offset, then each object's (none without uncertainties), within the
  // scaled half-widths; the scene rendered at those poses.
  Rendering true_scene(const Scene& scene, const Camera& camera,
                       const ExpectationUncertainty& uncertainty, SimulatedImage& out) {
    out.camera_offset = draw_offset(uncertainty.camera);
    Scene truth;
    for (std::size_t o = 0; o < scene.objects().size(); ++o) {
      const SceneObject& object = scene.objects()[o];
      out.object_offsets.push_back(
          uncertainty.objects.empty() ? PoseOffset{} : draw_offset(uncertainty.objects[o]));
      truth.add(object.name, *object.model, *object.features,
                offset_pose(object.pose, out.object_offsets.back()));
    }
    const Camera true_camera(camera.projection(), camera.intrinsics(),
                             offset_pose(camera.pose(), out.camera_offset));
    return render(truth, true_camera, {.faces = false, .edges = true});
  }

  // Exactly round(drop n) pieces dropped, then round(split n') of the rest cut in two at 30-70%
  // of their length with a 1-4 px gap.
  std::vector<Piece> dropped_and_split(const std::vector<Piece>& seen) {
    const std::vector<char> dropped = chosen(seen.size(), perturbation_.drop);
    std::vector<Piece> kept;
    for (std::size_t i = 0; i < seen.size(); ++i)
      if (!dropped[i]) kept.push_back(seen[i]);
    const std::vector<char> cut = chosen(kept.size(), perturbation_.split);
    std::vector<Piece> pieces;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const Segment& segment = kept[i].segment;
      if (!cut[i]) {
        pieces.push_back(kept[i]);
        continue;
      }
      const double at = uniform(0.3, 0.7) * segment.length();
      const double gap = uniform(1.0, 4.0);
      const Eigen::Vector2d d = segment.direction();
      pieces.push_back({{segment.p0, segment.p0 + (at - gap / 2) * d}, kept[i].truth});
      pieces.push_back({{segment.p0 + (at + gap / 2) * d, segment.p1}, kept[i].truth});
    }
    return pieces;
  }

  // Pieces of different edges that continue each other joined with probability `join` (the
  // longer edge may continue into another).
  void join(std::vector<Piece>& pieces) {
    if (perturbation_.join <= 0) return;
    for (std::size_t i = 0; i < pieces.size(); ++i)
      for (std::size_t j = i + 1; j < pieces.size();) {
        const auto joined = pieces[i].truth != pieces[j].truth
                                ? continued(pieces[i].segment, pieces[j].segment)
                                : std::nullopt;
        if (joined && chance(perturbation_.join)) {
          pieces[i] = {*joined, pieces[i].truth + "+" + pieces[j].truth};
          pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(j));
          j = i + 1;
        } else {
          ++j;
        }
      }
  }

  // A shadow beside round(shadow n) pieces: 4-10 px to either side, along 50-100% of the piece.
  // Shadows and clutter are drawn again (up to kRedraws times) where they would lie on one of
  // the `true_edges` (on_a_true_edge).
  void add_shadows(std::vector<Piece>& pieces, const std::vector<Segment>& true_edges) {
    const std::vector<char> shaded = chosen(pieces.size(), perturbation_.shadow);
    for (std::size_t i = 0; i < shaded.size(); ++i) {
      if (!shaded[i]) continue;
      const Segment s = pieces[i].segment;
      const Eigen::Vector2d d = s.direction(), n(-d.y(), d.x());
      for (int attempt = 0; attempt < kRedraws; ++attempt) {
        const double side = chance(0.5) ? 1.0 : -1.0;
        const Eigen::Vector2d shift = side * uniform(4.0, 10.0) * n;
        const Segment shadow{s.p0 + shift, s.p0 + uniform(0.5, 1.0) * s.length() * d + shift};
        if (on_a_true_edge(shadow, true_edges)) continue;
        pieces.push_back({shadow, ""});
        break;
      }
    }
  }

  // Gaussian noise of noise_px on every end point.
  void add_noise(std::vector<Piece>& pieces) {
    for (Piece& piece : pieces) piece.segment = {noisy(piece.segment.p0), noisy(piece.segment.p1)};
  }

  // `clutter` segments of 10-60 px anywhere in the image, at any angle.
  void add_clutter(std::vector<Piece>& pieces, const Intrinsics& k,
                   const std::vector<Segment>& true_edges) {
    for (int c = 0; c < perturbation_.clutter; ++c)
      for (int attempt = 0; attempt < kRedraws; ++attempt) {
        const double y = uniform(0, k.height);  // before x, as in noisy()
        const Eigen::Vector2d middle(uniform(0, k.width), y);
        const double angle = uniform(0, std::numbers::pi), half = uniform(5.0, 30.0);
        const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
        const Segment clutter{middle - half * d, middle + half * d};
        if (on_a_true_edge(clutter, true_edges)) continue;
        pieces.push_back({clutter, ""});
        break;
      }
  }

  void shuffle(std::vector<Piece>& pieces) { std::shuffle(pieces.begin(), pieces.end(), random_); }

 private:
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit_(random_); }
  bool chance(double probability) { return unit_(random_) < probability; }
  PoseOffset draw_offset(const kinematics::PoseUncertainty& h) {
    const double s = perturbation_.pose_scale;
    return PoseOffset{uniform(-s * h.dx, s * h.dx), uniform(-s * h.dy, s * h.dy),
                      uniform(-s * h.dz, s * h.dz), uniform(-s * h.dtheta, s * h.dtheta)};
  }
  // `fraction` of `count` items, chosen at random: exactly round(fraction count) of them.
  std::vector<char> chosen(std::size_t count, double fraction) {
    std::vector<char> out(count, 0);
    std::fill_n(out.begin(),
                static_cast<std::size_t>(std::lround(fraction * static_cast<double>(count))), 1);
    std::shuffle(out.begin(), out.end(), random_);
    return out;
  }
  Eigen::Vector2d noisy(const Eigen::Vector2d& p) {
    // Two statements, not two arguments: arguments are evaluated in an unspecified order (GCC
    // and clang differ), and one seed must give one image whatever the compiler. y is drawn
    // first, the order GCC has always used, so the images the tests were written on stay.
    const double dy = noise_(random_);
    const double dx = noise_(random_);
    return p + perturbation_.noise_px * Eigen::Vector2d(dx, dy);
  }

  const ImagePerturbation& perturbation_;
  std::mt19937_64 random_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  std::normal_distribution<double> noise_{0.0, 1.0};
};

}  // namespace

SimulatedImage simulate(const Scene& scene, const Camera& camera,
                        const ExpectationUncertainty& uncertainty,
                        const ImagePerturbation& perturbation, std::uint64_t seed) {
  check_perturbation(scene, uncertainty, perturbation);
  Simulation simulation(perturbation, seed);
  SimulatedImage out;
  const Rendering seen = simulation.true_scene(scene, camera, uncertainty, out);
  std::vector<Piece> pieces = simulation.dropped_and_split(resolved_pieces(seen, scene));
  simulation.join(pieces);
  std::vector<Segment> true_edges;
  for (const EdgeView& view : seen.edges) true_edges.push_back({view.u0, view.u1});
  simulation.add_shadows(pieces, true_edges);
  simulation.add_noise(pieces);
  simulation.add_clutter(pieces, camera.intrinsics(), true_edges);
  simulation.shuffle(pieces);
  const Intrinsics& k = camera.intrinsics();
  for (const Piece& piece : pieces) {
    const auto inside = clipped(piece.segment, k.width, k.height);
    if (!inside || inside->length() < 1.0) continue;
    out.edges.push_back(
        {.edge = {.id = std::string("e").append(std::to_string(out.edges.size() + 1)),
                  .segment = *inside},
         .truth = piece.truth});
  }
  return out;
}

}  // namespace spar::sensing::pseiki
