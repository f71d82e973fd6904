#include "spar/sensing/pseiki/vision_json.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>

#include "spar/sensing/error.hpp"
#include "spar/sensing/internal/json_text.hpp"

namespace spar::sensing::pseiki {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;
using sensing::internal::shown;

[[noreturn]] void fail(const std::string& source, const std::string& path,
                       const std::string& what) {
  throw SensingError(source + ": " + path + ": " + what);
}

Eigen::Vector2d read_point(const json& value, const std::string& source, const std::string& path) {
  if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number())
    fail(source, path, "expected [u, v] (two numbers, pixels), got " + shown(value));
  const Eigen::Vector2d p(value[0].get<double>(), value[1].get<double>());
  if (!p.allFinite()) fail(source, path, "expected finite pixel coordinates, got " + shown(value));
  return p;
}

ordered_json point(const Eigen::Vector2d& p) { return ordered_json::array({p.x(), p.y()}); }

// Rz(yaw) Ry(pitch) Rx(roll), as scenario files write rotations.
Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& r) {
  return {std::atan2(r(2, 1), r(2, 2)), std::asin(std::clamp(-r(2, 0), -1.0, 1.0)),
          std::atan2(r(1, 0), r(0, 0))};
}

ordered_json pose_json(const Eigen::Isometry3d& pose, const OutputUnits& units) {
  const Eigen::Vector3d t = pose.translation() / units.metres_per_length;
  const Eigen::Vector3d rpy = roll_pitch_yaw(pose.linear()) / units.radians_per_angle;
  return {{"xyz", {t.x(), t.y(), t.z()}}, {"rpy", {rpy.x(), rpy.y(), rpy.z()}}};
}

ordered_json units_json(const OutputUnits& units) {
  return {{"length", units.length}, {"angle", units.angle}};
}

// The input ids of an element.
ordered_json ids_of(const ImageEdge& edge, const ImageFile& image) {
  ordered_json out = ordered_json::array();
  for (const int input : edge.inputs) out.push_back(image.ids[static_cast<std::size_t>(input)]);
  return out;
}

ordered_json label_of(const ModelPanel& panel, int label) {
  return label < 0 ? ordered_json(nullptr)
                   : ordered_json(panel.edges()[static_cast<std::size_t>(label)].id);
}

// Input edge i of the image: its element's label and belief, the inputs merged with it, or the
// labelled pieces it was split into.
ordered_json image_edge_json(std::size_t i, const Verification& result, const ImageFile& image) {
  const ModelPanel& panel = *result.expected;
  const Blackboard& board = result.board;
  const int element = board.element_of(static_cast<int>(i));
  ordered_json entry{{"id", image.ids[i]}};
  if (element < 0) {  // cannot happen: every input is in an active element or its pieces
    entry["label"] = nullptr;
    entry["belief"] = 0.0;
    return entry;
  }
  const ImageEdge& edge = board.edges[static_cast<std::size_t>(element)];
  entry["label"] = label_of(panel, edge.label);
  entry["belief"] = edge.belief;
  if (edge.inputs.size() > 1 && edge.split_from < 0) {
    ordered_json others = ordered_json::array();
    for (const int input : edge.inputs)
      if (input != static_cast<int>(i))
        others.push_back(image.ids[static_cast<std::size_t>(input)]);
    entry["merged_with"] = others;
  }
  if (edge.split_from >= 0) {
    ordered_json pieces = ordered_json::array();
    for (const ImageEdge& piece : board.edges)
      if (piece.active && piece.split_from == edge.split_from)
        pieces.push_back({{"label", label_of(panel, piece.label)},
                          {"belief", piece.belief},
                          {"p0", point(piece.segment.p0)},
                          {"p1", point(piece.segment.p1)}});
    entry["pieces"] = pieces;
  }
  return entry;
}

// The accepted interpretation's pose correction, in the output units.
ordered_json correction_json(const PoseCorrection& c, const ModelPanel& panel,
                             const std::string& camera, const OutputUnits& units) {
  const bool on_camera = c.target == kCameraTarget;
  return {{"object", on_camera ? camera : panel.objects()[static_cast<std::size_t>(c.target)].name},
          {"frame", on_camera ? "camera" : "object"},
          {"xyz",
           {c.offset.dx / units.metres_per_length, c.offset.dy / units.metres_per_length,
            c.offset.dz / units.metres_per_length}},
          {"rpy", {0.0, 0.0, c.offset.dtheta / units.radians_per_angle}},
          {"pose", pose_json(c.pose, units)},
          {"residual", c.residual_px},
          {"residual_before", c.residual_before_px},
          {"uncertainty",
           {{"dx", c.uncertainty.dx / units.metres_per_length},
            {"dy", c.uncertainty.dy / units.metres_per_length},
            {"dz", c.uncertainty.dz / units.metres_per_length},
            {"dtheta", c.uncertainty.dtheta / units.radians_per_angle}}},
          {"edges", c.observations}};
}

}  // namespace

