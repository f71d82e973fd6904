// Scene: object models at poses in the world, what a sensor looks at. The renderer (render.hpp)
// finds which of their faces and edges a camera sees, with occlusion between the objects.
//
// A scene keeps references to each object's model and features (model_features.hpp): they must
// outlive the scene, which is a cheap value built where it is used (one per hypothesis, per
// candidate sensing operation). It copies the vertices into the world frame, and the faces'
// outward normals and plane offsets (normal · x = offset).
//
// Example:
//   const ObjectModel block = make_builtin_object("block");
//   const ObjectFeatures features = object_features(block);
//   Scene scene;
//   const int index = scene.add("block", block, features, Eigen::Isometry3d::Identity());
//   scene.objects()[index].face_normals[0];   // face 1's outward normal, world frame
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "spar/geometry/object.hpp"
#include "spar/sensing/model_features.hpp"

namespace spar::sensing {

struct SceneObject {
  std::string name;
  const geometry::ObjectModel* model{nullptr};            // not owned: outlives the scene
  const ObjectFeatures* features{nullptr};                // not owned: outlives the scene
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  // object frame in the world
  std::vector<Eigen::Vector3d> vertices;                  // the mesh's vertices, world frame
  std::vector<Eigen::Vector3d> face_normals;              // [face id - 1], world frame
  std::vector<double> face_offsets;                       // [face id - 1], world frame
};

class Scene {
 public:
  // Adds an object (SensingError if `features` are not the model's); returns its index.
  int add(std::string name, const geometry::ObjectModel& model, const ObjectFeatures& features,
          const Eigen::Isometry3d& pose);
  [[nodiscard]] const std::vector<SceneObject>& objects() const { return objects_; }
  // The diagonal of the box around every vertex (0 for an empty scene): the length scale of
  // tolerances.
  [[nodiscard]] double scale() const;

 private:
  std::vector<SceneObject> objects_;
};

}  // namespace spar::sensing
