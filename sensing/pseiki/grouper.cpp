#include "spar/sensing/pseiki/grouper.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "spar/sensing/pseiki/hierarchical_evidence.hpp"

namespace spar::sensing::pseiki {
namespace {

// The fraction of panel edge `m`'s visible length covered by `members` (image edges) projected on
// its line, and their length-weighted mean belief.
struct Cover {
  double fraction{0}, belief{0};
};

Cover cover_of(const Blackboard& board, int m, const std::vector<int>& members,
               double minimum_belief) {
  const PanelEdge& panel = board.model().edges()[static_cast<std::size_t>(m)];
  const Eigen::Vector2d origin = panel.span.p0, direction = panel.span.direction();
  const double length = panel.span.length();
  std::vector<std::pair<double, double>> spans;
  double weighted = 0, total = 0;
  for (const int e : members) {
    const ImageEdge& edge = board.edges[static_cast<std::size_t>(e)];
    if (edge.label != m || edge.belief < minimum_belief) continue;
    const double s0 = std::clamp((edge.segment.p0 - origin).dot(direction), 0.0, length);
    const double s1 = std::clamp((edge.segment.p1 - origin).dot(direction), 0.0, length);
    spans.emplace_back(std::min(s0, s1), std::max(s0, s1));
    weighted += edge.belief * edge.segment.length();
    total += edge.segment.length();
  }
  if (spans.empty() || !(panel.visible_length > 0)) return {};
  std::sort(spans.begin(), spans.end());
  double covered = 0, reach = 0;
  for (const auto& [from, to] : spans) {
    const double start = std::max(from, reach);
    if (to > start) covered += to - start;
    reach = std::max(reach, to);
  }
  return {std::min(1.0, covered / panel.visible_length), total > 0 ? weighted / total : 0.0};
}

// Overlap of two regions normalised by their mean area (0 when either is degenerate).
double normalised_overlap(const internal::Polygon& a, const internal::Polygon& b) {
  const double mean = 0.5 * (internal::area(a) + internal::area(b));
  return mean > 0 ? internal::overlap_area(a, b) / mean : 0.0;
}

// Bel and Bel(not) of one label from its pieces: a tree root -> {label, the rest}.
std::pair<double, double> dichotomy(const std::vector<std::pair<double, double>>& pieces) {
  HypothesisTree tree;
  const int label = tree.add_node(0, "label");
  tree.add_node(0, "rest");
  for (const auto& [for_it, against_it] : pieces)
    tree.add_evidence(label, capped(for_it), capped(against_it));
  const TreeBeliefs combined = tree.combine();
  return {combined.belief[static_cast<std::size_t>(label)],
          1 - combined.plausibility[static_cast<std::size_t>(label)]};
}

}  // namespace

double coverage_floor(const std::vector<double>& lengths, double detection_probability) {
  constexpr double kBins = 1024;
  const double p = detection_probability;
  double total = 0;
  for (const double length : lengths) total += length;
  if (!(total > 0)) return 0;
  // mass[k]: the probability that the edges found so far cover k bins; `full` bins is all of them
  // (the rounded shares need not add up to kBins exactly).
  std::vector<std::size_t> shifts;
  std::size_t full = 0;
  for (const double length : lengths) {
    shifts.push_back(static_cast<std::size_t>(std::lround(length / total * kBins)));
    full += shifts.back();
  }
  if (full == 0) return 0;
  std::vector<double> mass(full + 1, 0.0), next(full + 1);
  mass[0] = 1;
  std::size_t reach = 0;  // highest bin with mass
  for (const std::size_t shift : shifts) {
    std::fill(next.begin(), next.end(), 0.0);
    for (std::size_t bin = 0; bin <= reach; ++bin) {
      next[bin] += (1 - p) * mass[bin];
      next[bin + shift] += p * mass[bin];
    }
    reach += shift;
    mass.swap(next);
  }
  double below = 0;
  for (std::size_t bin = 0; bin <= full; ++bin) {
    below += mass[bin];
    if (below >= kCoverageQuantile) return double(bin) / double(full);
  }
  return 1;
}

void Grouper::group(Blackboard& board) const {
  group_faces(board);
  group_objects(board);
  group_scene(board);
}

void Grouper::group_faces(Blackboard& board) const {
  const ModelPanel& model = board.model();
  // Doubt about each object from the previous round, before the faces are replaced.
  std::vector<double> object_doubt(model.objects().size(), 0.0);
  for (const ImageObject& object : board.objects)
    object_doubt[static_cast<std::size_t>(object.label)] = object.disbelief;

  std::vector<ImageFace> faces;
  for (std::size_t f = 0; f < model.faces().size(); ++f) {
    const PanelFace& panel = model.faces()[f];
    ImageFace face{.label = static_cast<int>(f)};
    std::vector<Eigen::Vector2d> corners;
    for (std::size_t e = 0; e < board.edges.size(); ++e) {
      const ImageEdge& edge = board.edges[e];
      if (!edge.active || edge.label < 0 ||
          std::find(panel.edges.begin(), panel.edges.end(), edge.label) == panel.edges.end())
        continue;
      face.members.push_back(static_cast<int>(e));
      for (const int v : edge.vertices)
        corners.push_back(board.vertices[static_cast<std::size_t>(v)].pixel);
    }
    if (face.members.empty()) continue;
    face.region = internal::convex_hull(corners);
    double total_length = 0, seen = 0;
    for (const int m : panel.edges)
      total_length += model.edges()[static_cast<std::size_t>(m)].visible_length;
    for (const int m : panel.edges) {
      const Cover cover = cover_of(board, m, face.members, 0.0);
      seen +=
          model.edges()[static_cast<std::size_t>(m)].visible_length * cover.fraction * cover.belief;
    }
    face.support =
        capped(total_length > 0 ? seen / total_length / board.detection_probability() : 0);
    faces.push_back(std::move(face));
  }

  for (std::size_t i = 0; i < faces.size(); ++i) {
    ImageFace& face = faces[i];
    const PanelFace& panel = model.faces()[static_cast<std::size_t>(face.label)];
    HypothesisTree tree;
    const int object =
        tree.add_node(0, model.objects()[static_cast<std::size_t>(panel.object)].name);
    const int leaf = tree.add_node(object, panel.id);
    tree.add_node(object, "other faces");
    tree.add_node(0, "none");
    tree.add_for(leaf, face.support);
    for (std::size_t j = 0; j < faces.size(); ++j) {
      if (j == i) continue;
      const PanelFace& other = model.faces()[static_cast<std::size_t>(faces[j].label)];
      const double excess = normalised_overlap(face.region, faces[j].region) -
                            normalised_overlap(panel.region, other.region);
      if (excess > 0) tree.add_against(leaf, capped(excess * faces[j].support));
    }
    if (object_doubt[static_cast<std::size_t>(panel.object)] > 0)
      tree.add_against(object, capped(object_doubt[static_cast<std::size_t>(panel.object)]));
    const TreeBeliefs combined = tree.combine();
    face.belief = combined.belief[static_cast<std::size_t>(leaf)];
    face.disbelief = 1 - combined.plausibility[static_cast<std::size_t>(leaf)];
  }
  board.faces = std::move(faces);
}

void Grouper::group_objects(Blackboard& board) const {
  const ModelPanel& model = board.model();
  std::vector<ImageObject> objects;
  for (std::size_t o = 0; o < model.objects().size(); ++o) {
    const PanelObject& panel = model.objects()[o];
    if (panel.edges.empty()) continue;  // nothing of it is visible
    ImageObject object{.label = static_cast<int>(o)};
    double area = 0, supported = 0;
    for (const int f : panel.faces) area += model.faces()[static_cast<std::size_t>(f)].area_px;
    std::vector<int> members;
    for (std::size_t i = 0; i < board.faces.size(); ++i) {
      const ImageFace& face = board.faces[i];
      const PanelFace& face_panel = model.faces()[static_cast<std::size_t>(face.label)];
      if (face_panel.object != static_cast<int>(o)) continue;
      object.faces.push_back(static_cast<int>(i));
      supported += face_panel.area_px * face.belief;
      members.insert(members.end(), face.members.begin(), face.members.end());
    }
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    double seen = 0;
    std::vector<double> lengths;
    for (const int m : panel.edges) {
      const double length = model.edges()[static_cast<std::size_t>(m)].visible_length;
      seen += length * cover_of(board, m, members, kDetectionBelief).fraction;
      lengths.push_back(length);
    }
    object.coverage = seen / panel.visible_length;
    const double floor = coverage_floor(lengths, board.detection_probability());
    const double deficit = floor > 0 ? (floor - object.coverage) / floor : 0.0;
    const auto [belief, disbelief] =
        dichotomy({{area > 0 ? supported / area : 0.0, 0.0}, {0.0, deficit}});
    object.belief = belief;
    object.disbelief = disbelief;
    objects.push_back(std::move(object));
  }
  board.objects = std::move(objects);
}

void Grouper::group_scene(Blackboard& board) const {
  double supported = 0;
  std::vector<std::pair<double, double>> pieces;
  for (const ImageObject& object : board.objects) {
    supported += object.belief;
    pieces.emplace_back(0.0, object.disbelief);
  }
  pieces.emplace_back(board.objects.empty() ? 0.0 : supported / double(board.objects.size()), 0.0);
  const auto [belief, disbelief] = dichotomy(pieces);
  board.scene = {.belief = belief, .disbelief = disbelief};
}

}  // namespace spar::sensing::pseiki