ImageFile image_file(const json& document, const std::string& source) {
  if (!document.is_object() || !document.contains("edges"))
    throw SensingError(source +
                       ": expected an object {\"edges\": [{\"id\", \"p0\", \"p1\"}, ...]}");
  const json& edges = document.at("edges");
  if (!edges.is_array()) fail(source, "edges", "expected a list, got " + shown(edges));
  if (edges.size() > kMaxImageEdges)
    fail(source, "edges",
         "at most " + std::to_string(kMaxImageEdges) + " edges, got " +
             std::to_string(edges.size()));
  ImageFile out;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const std::string path = "edges[" + std::to_string(i) + "]";
    const json& edge = edges[i];
    if (!edge.is_object())
      fail(source, path, "expected {\"id\", \"p0\", \"p1\"}, got " + shown(edge));
    for (const char* key : {"id", "p0", "p1"})
      if (!edge.contains(key)) fail(source, path, std::string("missing key '") + key + "'");
    const json& id = edge.at("id");
    if (!(id.is_string() && !id.get<std::string>().empty()) && !id.is_number_integer())
      fail(source, path + ".id", "expected a name or a whole number, got " + shown(id));
    const std::string text = id.is_string() ? id.get<std::string>() : id.dump();
    if (!seen.insert(id.dump()).second) fail(source, path + ".id", "'" + text + "' is used twice");
    const Segment segment{read_point(edge.at("p0"), source, path + ".p0"),
                          read_point(edge.at("p1"), source, path + ".p1")};
    if (!(segment.length() > 0)) fail(source, path, "p0 and p1 are the same point, not an edge");
    out.edges.push_back({.id = text, .segment = segment});
    out.ids.push_back(id.is_string() ? ordered_json(id.get<std::string>())
                                     : ordered_json(id.get<std::int64_t>()));
  }
  return out;
}

ImageFile parse_image_json(std::string_view text, const std::string& source) {
  return image_file(sensing::internal::parse_json_text(text, source), source);
}

ImageFile load_image_file(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw SensingError(
        path.string() + ": cannot read the image file: " +
        (std::filesystem::exists(path, error) ? "not a regular file" : "no such file"));
  std::ifstream file(path, std::ios::binary);
  if (!file) throw SensingError(path.string() + ": cannot read the image file");
  std::ostringstream text;
  text << file.rdbuf();
  return parse_image_json(text.str(), path.string());
}

