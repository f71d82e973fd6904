#include "spar/sensing/render.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <span>
#include <utility>
#include <vector>

#include "spar/sensing/error.hpp"
#include "spar/sensing/internal/item_buffer.hpp"

namespace spar::sensing {
namespace {

constexpr int kTile = 16;  // pixels per side of a tile of the edge-occlusion grid
// An orthographic view direction within this cosine of a face's plane sees the face edge-on.
constexpr double kEdgeOn = 1e-9;

// The points p with normal · p + offset >= 0 (camera frame).
struct HalfSpace {
  Eigen::Vector3d normal;
  double offset{0};
  [[nodiscard]] double at(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
};

// Cyrus-Beck: shrinks [t0, t1] to the parameters of p + t d inside every half-space; false when
// nothing is left.
bool clip(const Eigen::Vector3d& p, const Eigen::Vector3d& d, std::span<const HalfSpace> spaces,
          double& t0, double& t1) {
  for (const HalfSpace& space : spaces) {
    const double start = space.at(p), rate = space.normal.dot(d);
    if (rate == 0) {
      if (start < 0) return false;
      continue;
    }
    const double t = -start / rate;
    if (rate > 0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 >= t1) return false;
  }
  return true;
}

// The view volume of a camera in its own frame: the image rectangle and the near plane.
std::array<HalfSpace, 5> view_volume(const Camera& camera) {
  const Intrinsics& k = camera.intrinsics();
  const double w = k.width, h = k.height;
  if (camera.projection() == Projection::kPinhole)
    return {{{{0, 0, 1}, -kNearPlane},
             {{k.fx, 0, k.cx}, 0},
             {{-k.fx, 0, w - k.cx}, 0},
             {{0, k.fy, k.cy}, 0},
             {{0, -k.fy, h - k.cy}, 0}}};
  return {{{{0, 0, 1}, 0},
           {{k.fx, 0, 0}, k.cx},
           {{-k.fx, 0, 0}, w - k.cx},
           {{0, k.fy, 0}, k.cy},
           {{0, -k.fy, 0}, h - k.cy}}};
}

// Sutherland-Hodgman against z >= near: the part of a camera-frame triangle in front of the
// camera (0, 3 or 4 corners).
std::vector<Eigen::Vector3d> clip_near(const std::array<Eigen::Vector3d, 3>& triangle,
                                       double near) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& p = triangle[i];
    const Eigen::Vector3d& q = triangle[(i + 1) % 3];
    const bool p_in = p.z() >= near, q_in = q.z() >= near;
    if (p_in) out.push_back(p);
    if (p_in != q_in) out.push_back(p + (q - p) * ((near - p.z()) / (q.z() - p.z())));
  }
  return out;
}

// Depth key of a camera-frame point (internal/item_buffer.hpp): smaller is nearer.
double depth_key(const Camera& camera, const Eigen::Vector3d& p) {
  return camera.projection() == Projection::kPinhole ? -1.0 / p.z() : p.z();
}

// The camera with `factor` samples per pixel side.
Camera supersampled(const Camera& camera, int factor) {
  Intrinsics k = camera.intrinsics();
  k.fx *= factor;
  k.fy *= factor;
  k.cx *= factor;
  k.cy *= factor;
  k.width *= factor;
  k.height *= factor;
  return Camera(camera.projection(), k, camera.pose());
}

// A front-facing triangle of the scene in camera coordinates.
struct Occluder {
  std::array<Eigen::Vector3d, 3> corners;
  Eigen::Vector3d normal;           // outward, unnormalised
  std::array<HalfSpace, 4> shadow;  // the shadow volume (render.hpp), built on first use
  bool shadow_built{false};
};

void build_shadow(Occluder& occluder, const Camera& camera, double tolerance) {
  const auto& [a, b, c] = occluder.corners;
  const bool pinhole = camera.projection() == Projection::kPinhole;
  const Eigen::Vector3d view = Eigen::Vector3d::UnitZ();
  const std::array<std::pair<Eigen::Vector3d, Eigen::Vector3d>, 3> sides = {
      {{a, b}, {b, c}, {c, a}}};
  const std::array<Eigen::Vector3d, 3> opposite = {c, a, b};
  for (int i = 0; i < 3; ++i) {
    const auto& [p, q] = sides[i];
    // Plane through the eye (pinhole: the origin) or along the view, and the side p-q.
    HalfSpace side;
    side.normal = pinhole ? p.cross(q) : (q - p).cross(view);
    side.offset = pinhole ? 0.0 : -side.normal.dot(p);
    if (side.at(opposite[i]) < 0) {
      side.normal = -side.normal;
      side.offset = -side.offset;
    }
    occluder.shadow[i] = side;
  }
  // Behind the triangle's plane (seen from the eye) by more than the tolerance.
  const Eigen::Vector3d unit = occluder.normal.normalized();
  occluder.shadow[3] = {-unit, unit.dot(a) - tolerance};
  occluder.shadow_built = true;
}

struct FaceSums {
  int samples{0};
  double area{0};
  Eigen::Vector3d weighted{Eigen::Vector3d::Zero()};  // sum of area * point (camera frame)
};

// A front-facing triangle of the scene, globally numbered by its place in CameraView's list.
struct TriangleRef {
  int object, triangle, face;
};

// The occluders (every front-facing triangle) binned by the image tiles their screen boxes
// touch, for the edge pass: an edge is tested only against the occluders of the tiles its own
// screen box touches, each once (the stamp).
class OcclusionGrid {
 public:
  OcclusionGrid(const Camera& camera, std::vector<Occluder> occluders)
      : camera_(&camera),
        columns_((camera.intrinsics().width + kTile - 1) / kTile),
        rows_((camera.intrinsics().height + kTile - 1) / kTile),
        tiles_(static_cast<std::size_t>(columns_ * rows_)),
        occluders_(std::move(occluders)),
        stamp_(occluders_.size(), -1) {
    const Intrinsics& k = camera.intrinsics();
    for (std::size_t i = 0; i < occluders_.size(); ++i) {
      const Occluder& occluder = occluders_[i];
      // Its screen box (the whole image when part of it is behind a pinhole's near plane).
      double x0 = 0, x1 = k.width, y0 = 0, y1 = k.height;
      const bool behind =
          std::any_of(occluder.corners.begin(), occluder.corners.end(),
                      [&](const Eigen::Vector3d& p) { return p.z() < camera.near_depth(); });
      if (!behind) {
        x0 = y0 = std::numeric_limits<double>::infinity();
        x1 = y1 = -x0;
        for (const Eigen::Vector3d& p : occluder.corners) {
          const Eigen::Vector2d uv = camera.project_camera(p);
          x0 = std::min(x0, uv.x());
          x1 = std::max(x1, uv.x());
          y0 = std::min(y0, uv.y());
          y1 = std::max(y1, uv.y());
        }
      }
      const int c0 = std::max(0, static_cast<int>(std::floor(x0 / kTile)));
      const int c1 = std::min(columns_ - 1, static_cast<int>(std::floor(x1 / kTile)));
      const int r0 = std::max(0, static_cast<int>(std::floor(y0 / kTile)));
      const int r1 = std::min(rows_ - 1, static_cast<int>(std::floor(y1 / kTile)));
      for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c)
          tiles_[static_cast<std::size_t>(r * columns_ + c)].push_back(static_cast<int>(i));
    }
  }

