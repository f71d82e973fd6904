#include "spar/sensing/scene.hpp"

#include <algorithm>
#include <limits>

#include "spar/sensing/error.hpp"

namespace spar::sensing {

int Scene::add(std::string name, const geometry::ObjectModel& model, const ObjectFeatures& features,
               const Eigen::Isometry3d& pose) {
  if (features.triangle_face.size() != model.mesh().triangles.size() ||
      features.face_edges.size() != model.faces().size())
    throw SensingError("scene: the features given for '" + name + "' are not its model's");
  SceneObject object;
  object.name = std::move(name);
  object.model = &model;
  object.features = &features;
  object.pose = pose;
  object.vertices.reserve(model.mesh().vertices.size());
  for (const Eigen::Vector3d& vertex : model.mesh().vertices)
    object.vertices.push_back(pose * vertex);
  for (const geometry::Face& face : model.faces()) {
    const Eigen::Vector3d normal = pose.linear() * face.normal;
    object.face_normals.push_back(normal);
    object.face_offsets.push_back(face.offset + normal.dot(pose.translation()));
  }
  objects_.push_back(std::move(object));
  return static_cast<int>(objects_.size()) - 1;
}

double Scene::scale() const {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  bool any = false;
  for (const SceneObject& object : objects_)
    for (const std::array<int, 3>& triangle : object.model->mesh().triangles)
      for (const int v : triangle) {
        low = low.cwiseMin(object.vertices[static_cast<std::size_t>(v)]);
        high = high.cwiseMax(object.vertices[static_cast<std::size_t>(v)]);
        any = true;
      }
  return any ? (high - low).norm() : 0.0;
}

}  // namespace spar::sensing
