#include "spar/sensing/model_features.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>

namespace spar::sensing {
namespace {

// One mesh edge between two faces, directed along face_a's boundary.
struct Piece {
  double start{0}, end{0};  // parameters along the pair's reference line, start < end
  bool forward{true};       // runs along the reference direction
};

}  // namespace

ObjectFeatures object_features(const geometry::ObjectModel& model) {
  const geometry::Mesh& mesh = model.mesh();
  ObjectFeatures out;
  out.triangle_face.assign(mesh.triangles.size(), 0);
  for (const geometry::Face& face : model.faces())
    for (const int t : face.triangles) out.triangle_face[static_cast<std::size_t>(t)] = face.id;
  out.face_edges.resize(model.faces().size());

  // Directed mesh edge -> triangle that runs it (validated meshes have each once, with a twin).
  std::map<std::pair<int, int>, int> owner;
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t)
    for (int c = 0; c < 3; ++c) owner[{mesh.triangles[t][c], mesh.triangles[t][(c + 1) % 3]}] = t;

  // Face pair -> the line's origin and direction (from its first piece), and its pieces.
  struct Line {
    Eigen::Vector3d origin, direction;
    std::vector<Piece> pieces;
  };
  std::map<std::pair<int, int>, Line> lines;
  for (const auto& [edge, t] : owner) {
    const auto twin = owner.find({edge.second, edge.first});
    if (twin == owner.end()) continue;  // cannot happen on a validated mesh
    const int face = out.triangle_face[static_cast<std::size_t>(t)];
    const int other = out.triangle_face[static_cast<std::size_t>(twin->second)];
    if (face >= other) continue;  // each pair once, from face_a's side; none inside a face
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(edge.first)];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(edge.second)];
    auto [it, inserted] = lines.try_emplace({face, other});
    Line& line = it->second;
    if (inserted) {
      line.origin = a;
      line.direction = (b - a).normalized();
    }
    const double s = (a - line.origin).dot(line.direction);
    const double e = (b - line.origin).dot(line.direction);
    line.pieces.push_back({std::min(s, e), std::max(s, e), e > s});
  }

  const double tolerance = model.tolerance();
  for (auto& [pair, line] : lines) {
    const Eigen::Vector3d& normal_a = model.face(pair.first).normal;
    const Eigen::Vector3d& normal_b = model.face(pair.second).normal;
    std::sort(line.pieces.begin(), line.pieces.end(), [](const Piece& x, const Piece& y) {
      return std::tie(x.forward, x.start) < std::tie(y.forward, y.start);
    });
    for (std::size_t i = 0; i < line.pieces.size();) {
      Piece run = line.pieces[i];
      std::size_t j = i + 1;
      for (; j < line.pieces.size() && line.pieces[j].forward == run.forward &&
             line.pieces[j].start <= run.end + tolerance;
           ++j)
        run.end = std::max(run.end, line.pieces[j].end);
      ModelEdge edge;
      edge.face_a = pair.first;
      edge.face_b = pair.second;
      const Eigen::Vector3d from = line.origin + run.start * line.direction;
      const Eigen::Vector3d to = line.origin + run.end * line.direction;
      edge.p0 = run.forward ? from : to;
      edge.p1 = run.forward ? to : from;
      edge.dihedral = std::acos(std::clamp(normal_a.dot(normal_b), -1.0, 1.0));
      edge.convex = normal_a.cross(normal_b).dot(edge.p1 - edge.p0) > 0;
      out.edges.push_back(edge);
      i = j;
    }
  }
  // `lines` iterates by face pair, and a pair's runs come by direction, then start: the ids.
  for (std::size_t k = 0; k < out.edges.size(); ++k) {
    ModelEdge& edge = out.edges[k];
    edge.id = static_cast<int>(k) + 1;
    out.face_edges[static_cast<std::size_t>(edge.face_a - 1)].push_back(edge.id);
    out.face_edges[static_cast<std::size_t>(edge.face_b - 1)].push_back(edge.id);
  }
  for (std::vector<int>& ids : out.face_edges) std::sort(ids.begin(), ids.end());
  return out;
}

}  // namespace spar::sensing