  // The parameter intervals of start + t direction, t in [t_in, t_out], that some occluder's
  // shadow volume hides, sorted; a, b are the segment's end points in pixels.
  std::vector<std::pair<double, double>> hidden(const Eigen::Vector3d& start,
                                                const Eigen::Vector3d& direction, double t_in,
                                                double t_out, const Eigen::Vector2d& a,
                                                const Eigen::Vector2d& b, double tolerance) {
    const auto column = [&](double x) {
      return std::clamp(static_cast<int>(std::floor(x / kTile)), 0, columns_ - 1);
    };
    const auto row = [&](double y) {
      return std::clamp(static_cast<int>(std::floor(y / kTile)), 0, rows_ - 1);
    };
    const int c0 = column(std::min(a.x(), b.x())), c1 = column(std::max(a.x(), b.x()));
    const int r0 = row(std::min(a.y(), b.y())), r1 = row(std::max(a.y(), b.y()));
    ++stamp_value_;
    std::vector<std::pair<double, double>> out;
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c)
        for (const int i : tiles_[static_cast<std::size_t>(r * columns_ + c)]) {
          if (stamp_[static_cast<std::size_t>(i)] == stamp_value_) continue;
          stamp_[static_cast<std::size_t>(i)] = stamp_value_;
          Occluder& occluder = occluders_[static_cast<std::size_t>(i)];
          if (!occluder.shadow_built) build_shadow(occluder, *camera_, tolerance);
          double h0 = t_in, h1 = t_out;
          if (clip(start, direction, occluder.shadow, h0, h1)) out.emplace_back(h0, h1);
        }
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  const Camera* camera_;
  int columns_, rows_;
  std::vector<std::vector<int>> tiles_;  // per tile, row-major: the occluders touching it
  std::vector<Occluder> occluders_;
  std::vector<int> stamp_;  // per occluder: the last edge query that tested it
  int stamp_value_{0};
};

