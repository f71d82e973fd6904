#include "spar/sensing/pseiki/expected_scene.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "spar/sensing/error.hpp"
#include "spar/sensing/pseiki/splitter.hpp"
#include "spar/sensing/render.hpp"

namespace spar::sensing::pseiki {
namespace {

constexpr double kVertexMerge = 0.5;  // pixels: end points this close are one vertex
constexpr double kEndSlack = 1.0;     // pixels an edge detector may lose or add at an end

// Every corner of a half-width box: each uncertain component at -h and +h. None when exact.
std::vector<PoseOffset> corners(const kinematics::PoseUncertainty& h) {
  std::vector<PoseOffset> out = {{}};
  const auto split = [&](double half_width, double PoseOffset::*member) {
    if (!(half_width > 0)) return;
    std::vector<PoseOffset> next;
    for (PoseOffset offset : out)
      for (const double sign : {-1.0, 1.0}) {
        offset.*member = sign * half_width;
        next.push_back(offset);
      }
    out = std::move(next);
  };
  split(h.dx, &PoseOffset::dx);
  split(h.dy, &PoseOffset::dy);
  split(h.dz, &PoseOffset::dz);
  split(h.dtheta, &PoseOffset::dtheta);
  return out.size() == 1 ? std::vector<PoseOffset>{} : out;
}

// How much a tolerance grows at one corner: the change of a line's angle, the largest distance
// of the moved end points from the expected line, and their largest shift along it.
struct Misfit {
  double angle{0}, offset{0}, along{0};
  void widen(const Misfit& other) {
    angle = std::max(angle, other.angle);
    offset = std::max(offset, other.offset);
    along = std::max(along, other.along);
  }
};

Misfit misfit(const Segment& expected, const Segment& moved) {
  const Eigen::Vector2d direction = expected.direction();
  return {.angle = line_angle(expected, moved),
          .offset = std::max(expected.line_distance(moved.p0), expected.line_distance(moved.p1)),
          .along = std::max(std::abs((moved.p0 - expected.p0).dot(direction)),
                            std::abs((moved.p1 - expected.p1).dot(direction)))};
}

// The tolerance from what the object's and the camera's uncertainty do (their sum) and the noise.
Tolerance tolerance_of(const Misfit& object, const Misfit& camera, double noise_px) {
  return {.angle = object.angle + camera.angle,
          .offset = object.offset + camera.offset + 3 * noise_px + kMinimumOffsetPx,
          .margin = object.along + camera.along + 3 * noise_px + kEndSlack,
          .noise_px = noise_px};
}

// One pose hypothesis of the corner analysis: the camera and one object's pose, possibly moved.
struct CornerView {
  Camera camera;
  int moved_object{-1};                                            // -1: only the camera moved
  Eigen::Isometry3d object_motion{Eigen::Isometry3d::Identity()};  // world -> world
};

// Whether `piece` lies on `on`: both its ends within kResolvePixels of that line and along it.
bool lies_on(const Segment& piece, const Segment& on) {
  const Eigen::Vector2d direction = on.direction();
  if (direction.isZero()) return false;
  for (const Eigen::Vector2d& end : {piece.p0, piece.p1}) {
    const double along = (end - on.p0).dot(direction);
    if (on.line_distance(end) > kResolvePixels || along < -kEndSlack ||
        along > on.length() + kEndSlack)
      return false;
  }
  return true;
}

}  // namespace

std::vector<bool> distinct_edges(std::span<const std::vector<Segment>> edges) {
  std::vector<double> length(edges.size(), 0);
  for (std::size_t e = 0; e < edges.size(); ++e)
    for (const Segment& piece : edges[e]) length[e] += piece.length();
  std::vector<std::size_t> longest_first(edges.size());
  std::iota(longest_first.begin(), longest_first.end(), std::size_t{0});
  std::stable_sort(longest_first.begin(), longest_first.end(),
                   [&](std::size_t a, std::size_t b) { return length[a] > length[b]; });
  std::vector<bool> distinct(edges.size(), false);
  std::vector<const Segment*> kept_pieces;
  for (const std::size_t e : longest_first) {
    const bool on_a_kept_edge = std::ranges::all_of(edges[e], [&](const Segment& piece) {
      return std::ranges::any_of(kept_pieces,
                                 [&](const Segment* on) { return lies_on(piece, *on); });
    });
    distinct[e] = !edges[e].empty() && !on_a_kept_edge;
    if (distinct[e])
      for (const Segment& piece : edges[e]) kept_pieces.push_back(&piece);
  }
  return distinct;
}

Eigen::Isometry3d offset_pose(const Eigen::Isometry3d& pose, const PoseOffset& offset) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() =
      Eigen::AngleAxisd(offset.dtheta, Eigen::Vector3d::UnitZ()).toRotationMatrix() * pose.linear();
  out.translation() = pose.translation() + Eigen::Vector3d(offset.dx, offset.dy, offset.dz);
  return out;
}

