#include "spar/sensing/aspects.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <boost/math/quadrature/gauss.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>

#include "spar/common/number.hpp"
#include "spar/sensing/camera.hpp"
#include "spar/sensing/error.hpp"
#include "spar/sensing/internal/icosphere.hpp"
#include "spar/sensing/internal/item_buffer.hpp"
#include "spar/sensing/render.hpp"
#include "spar/sensing/sensors.hpp"

namespace spar::sensing {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kSmallestCell = 1e-10;  // sr: exact cells below this are degenerate, dropped

void check_options(const AspectOptions& options) {
  if (!(options.max_angle > 0 && options.max_angle <= std::numbers::pi / 2 + 1e-12))
    throw SensingError("aspects: max_angle must be in (0, 90] degrees, got " +
                       format_number(options.max_angle * 180 / std::numbers::pi));
  if (options.view_sphere_level < 0 || options.view_sphere_level > 6)
    throw SensingError("aspects: view_sphere_level must be 0 to 6, got " +
                       std::to_string(options.view_sphere_level));
  if (options.resolution < 16 || options.resolution > 1024)
    throw SensingError("aspects: resolution must be 16 to 1024 samples, got " +
                       std::to_string(options.resolution));
}

// Every vertex on or behind every face's plane.
bool is_convex(const geometry::ObjectModel& model) {
  const double tolerance = model.tolerance();
  for (const geometry::Face& face : model.faces())
    for (const Eigen::Vector3d& vertex : model.mesh().vertices)
      if (face.normal.dot(vertex) > face.offset + tolerance) return false;
  return true;
}

bool use_exact(const geometry::ObjectModel& model, const AspectOptions& options) {
  return !options.force_view_sphere && static_cast<int>(model.faces().size()) <= kExactFaceLimit &&
         is_convex(model);
}

// Orders aspects by face list and labels them.
void label(std::vector<Aspect>& aspects) {
  std::sort(aspects.begin(), aspects.end(),
            [](const Aspect& a, const Aspect& b) { return a.faces < b.faces; });
  for (std::size_t i = 0; i < aspects.size(); ++i) {
    char text[24];  // formatted directly: GCC 12 warns (-Wrestrict) on "A" + std::to_string(i)
    std::snprintf(text, sizeof text, "A%zu", i + 1);
    aspects[i].label = text;
  }
}

std::vector<int> faces_of_mask(std::uint64_t mask) {
  std::vector<int> faces;
  for (int i = 0; i < 64; ++i)
    if (mask & (std::uint64_t{1} << i)) faces.push_back(i + 1);
  return faces;
}

// ---- the exact arrangement (convex objects) ----

// The faces a direction d sees within the angle: bit i set when d · normal_i > c.
struct VisibleFaces {
  const std::vector<Eigen::Vector3d>* normals;
  double c;
  [[nodiscard]] std::uint64_t operator()(const Eigen::Vector3d& d) const {
    std::uint64_t mask = 0;
    for (std::size_t i = 0; i < normals->size(); ++i)
      if (d.dot((*normals)[i]) > c) mask |= std::uint64_t{1} << i;
    return mask;
  }
};

// The sweep's frame: a generic axis (no symmetry of a modelled part lines up with it) and two
// axes around it.
struct SweepFrame {
  Eigen::Vector3d pole, e1, e2;
};

// The heights along the pole where the arrangement of the visibility circles (cos = c, sin = s
// of the angle) changes: each circle's top and bottom and each two circles' crossings; sorted,
// within [-1, 1], near-equal ones merged.
std::vector<double> band_heights(const std::vector<Eigen::Vector3d>& normals, double c, double s,
                                 const Eigen::Vector3d& pole) {
  std::vector<double> heights = {-1.0, 1.0};
  for (const Eigen::Vector3d& normal : normals) {
    const double height = normal.dot(pole);
    const double radius = std::sqrt(std::max(0.0, 1 - height * height));
    heights.push_back(c * height - s * radius);
    heights.push_back(c * height + s * radius);
  }
  for (std::size_t i = 0; i < normals.size(); ++i)
    for (std::size_t j = i + 1; j < normals.size(); ++j) {
      const double g = normals[i].dot(normals[j]);
      if (std::abs(g) > 1 - 1e-12) continue;  // parallel circles: no crossing point
      const double along = c / (1 + g);
      const double across_squared = 1 - 2 * c * c / (1 + g);
      if (across_squared < 0) continue;
      const Eigen::Vector3d middle = along * (normals[i] + normals[j]);
      const Eigen::Vector3d axis = normals[i].cross(normals[j]).normalized();
      for (const double sign : {-1.0, 1.0})
        heights.push_back((middle + sign * std::sqrt(across_squared) * axis).dot(pole));
    }
  for (double& height : heights) height = std::clamp(height, -1.0, 1.0);
  std::sort(heights.begin(), heights.end());
  heights.erase(std::unique(heights.begin(), heights.end(),
                            [](double a, double b) { return b - a <= 1e-14; }),
                heights.end());
  return heights;
}

// One cell of the arrangement (the directions seeing one face set), integrated.
struct SweptCell {
  double area{0};
  Eigen::Vector3d moment{Eigen::Vector3d::Zero()};  // integral of d over the cell
  double longest{-1};                               // longest latitude arc seen
  Eigen::Vector3d longest_middle{Eigen::Vector3d::Zero()};
};

// The cells by face set: each band between two heights integrated over z with a 20-point Gauss
// rule (in t, z = low + (high - low)(1 - cos t)/2, which takes the sqrt ends), each latitude cut
// exactly where a circle crosses it.
std::map<std::uint64_t, SweptCell> swept_cells(const std::vector<Eigen::Vector3d>& normals,
                                               const VisibleFaces& visible, const SweepFrame& frame,
                                               const std::vector<double>& heights) {
  std::map<std::uint64_t, SweptCell> cells;
  using Gauss = boost::math::quadrature::gauss<double, 20>;
  std::vector<std::pair<double, double>> nodes;  // on [-1, 1]
  for (std::size_t k = 0; k < Gauss::abscissa().size(); ++k) {
    nodes.emplace_back(Gauss::abscissa()[k], Gauss::weights()[k]);
    if (Gauss::abscissa()[k] != 0) nodes.emplace_back(-Gauss::abscissa()[k], Gauss::weights()[k]);
  }
  const auto& [pole, e1, e2] = frame;
  std::vector<double> breaks;
  for (std::size_t band = 0; band + 1 < heights.size(); ++band) {
    const double low = heights[band], high = heights[band + 1];
    for (const auto& [x, w] : nodes) {
      // z = low + (high - low)(1 - cos t)/2 with t = pi (x + 1)/2 in [0, pi].
      const double t = std::numbers::pi * (x + 1) / 2;
      const double z = low + (high - low) * (1 - std::cos(t)) / 2;
      const double weight = w * (std::numbers::pi / 2) * (high - low) * std::sin(t) / 2;
      const double r = std::sqrt(std::max(0.0, 1 - z * z));
      breaks.assign(1, 0.0);
      for (const Eigen::Vector3d& normal : normals) {
        const double a = normal.dot(e1), b = normal.dot(e2), along = normal.dot(pole);
        const double reach = r * std::hypot(a, b);
        if (reach <= 0) continue;
        const double threshold = (visible.c - z * along) / reach;
        if (threshold <= -1 || threshold >= 1) continue;  // the whole latitude or none of it
        const double middle = std::atan2(b, a), half = std::acos(threshold);
        for (const double edge : {middle - half, middle + half})
          breaks.push_back(edge - kTwoPi * std::floor(edge / kTwoPi));
      }
      std::sort(breaks.begin(), breaks.end());
      breaks.push_back(kTwoPi);
      for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
        const double from = breaks[i], to = breaks[i + 1], span = to - from;
        if (span <= 0) continue;
        const double mid = (from + to) / 2;
        const Eigen::Vector3d direction =
            r * std::cos(mid) * e1 + r * std::sin(mid) * e2 + z * pole;
        SweptCell& cell = cells[visible(direction)];
        cell.area += weight * span;
        cell.moment += weight * (r * (std::sin(to) - std::sin(from)) * e1 +
                                 r * (std::cos(from) - std::cos(to)) * e2 + z * span * pole);
        if (r * span > cell.longest) {
          cell.longest = r * span;
          cell.longest_middle = direction;
        }
      }
    }
  }
  return cells;
}