ordered_json render_json(const ModelPanel& panel, const std::string& camera) {
  const Intrinsics& k = panel.camera().intrinsics();
  ordered_json out{{"camera", camera},
                   {"projection", to_string(panel.camera().projection())},
                   {"width", k.width},
                   {"height", k.height}};
  const auto vertex_id = [](int v) { return std::string("v").append(std::to_string(v + 1)); };
  const auto edge_id = [&](int e) { return panel.edges()[static_cast<std::size_t>(e)].id; };
  const auto face_id = [&](int f) { return panel.faces()[static_cast<std::size_t>(f)].id; };
  out["vertices"] = ordered_json::array();
  for (std::size_t v = 0; v < panel.vertices().size(); ++v) {
    ordered_json edges = ordered_json::array();
    for (const int e : panel.vertices()[v].edges) edges.push_back(edge_id(e));
    out["vertices"].push_back({{"id", vertex_id(static_cast<int>(v))},
                               {"p", point(panel.vertices()[v].pixel)},
                               {"edges", edges}});
  }
  out["edges"] = ordered_json::array();
  for (const PanelEdge& edge : panel.edges()) {
    ordered_json faces = ordered_json::array(), pieces = ordered_json::array(),
                 vertices = ordered_json::array();
    for (const int f : edge.faces) faces.push_back(face_id(f));
    for (const Segment& piece : edge.pieces) pieces.push_back({point(piece.p0), point(piece.p1)});
    for (const auto& ends : edge.vertices)
      for (const int v : ends) vertices.push_back(vertex_id(v));
    out["edges"].push_back({{"id", edge.id},
                            {"object", panel.objects()[static_cast<std::size_t>(edge.object)].name},
                            {"faces", faces},
                            {"p0", point(edge.span.p0)},
                            {"p1", point(edge.span.p1)},
                            {"pieces", pieces},
                            {"vertices", vertices},
                            {"silhouette", edge.silhouette},
                            {"tolerance",
                             {{"angle", edge.tolerance.angle},
                              {"offset", edge.tolerance.offset},
                              {"margin", edge.tolerance.margin}}}});
  }
  out["faces"] = ordered_json::array();
  for (const PanelFace& face : panel.faces()) {
    ordered_json edges = ordered_json::array();
    for (const int e : face.edges) edges.push_back(edge_id(e));
    out["faces"].push_back({{"id", face.id},
                            {"object", panel.objects()[static_cast<std::size_t>(face.object)].name},
                            {"edges", edges},
                            {"area", face.area_px}});
  }
  out["objects"] = ordered_json::array();
  for (const PanelObject& object : panel.objects()) {
    if (object.edges.empty()) continue;
    ordered_json faces = ordered_json::array(), edges = ordered_json::array();
    for (const int f : object.faces) faces.push_back(face_id(f));
    for (const int e : object.edges) edges.push_back(edge_id(e));
    out["objects"].push_back({{"id", object.name}, {"faces", faces}, {"edges", edges}});
  }
  return out;
}

ordered_json match_json(const Verification& result, const ImageFile& image,
                        const std::string& camera, const OutputUnits& units, double acceptance) {
  const ModelPanel& panel = *result.expected;
  const Blackboard& board = result.board;
  ordered_json out{{"camera", camera}, {"passes", result.passes}};
  out["edges"] = ordered_json::array();
  for (std::size_t i = 0; i < image.edges.size(); ++i)
    out["edges"].push_back(image_edge_json(i, result, image));
  out["faces"] = ordered_json::array();
  for (const ImageFace& face : board.faces) {
    ordered_json members = ordered_json::array();
    for (const int e : face.members)
      for (const auto& id : ids_of(board.edges[static_cast<std::size_t>(e)], image))
        if (std::find(members.begin(), members.end(), id) == members.end()) members.push_back(id);
    out["faces"].push_back({{"label", panel.faces()[static_cast<std::size_t>(face.label)].id},
                            {"members", members},
                            {"belief", face.belief}});
  }
  out["objects"] = ordered_json::array();
  for (const ImageObject& object : board.objects)
    out["objects"].push_back(
        {{"label", panel.objects()[static_cast<std::size_t>(object.label)].name},
         {"belief", object.belief},
         {"coverage", object.coverage}});
  out["scene"] = {{"belief", board.scene.belief},
                  {"disbelief", board.scene.disbelief},
                  {"accepted", result.accepted},
                  {"threshold", acceptance}};
  out["pose_correction"] = result.correction
                               ? correction_json(*result.correction, panel, camera, units)
                               : ordered_json(nullptr);
  out["units"] = units_json(units);
  return out;
}

ordered_json simulated_json(const SimulatedImage& image, const Scene& believed,
                            const Camera& camera, const std::string& camera_name,
                            const OutputUnits& units) {
  ordered_json out{{"camera", camera_name}};
  out["edges"] = ordered_json::array();
  for (const SimulatedEdge& edge : image.edges)
    out["edges"].push_back(
        {{"id", edge.edge.id},
         {"p0", point(edge.edge.segment.p0)},
         {"p1", point(edge.edge.segment.p1)},
         {"truth", edge.truth.empty() ? ordered_json(nullptr) : ordered_json(edge.truth)}});
  ordered_json objects = ordered_json::array();
  for (std::size_t o = 0; o < believed.objects().size(); ++o) {
    ordered_json entry{{"name", believed.objects()[o].name}};
    entry.update(
        pose_json(offset_pose(believed.objects()[o].pose, image.object_offsets[o]), units));
    objects.push_back(entry);
  }
  out["truth"] = {{"camera", pose_json(offset_pose(camera.pose(), image.camera_offset), units)},
                  {"objects", objects},
                  {"units", units_json(units)}};
  return out;
}

}  // namespace spar::sensing::pseiki