namespace {

// World end points of a panel edge's span (its first piece's start, its last piece's end).
using SpanWorld = std::array<Eigen::Vector3d, 2>;

// The renderer's edge pieces an edge detector resolves (the header's Resolution: none under
// kMinimumPiece, none lying on a longer edge), grouped by (object, model edge) into panel edges;
// `spans[e]` the world end points of edge e's span.
std::vector<PanelEdge> panel_edges(const Rendering& seen, const std::vector<SceneObject>& objects,
                                   std::vector<SpanWorld>& spans) {
  std::vector<PanelEdge> edges;
  for (const EdgeView& view : seen.edges) {
    if ((view.u1 - view.u0).norm() < kMinimumPiece) continue;  // below the resolution
    if (edges.empty() || edges.back().object != view.object ||
        edges.back().model_edge != view.edge) {
      const SceneObject& object = objects[static_cast<std::size_t>(view.object)];
      const ModelEdge& model = object.features->edges[static_cast<std::size_t>(view.edge - 1)];
      PanelEdge edge;
      edge.id = object.name + "/e" + std::to_string(view.edge);
      edge.object = view.object;
      edge.model_edge = view.edge;
      edge.p0 = model.p0;
      edge.p1 = model.p1;
      edges.push_back(std::move(edge));
      spans.push_back({view.p0, view.p1});
    }
    PanelEdge& edge = edges.back();
    edge.pieces.push_back({view.u0, view.u1});
    edge.visible_length += (view.u1 - view.u0).norm();
    edge.silhouette = edge.silhouette || view.silhouette;
    spans.back()[1] = view.p1;
  }
  // Edges lying on longer ones are seen as those.
  std::vector<std::vector<Segment>> pieces;
  for (const PanelEdge& edge : edges) pieces.push_back(edge.pieces);
  const std::vector<bool> distinct = distinct_edges(pieces);
  std::size_t kept = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (!distinct[e]) continue;
    if (kept != e) {  // a vector moved onto itself is emptied
      edges[kept] = std::move(edges[e]);
      spans[kept] = spans[e];
    }
    ++kept;
  }
  edges.resize(kept);
  spans.resize(kept);
  for (PanelEdge& edge : edges) edge.span = {edge.pieces.front().p0, edge.pieces.back().p1};
  return edges;
}

// The visible faces with a visible edge, each listed in its edges' `faces`.
std::vector<PanelFace> panel_faces(const Rendering& seen, const std::vector<SceneObject>& objects,
                                   std::vector<PanelEdge>& edges, double samples_per_pixel) {
  std::vector<PanelFace> faces;
  for (const FaceView& view : seen.faces) {
    PanelFace face;
    face.object = view.object;
    face.model_face = view.face;
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const PanelEdge& edge = edges[e];
      if (edge.object != view.object) continue;
      const ModelEdge& model = objects[static_cast<std::size_t>(edge.object)]
                                   .features->edges[static_cast<std::size_t>(edge.model_edge - 1)];
      if (model.face_a == view.face || model.face_b == view.face)
        face.edges.push_back(static_cast<int>(e));
    }
    if (face.edges.empty()) continue;
    face.id =
        objects[static_cast<std::size_t>(view.object)].name + "/f" + std::to_string(view.face);
    face.area_px = view.samples / samples_per_pixel;
    for (const int e : face.edges)
      edges[static_cast<std::size_t>(e)].faces.push_back(static_cast<int>(faces.size()));
    faces.push_back(std::move(face));
  }
  return faces;
}