AspectSet exact_aspects(const geometry::ObjectModel& model, const AspectOptions& options) {
  const double c = std::cos(options.max_angle), s = std::sin(options.max_angle);
  std::vector<Eigen::Vector3d> normals;
  for (const geometry::Face& face : model.faces()) normals.push_back(face.normal);
  const VisibleFaces visible{&normals, c};
  SweepFrame frame;
  frame.pole = Eigen::Vector3d(0.2718281828, 0.3141592653, 0.9093).normalized();
  frame.e1 = frame.pole.unitOrthogonal();
  frame.e2 = frame.pole.cross(frame.e1);
  const std::map<std::uint64_t, SweptCell> cells =
      swept_cells(normals, visible, frame, band_heights(normals, c, s, frame.pole));

  AspectSet out;
  out.method = AspectMethod::kExactArrangement;
  out.max_angle = options.max_angle;
  out.cos_max_angle = c;
  out.normals = normals;
  for (const auto& [mask, cell] : cells) {
    if (cell.area < kSmallestCell) continue;
    Aspect aspect;
    aspect.faces = faces_of_mask(mask);
    aspect.solid_angle = cell.area;
    const Eigen::Vector3d mean = cell.moment.normalized();
    aspect.direction = cell.moment.norm() > 1e-12 && visible(mean) == mask
                           ? mean
                           : cell.longest_middle.normalized();
    out.aspects.push_back(aspect);
  }
  label(out.aspects);
  return out;
}

