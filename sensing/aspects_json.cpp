#include "spar/sensing/aspects_json.hpp"

#include <numbers>

namespace spar::sensing {

nlohmann::ordered_json aspects_json(const geometry::ObjectModel& model, const AspectSet& aspects,
                                    const AspectOptions& options, const std::string& units,
                                    double metres_per_unit) {
  const double unit = metres_per_unit;
  const ObjectFeatures features = object_features(model);
  nlohmann::ordered_json out;
  out["object"] = model.name();
  out["units"] = units;
  out["method"] = to_string(aspects.method);
  out["max_angle"] = aspects.max_angle * 180 / std::numbers::pi;
  if (aspects.method == AspectMethod::kViewSphere)
    out["view_sphere"] = {{"level", options.view_sphere_level},
                          {"cells", aspects.cells.size()},
                          {"resolution", options.resolution}};
  out["aspects"] = nlohmann::ordered_json::array();
  for (const Aspect& aspect : aspects.aspects) {
    const AspectFeatures seen = aspect_features(model, features, aspect, options);
    nlohmann::ordered_json faces = nlohmann::ordered_json::array();
    nlohmann::ordered_json edges = nlohmann::ordered_json::array();
    for (const FaceProminence& face : seen.faces)
      faces.push_back({{"face", face.face},
                       {"visible_area", face.visible_area / (unit * unit)},
                       {"prominence", face.prominence}});
    for (const EdgeProminence& edge : seen.edges) {
      const ModelEdge& model_edge = features.edges[static_cast<std::size_t>(edge.edge - 1)];
      edges.push_back({{"edge", edge.edge},
                       {"faces", {model_edge.face_a, model_edge.face_b}},
                       {"visible_length", edge.visible_length / unit},
                       {"contrast", edge.contrast},
                       {"prominence", edge.prominence}});
    }
    out["aspects"].push_back(
        {{"label", aspect.label},
         {"faces", aspect.faces},
         {"solid_angle", aspect.solid_angle},
         {"direction", {aspect.direction.x(), aspect.direction.y(), aspect.direction.z()}},
         {"features", {{"faces", faces}, {"edges", edges}}}});
  }
  return out;
}

}  // namespace spar::sensing