// The pieces' end points, merged when closer than kVertexMerge; sets each edge's piece ends and
// each face's region (the convex hull of its edges' vertices).
std::vector<PanelVertex> panel_vertices(std::vector<PanelEdge>& edges,
                                        std::vector<PanelFace>& faces) {
  std::vector<PanelVertex> vertices;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    PanelEdge& edge = edges[e];
    for (const Segment& piece : edge.pieces) {
      std::array<int, 2> ends{};
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector2d& p = k == 0 ? piece.p0 : piece.p1;
        auto found = std::find_if(vertices.begin(), vertices.end(), [&](const PanelVertex& v) {
          return (v.pixel - p).norm() < kVertexMerge;
        });
        if (found == vertices.end()) {
          vertices.push_back({.pixel = p, .edges = {}});
          found = vertices.end() - 1;
        }
        if (found->edges.empty() || found->edges.back() != static_cast<int>(e))
          found->edges.push_back(static_cast<int>(e));
        ends[static_cast<std::size_t>(k)] = static_cast<int>(found - vertices.begin());
      }
      edge.vertices.push_back(ends);
    }
  }
  for (PanelFace& face : faces) {
    std::vector<Eigen::Vector2d> corners_of_face;
    for (const int e : face.edges)
      for (const std::array<int, 2>& ends : edges[static_cast<std::size_t>(e)].vertices)
        for (const int v : ends)
          corners_of_face.push_back(vertices[static_cast<std::size_t>(v)].pixel);
    face.region = internal::convex_hull(corners_of_face);
  }
  return vertices;
}

// One panel object per scene object, with its faces, edges and visible length.
std::vector<PanelObject> panel_objects(const std::vector<SceneObject>& objects,
                                       const std::vector<PanelFace>& faces,
                                       const std::vector<PanelEdge>& edges) {
  std::vector<PanelObject> out;
  for (const SceneObject& object : objects)
    out.push_back(
        {.name = object.name, .faces = {}, .edges = {}, .visible_length = 0, .pose = object.pose});
  for (std::size_t f = 0; f < faces.size(); ++f)
    out[static_cast<std::size_t>(faces[f].object)].faces.push_back(static_cast<int>(f));
  for (std::size_t e = 0; e < edges.size(); ++e) {
    PanelObject& object = out[static_cast<std::size_t>(edges[e].object)];
    object.edges.push_back(static_cast<int>(e));
    object.visible_length += edges[e].visible_length;
  }
  return out;
}

// Per edge, the other edges of its faces (sorted, once each).
std::vector<std::vector<int>> face_neighbours(const std::vector<PanelFace>& faces,
                                              std::size_t edge_count) {
  std::vector<std::vector<int>> neighbours(edge_count);
  for (const PanelFace& face : faces)
    for (const int a : face.edges)
      for (const int b : face.edges)
        if (a != b) neighbours[static_cast<std::size_t>(a)].push_back(b);
  for (std::vector<int>& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return neighbours;
}

// The tolerances: every edge's span seen at every corner of the camera's box and of its object's
// box (CornerView), and how far each moves from where it is expected.
class CornerAnalysis {
 public:
  CornerAnalysis(const std::vector<SceneObject>& objects, const Camera& camera,
                 const ExpectationUncertainty& uncertainty, std::vector<SpanWorld> spans)
      : objects_(objects), believed_{.camera = camera}, spans_(std::move(spans)) {
    for (const PoseOffset& offset : corners(uncertainty.camera))
      views_.push_back({.camera = Camera(camera.projection(), camera.intrinsics(),
                                         offset_pose(camera.pose(), offset)),
                        .moved_object = -1,
                        .object_motion = Eigen::Isometry3d::Identity()});
    if (!uncertainty.objects.empty())
      for (std::size_t o = 0; o < objects.size(); ++o)
        for (const PoseOffset& offset : corners(uncertainty.objects[o])) {
          const Eigen::Isometry3d& pose = objects[o].pose;
          views_.push_back({.camera = camera,
                            .moved_object = static_cast<int>(o),
                            .object_motion = offset_pose(pose, offset) * pose.inverse()});
        }
  }

  // Each edge's tolerance and the longest its image can be (PanelEdge::longest_px).
  void set_edge_tolerances(std::vector<PanelEdge>& edges, double noise_px) const {
    for (std::size_t e = 0; e < edges.size(); ++e) {
      Misfit by_object, by_camera;
      double longest = std::max(whole_length(believed_, edges[e]), edges[e].span.length());
      for (const CornerView& view : views_) {
        if (!moves(view, edges[e])) continue;
        if (const auto moved = seen_at(view, e))
          (view.moved_object < 0 ? by_camera : by_object).widen(misfit(edges[e].span, *moved));
        longest = std::max(longest, whole_length(view, edges[e]));
      }
      edges[e].tolerance = tolerance_of(by_object, by_camera, noise_px);
      edges[e].longest_px = longest + 3 * std::sqrt(2.0) * noise_px;
    }
  }

  // The tolerance of edge a where its neighbour b predicts it (predicted_partner), per pair.
  std::map<std::pair<int, int>, Tolerance> relational_tolerances(
      const std::vector<PanelEdge>& edges, const std::vector<std::vector<int>>& neighbours,
      double noise_px) const {
    std::map<std::pair<int, int>, Tolerance> out;
    for (std::size_t a = 0; a < edges.size(); ++a)
      for (const int b : neighbours[a]) {
        Misfit by_object, by_camera;
        for (const CornerView& view : views_) {
          if (!moves(view, edges[a])) continue;
          const auto seen_a = seen_at(view, a);
          const auto seen_b = seen_at(view, static_cast<std::size_t>(b));
          if (!seen_a || !seen_b) continue;
          const Segment predicted =
              predicted_partner(*seen_b, edges[a].span, edges[static_cast<std::size_t>(b)].span);
          (view.moved_object < 0 ? by_camera : by_object).widen(misfit(predicted, *seen_a));
        }
        out[{static_cast<int>(a), b}] = tolerance_of(by_object, by_camera, noise_px);
      }
    return out;
  }

 private:
  // Which edges a view moves: all (camera) or its object's.
  static bool moves(const CornerView& view, const PanelEdge& edge) {
    return view.moved_object < 0 || view.moved_object == edge.object;
  }
  // Edge e's span in a view (nothing where an end is behind the camera).
  std::optional<Segment> seen_at(const CornerView& view, std::size_t e) const {
    const auto u0 = view.camera.project(view.object_motion * spans_[e][0]);
    const auto u1 = view.camera.project(view.object_motion * spans_[e][1]);
    if (!u0 || !u1) return std::nullopt;
    return Segment{*u0, *u1};
  }
  // The whole edge's image length in a view (0 where an end is behind the camera).
  double whole_length(const CornerView& view, const PanelEdge& edge) const {
    const Eigen::Isometry3d& pose = objects_[static_cast<std::size_t>(edge.object)].pose;
    const auto u0 = view.camera.project(view.object_motion * (pose * edge.p0));
    const auto u1 = view.camera.project(view.object_motion * (pose * edge.p1));
    return u0 && u1 ? (*u1 - *u0).norm() : 0.0;
  }

  const std::vector<SceneObject>& objects_;
  CornerView believed_;
  std::vector<SpanWorld> spans_;
  std::vector<CornerView> views_;
};

}  // namespace