// ---- the view sphere (any object) ----

// Van Oosterom and Strackee's solid angle of a spherical triangle.
double spherical_area(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Vector3d& c) {
  const double numerator = std::abs(a.dot(b.cross(c)));
  const double denominator = 1 + a.dot(b) + b.dot(c) + c.dot(a);
  return 2 * std::atan2(numerator, denominator);
}

// Renders one object orthographically from many directions into one reused item buffer and
// reports the faces seen.
class ViewRenderer {
 public:
  ViewRenderer(const geometry::ObjectModel& model, const AspectOptions& options)
      : model_(model),
        resolution_(options.resolution),
        cos_max_(std::cos(options.max_angle)),
        buffer_(options.resolution, options.resolution) {
    Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d high = -low;
    for (const auto& triangle : model.mesh().triangles)
      for (const int v : triangle) {
        low = low.cwiseMin(model.mesh().vertices[static_cast<std::size_t>(v)]);
        high = high.cwiseMax(model.mesh().vertices[static_cast<std::size_t>(v)]);
      }
    centre_ = (low + high) / 2;
    radius_ = (high - low).norm() / 2;
    triangle_face_.assign(model.mesh().triangles.size(), 0);
    for (const geometry::Face& face : model.faces())
      for (const int t : face.triangles) triangle_face_[static_cast<std::size_t>(t)] = face.id;
    seen_.assign(model.faces().size() + 1, 0);
  }

  std::vector<int> faces_seen(const Eigen::Vector3d& direction) {
    const Camera camera = Camera::orthographic_view(direction, centre_, radius_, resolution_);
    buffer_.clear();
    const auto& vertices = model_.mesh().vertices;
    projected_.resize(vertices.size());
    depth_.resize(vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v) {
      const Eigen::Vector3d p = camera.to_camera(vertices[v]);
      projected_[v] = camera.project_camera(p);
      depth_[v] = p.z();
    }
    const auto& faces = model_.faces();
    for (std::size_t t = 0; t < model_.mesh().triangles.size(); ++t) {
      const int face = triangle_face_[t];
      // Turned toward the viewer as render.hpp defines it.
      if (!(faces[static_cast<std::size_t>(face - 1)].normal.dot(direction) > 1e-9)) continue;
      const auto& [a, b, c] = model_.mesh().triangles[t];
      buffer_.draw({projected_[a], projected_[b], projected_[c]}, {depth_[a], depth_[b], depth_[c]},
                   face);
    }
    std::fill(seen_.begin(), seen_.end(), 0);
    for (const int item : buffer_.items())
      if (item > 0) seen_[static_cast<std::size_t>(item)] = 1;
    std::vector<int> out;
    for (const geometry::Face& face : faces)
      if (seen_[static_cast<std::size_t>(face.id)] && face.normal.dot(direction) > cos_max_)
        out.push_back(face.id);
    return out;
  }

 private:
  const geometry::ObjectModel& model_;
  int resolution_;
  double cos_max_;
  internal::ItemBuffer buffer_;
  Eigen::Vector3d centre_;
  double radius_{0};
  std::vector<int> triangle_face_;
  std::vector<char> seen_;
  std::vector<Eigen::Vector2d> projected_;
  std::vector<double> depth_;
};

AspectSet view_sphere_aspects(const geometry::ObjectModel& model, const AspectOptions& options) {
  ViewRenderer renderer(model, options);
  std::map<std::vector<int>, std::vector<int>> members;  // face set -> cell indices
  AspectSet out;
  out.method = AspectMethod::kViewSphere;
  out.max_angle = options.max_angle;
  out.cos_max_angle = std::cos(options.max_angle);
  for (const auto& [a, b, c] : internal::icosphere(options.view_sphere_level)) {
    ViewCell cell;
    cell.direction = (a + b + c).normalized();
    cell.solid_angle = spherical_area(a, b, c);
    members[renderer.faces_seen(cell.direction)].push_back(static_cast<int>(out.cells.size()));
    out.cells.push_back(cell);
  }
  for (const auto& [faces, cells] : members) {
    Aspect aspect;
    aspect.faces = faces;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const int i : cells) {
      aspect.solid_angle += out.cells[static_cast<std::size_t>(i)].solid_angle;
      mean += out.cells[static_cast<std::size_t>(i)].solid_angle *
              out.cells[static_cast<std::size_t>(i)].direction;
    }
    // The member cell nearest the mean direction.
    int best = cells.front();
    for (const int i : cells)
      if (out.cells[static_cast<std::size_t>(i)].direction.dot(mean) >
          out.cells[static_cast<std::size_t>(best)].direction.dot(mean))
        best = i;
    aspect.direction = out.cells[static_cast<std::size_t>(best)].direction;
    out.aspects.push_back(aspect);
  }
  label(out.aspects);
  // Each cell's aspect index, now that they are ordered.
  std::map<std::vector<int>, int> index;
  for (std::size_t i = 0; i < out.aspects.size(); ++i)
    index[out.aspects[i].faces] = static_cast<int>(i);
  for (const auto& [faces, cells] : members)
    for (const int i : cells) out.cells[static_cast<std::size_t>(i)].aspect = index[faces];
  return out;
}

}  // namespace

