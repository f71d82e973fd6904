#include "spar/sensing/pseiki/blackboard.hpp"

#include <algorithm>
#include <cmath>

#include "spar/sensing/error.hpp"

namespace spar::sensing::pseiki {

Blackboard::Blackboard(const ModelPanel& model, std::vector<ImageEdgeInput> image,
                       double detection_probability)
    : model_(&model), inputs_(std::move(image)), detection_probability_(detection_probability) {
  if (!(detection_probability > 0 && detection_probability <= 1))
    throw SensingError("blackboard: the detection probability must be in (0, 1]");
  for (std::size_t i = 0; i < inputs_.size(); ++i)
    add_edge({.segment = inputs_[i].segment, .inputs = {static_cast<int>(i)}});
  connect_vertices();
}

int Blackboard::add_edge(ImageEdge edge) {
  edges.push_back(std::move(edge));
  return static_cast<int>(edges.size()) - 1;
}

void Blackboard::connect_vertices() {
  const double merge = 2 * model().uncertainty().noise_px + 1;
  vertices.clear();
  for (std::size_t e = 0; e < edges.size(); ++e) {
    ImageEdge& edge = edges[e];
    edge.vertices = {-1, -1};
    if (!edge.active) continue;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d& p = k == 0 ? edge.segment.p0 : edge.segment.p1;
      auto found = std::find_if(vertices.begin(), vertices.end(),
                                [&](const ImageVertex& v) { return (v.pixel - p).norm() < merge; });
      if (found == vertices.end()) {
        vertices.push_back({.pixel = p, .edges = {}});
        found = vertices.end() - 1;
      }
      found->edges.push_back(static_cast<int>(e));
      edge.vertices[static_cast<std::size_t>(k)] = static_cast<int>(found - vertices.begin());
    }
  }
}

int Blackboard::element_of(int input) const {
  int best = -1;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const ImageEdge& edge = edges[e];
    if (!edge.active ||
        std::find(edge.inputs.begin(), edge.inputs.end(), input) == edge.inputs.end())
      continue;
    if (best < 0 || edge.segment.length() > edges[static_cast<std::size_t>(best)].segment.length())
      best = static_cast<int>(e);
  }
  return best;
}

}  // namespace spar::sensing::pseiki