// The scene as the camera sees it: camera-frame vertices, which faces turn toward the camera,
// and the front-facing triangles; the face pass (item buffer) and the edge pass (hidden-line
// clipping) both start from it.
class CameraView {
 public:
  CameraView(const Scene& scene, const Camera& camera)
      : scene_(&scene),
        camera_(&camera),
        tolerance_(1e-9 * std::max(scene.scale(), 1e-12)),
        pinhole_(camera.projection() == Projection::kPinhole) {
    const Eigen::Matrix3d to_camera_rotation = camera.pose().linear().transpose();
    prepared_.resize(scene.objects().size());
    for (std::size_t o = 0; o < scene.objects().size(); ++o) {
      const SceneObject& object = scene.objects()[o];
      Prepared& p = prepared_[o];
      for (const Eigen::Vector3d& v : object.vertices) p.vertices.push_back(camera.to_camera(v));
      for (std::size_t f = 0; f < object.face_normals.size(); ++f) {
        const Eigen::Vector3d& n = object.face_normals[f];
        // Plane n · x = offset; the eye sees its front when it is on the positive side, by more
        // than the tolerance (a face seen edge-on, to rounding, is turned away).
        const double side = pinhole_ ? n.dot(camera.pose().translation()) - object.face_offsets[f]
                                     : -n.dot(camera.pose().linear().col(2));
        p.front.push_back(side > (pinhole_ ? tolerance_ : kEdgeOn));
        p.normals.push_back(to_camera_rotation * n);
      }
      const auto& faces_of = object.features->triangle_face;
      for (std::size_t t = 0; t < faces_of.size(); ++t)
        if (p.front[static_cast<std::size_t>(faces_of[t] - 1)])
          triangles_.push_back({static_cast<int>(o), static_cast<int>(t), faces_of[t]});
    }
  }

  // The visible faces, by (object, face), from an item buffer with `supersampling` samples per
  // pixel side.
  [[nodiscard]] std::vector<FaceView> visible_faces(int supersampling) const {
    const Camera fine = supersampled(*camera_, supersampling);
    Eigen::AlignedBox2d covered;
    const std::vector<Fan> drawn = fans(fine, covered);
    std::vector<FaceView> out;
    for (const auto& [key, sum] : face_sums(fine, drawn, covered)) {
      const auto& [object_index, face_id] = key;
      const SceneObject& object = scene_->objects()[static_cast<std::size_t>(object_index)];
      const geometry::Face& face = object.model->face(face_id);
      FaceView view{.object = object_index, .face = face_id, .samples = sum.samples};
      view.visible_area = sum.area;
      view.visible_fraction = sum.area / face.area;
      view.centroid = camera_->pose() * (sum.weighted / sum.area);
      const Eigen::Vector3d world_centroid = object.pose * face.centroid;
      view.angle =
          std::acos(std::clamp(object.face_normals[static_cast<std::size_t>(face_id - 1)].dot(
                                   camera_->toward_viewer(world_centroid)),
                               -1.0, 1.0));
      out.push_back(view);
    }
    return out;
  }