const char* to_string(AspectMethod method) {
  return method == AspectMethod::kExactArrangement ? "exact arrangement" : "view sphere";
}

int AspectSet::aspect_at(const Eigen::Vector3d& direction) const {
  const Eigen::Vector3d d = direction.normalized();
  if (method == AspectMethod::kViewSphere) {
    int best = -1;
    double best_dot = -2;
    for (const ViewCell& cell : cells)
      if (const double dot = cell.direction.dot(d); dot > best_dot) {
        best_dot = dot;
        best = cell.aspect;
      }
    return best;
  }
  std::vector<int> faces;
  for (std::size_t i = 0; i < normals.size(); ++i)
    if (d.dot(normals[i]) > cos_max_angle) faces.push_back(static_cast<int>(i) + 1);
  const auto found = std::lower_bound(
      aspects.begin(), aspects.end(), faces,
      [](const Aspect& aspect, const std::vector<int>& key) { return aspect.faces < key; });
  return found != aspects.end() && found->faces == faces ? static_cast<int>(found - aspects.begin())
                                                         : -1;
}

std::vector<Eigen::Vector3d> view_directions(int level) {
  if (level < 0 || level > 6)
    throw SensingError("view directions: level must be 0 to 6, got " + std::to_string(level));
  std::vector<Eigen::Vector3d> out;
  for (const auto& [a, b, c] : internal::icosphere(level)) out.push_back((a + b + c).normalized());
  return out;
}

AspectSet compute_aspects(const geometry::ObjectModel& model, const AspectOptions& options) {
  check_options(options);
  return use_exact(model, options) ? exact_aspects(model, options)
                                   : view_sphere_aspects(model, options);
}

std::vector<int> faces_seen(const geometry::ObjectModel& model, const Eigen::Vector3d& direction,
                            const AspectOptions& options) {
  check_options(options);
  const Eigen::Vector3d d = direction.normalized();
  if (use_exact(model, options)) {
    std::vector<int> faces;
    for (const geometry::Face& face : model.faces())
      if (d.dot(face.normal) > std::cos(options.max_angle)) faces.push_back(face.id);
    return faces;
  }
  ViewRenderer renderer(model, options);
  return renderer.faces_seen(d);
}

AspectFeatures aspect_features(const geometry::ObjectModel& model, const ObjectFeatures& features,
                               const Aspect& aspect, const AspectOptions& options) {
  check_options(options);
  Scene scene;
  scene.add(model.name(), model, features, Eigen::Isometry3d::Identity());
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const Eigen::Vector3d& vertex : model.mesh().vertices) {
    low = low.cwiseMin(vertex);
    high = high.cwiseMax(vertex);
  }
  const Camera camera = Camera::orthographic_view(aspect.direction, (low + high) / 2,
                                                  (high - low).norm() / 2, options.resolution);
  const Rendering seen = render(scene, camera);
  AspectFeatures out;
  double total_area = 0;
  for (const int id : aspect.faces) {
    FaceProminence face{.face = id};
    for (const FaceView& view : seen.faces)
      if (view.face == id) face.visible_area = view.visible_area * std::cos(view.angle);
    total_area += face.visible_area;
    out.faces.push_back(face);
  }
  for (FaceProminence& face : out.faces)
    face.prominence = face_prominence(face.visible_area, total_area);
  const double metres_per_pixel = 1.0 / camera.intrinsics().fx;
  std::map<int, EdgeProminence> edges;
  for (const EdgeView& view : seen.edges) {
    EdgeProminence& edge = edges[view.edge];
    edge.edge = view.edge;
    const double length = (view.u1 - view.u0).norm() * metres_per_pixel;
    // Contrast: the length-weighted mean over the edge's visible pieces.
    edge.contrast = (edge.contrast * edge.visible_length + view.contrast * length) /
                    std::max(edge.visible_length + length, 1e-300);
    edge.visible_length += length;
  }
  for (auto& [id, edge] : edges) {
    edge.prominence = edge_prominence(edge.visible_length, edge.contrast, (high - low).norm());
    out.edges.push_back(edge);
  }
  return out;
}

}  // namespace spar::sensing