ModelPanel::ModelPanel(const Scene& scene, const Camera& camera,
                       const ExpectationUncertainty& uncertainty,
                       const ExpectedSceneOptions& options)
    : camera_(camera), uncertainty_(uncertainty) {
  const auto& scene_objects = scene.objects();
  if (!uncertainty.objects.empty() && uncertainty.objects.size() != scene_objects.size())
    throw SensingError("expected scene: " + std::to_string(uncertainty.objects.size()) +
                       " object uncertainties for " + std::to_string(scene_objects.size()) +
                       " objects");
  if (!(uncertainty.noise_px >= 0 && std::isfinite(uncertainty.noise_px)))
    throw SensingError("expected scene: the image noise must be a number >= 0 (pixels)");
  const Rendering seen =
      render(scene, camera, {.faces = true, .edges = true, .supersampling = options.supersampling});
  std::vector<SpanWorld> spans;
  edges_ = panel_edges(seen, scene_objects, spans);
  faces_ = panel_faces(seen, scene_objects, edges_, options.supersampling * options.supersampling);
  vertices_ = panel_vertices(edges_, faces_);
  objects_ = panel_objects(scene_objects, faces_, edges_);
  neighbours_ = face_neighbours(faces_, edges_.size());
  const CornerAnalysis analysis(scene_objects, camera, uncertainty, std::move(spans));
  analysis.set_edge_tolerances(edges_, uncertainty.noise_px);
  relational_ = analysis.relational_tolerances(edges_, neighbours_, uncertainty.noise_px);
}

int ModelPanel::edge_index(std::string_view id) const {
  for (std::size_t e = 0; e < edges_.size(); ++e)
    if (edges_[e].id == id) return static_cast<int>(e);
  return -1;
}

const Tolerance& ModelPanel::relational(int a, int b) const {
  const auto found = relational_.find({a, b});
  if (found == relational_.end())
    throw SensingError("expected scene: edges " + std::to_string(a) + " and " + std::to_string(b) +
                       " share no visible face");
  return found->second;
}

}  // namespace spar::sensing::pseiki