  // The visible pieces of the model edges of faces turned toward the camera, by (object, edge,
  // position along the edge).
  [[nodiscard]] std::vector<EdgeView> visible_edges() const {
    std::vector<Occluder> occluders(triangles_.size());
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
      Occluder& occluder = occluders[i];
      occluder.corners = corners_of(triangles_[i]);
      occluder.normal = (occluder.corners[1] - occluder.corners[0])
                            .cross(occluder.corners[2] - occluder.corners[0]);
    }
    OcclusionGrid grid(*camera_, std::move(occluders));
    const std::array<HalfSpace, 5> volume = view_volume(*camera_);
    std::vector<EdgeView> out;
    for (std::size_t o = 0; o < scene_->objects().size(); ++o)
      for (const ModelEdge& edge : scene_->objects()[o].features->edges)
        add_visible_pieces(static_cast<int>(o), edge, volume, grid, out);
    return out;
  }

 private:
  struct Prepared {
    std::vector<Eigen::Vector3d> vertices;
    std::vector<char> front;               // [face id - 1]
    std::vector<Eigen::Vector3d> normals;  // [face id - 1], camera frame
  };
  // One image piece of a triangle (a fan of its part in front of the near plane).
  struct Fan {
    std::array<Eigen::Vector2d, 3> corners;
    std::array<double, 3> depth;
    int item;  // the triangle's number
  };

  [[nodiscard]] std::array<Eigen::Vector3d, 3> corners_of(const TriangleRef& ref) const {
    const auto& indices = scene_->objects()[ref.object].model->mesh().triangles[ref.triangle];
    const auto& vertices = prepared_[ref.object].vertices;
    return {vertices[indices[0]], vertices[indices[1]], vertices[indices[2]]};
  }

  // The triangles' image pieces on the `fine` camera, and the window they cover.
  [[nodiscard]] std::vector<Fan> fans(const Camera& fine, Eigen::AlignedBox2d& covered) const {
    std::vector<Fan> out;
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
      const std::vector<Eigen::Vector3d> polygon =
          clip_near(corners_of(triangles_[i]), fine.near_depth());
      for (std::size_t j = 2; j < polygon.size(); ++j) {
        const std::array<Eigen::Vector3d, 3> fan = {polygon[0], polygon[j - 1], polygon[j]};
        const Fan drawn{
            {fine.project_camera(fan[0]), fine.project_camera(fan[1]), fine.project_camera(fan[2])},
            {depth_key(fine, fan[0]), depth_key(fine, fan[1]), depth_key(fine, fan[2])},
            static_cast<int>(i)};
        // A corner that does not project to a finite point draws nothing (ItemBuffer::draw).
        if (!std::all_of(drawn.corners.begin(), drawn.corners.end(),
                         [](const Eigen::Vector2d& c) { return c.allFinite(); }))
          continue;
        for (const Eigen::Vector2d& corner : drawn.corners) covered.extend(corner);
        out.push_back(drawn);
      }
    }
    return out;
  }

  // Per (object, face): the samples of an item buffer of the fans over the window they cover (no
  // sample outside it is drawn, so the window gives what the whole image would:
  // internal/item_buffer.hpp, for a fraction of the memory), with their footprints on the face's
  // plane.
  [[nodiscard]] std::map<std::pair<int, int>, FaceSums> face_sums(
      const Camera& fine, const std::vector<Fan>& drawn, const Eigen::AlignedBox2d& covered) const {
    const Intrinsics& k = fine.intrinsics();
    internal::PixelWindow window{0, 0, 0, 0};
    if (!covered.isEmpty()) {
      const auto clamped = [](double value, int high) {
        return static_cast<int>(std::clamp(value, 0.0, static_cast<double>(high)));
      };
      window.x0 = clamped(std::floor(covered.min().x()), k.width);
      window.y0 = clamped(std::floor(covered.min().y()), k.height);
      window.width = clamped(std::ceil(covered.max().x()), k.width) - window.x0;
      window.height = clamped(std::ceil(covered.max().y()), k.height) - window.y0;
    }
    internal::ItemBuffer buffer(window);
    if (window.width > 0 && window.height > 0)
      for (const Fan& fan : drawn) buffer.draw(fan.corners, fan.depth, fan.item);
    std::map<std::pair<int, int>, FaceSums> sums;
    for (int y = window.y0; y < window.y0 + window.height; ++y)
      for (int x = window.x0; x < window.x0 + window.width; ++x) {
        const int item = buffer.item(x, y);
        if (item < 0) continue;
        const TriangleRef& ref = triangles_[static_cast<std::size_t>(item)];
        const Eigen::Vector3d& normal =
            prepared_[ref.object].normals[static_cast<std::size_t>(ref.face - 1)];
        // The sample's ray (z component 1 for a pinhole) and surface point; its footprint on the
        // face's plane: z^2 / (fx fy |n · r|) for a pinhole, 1 / (fx fy |n_z|) orthographic.
        const double u = x + 0.5, v = y + 0.5;
        Eigen::Vector3d point;
        double footprint;
        if (pinhole_) {
          const double z = -1.0 / buffer.depth(x, y);
          const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
          point = ray * z;
          footprint = z * z / (k.fx * k.fy * std::abs(normal.dot(ray)));
        } else {
          point = {(u - k.cx) / k.fx, (v - k.cy) / k.fy, buffer.depth(x, y)};
          footprint = 1.0 / (k.fx * k.fy * std::abs(normal.z()));
        }
        FaceSums& sum = sums[{ref.object, ref.face}];
        ++sum.samples;
        sum.area += footprint;
        sum.weighted += footprint * point;
      }
    return sums;
  }

  // Appends the pieces of `edge` of object `o` that lie in the view volume and outside every
  // occluder's shadow (none when both its faces turn away).
  void add_visible_pieces(int o, const ModelEdge& edge, std::span<const HalfSpace> volume,
                          OcclusionGrid& grid, std::vector<EdgeView>& out) const {
    const SceneObject& object = scene_->objects()[static_cast<std::size_t>(o)];
    const Prepared& p = prepared_[static_cast<std::size_t>(o)];
    const bool front_a = p.front[static_cast<std::size_t>(edge.face_a - 1)];
    const bool front_b = p.front[static_cast<std::size_t>(edge.face_b - 1)];
    if (!front_a && !front_b) return;
    const Camera& camera = *camera_;
    const Eigen::Vector3d start = camera.to_camera(object.pose * edge.p0);
    const Eigen::Vector3d direction = camera.to_camera(object.pose * edge.p1) - start;
    double t_in = 0, t_out = 1;
    if (!clip(start, direction, volume, t_in, t_out)) return;
    const std::vector<std::pair<double, double>> hidden =
        grid.hidden(start, direction, t_in, t_out, camera.project_camera(start + t_in * direction),
                    camera.project_camera(start + t_out * direction), tolerance_);
    // The complement of the hidden intervals inside [t_in, t_out].
    const double length = direction.norm();
    const auto emit = [&](double from, double to) {
      if ((to - from) * length <= tolerance_) return;
      EdgeView view{.object = o, .edge = edge.id};
      view.p0 = camera.pose() * (start + from * direction);
      view.p1 = camera.pose() * (start + to * direction);
      view.u0 = camera.project_camera(start + from * direction);
      view.u1 = camera.project_camera(start + to * direction);
      view.silhouette = front_a != front_b;
      if (view.silhouette) {
        view.contrast = 1.0;
      } else {
        const Eigen::Vector3d toward = camera.toward_viewer(0.5 * (view.p0 + view.p1));
        view.contrast =
            std::abs(object.face_normals[static_cast<std::size_t>(edge.face_a - 1)].dot(toward) -
                     object.face_normals[static_cast<std::size_t>(edge.face_b - 1)].dot(toward));
      }
      out.push_back(view);
    };
    double cursor = t_in;
    for (const auto& [h0, h1] : hidden) {
      if (h0 > cursor) emit(cursor, h0);
      cursor = std::max(cursor, h1);
    }
    if (cursor < t_out) emit(cursor, t_out);
  }

  const Scene* scene_;
  const Camera* camera_;
  double tolerance_;  // lengths below it are rounding: 1e-9 of the scene's size
  bool pinhole_;
  std::vector<Prepared> prepared_;      // per object
  std::vector<TriangleRef> triangles_;  // the front-facing ones, by object then triangle
};

}  // namespace

Rendering render(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  if (options.supersampling < 1 || options.supersampling > 8)
    throw SensingError("render: supersampling must be 1 to 8, got " +
                       std::to_string(options.supersampling));
  const CameraView view(scene, camera);
  Rendering out;
  if (options.faces) out.faces = view.visible_faces(options.supersampling);
  if (options.edges) out.edges = view.visible_edges();
  return out;
}

}  // namespace spar::sensing
