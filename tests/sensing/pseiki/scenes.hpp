// Scenes for PSEIKI's tests: boxes on a table seen obliquely by a pinhole camera, with the pose
// uncertainty the tests perturb within. The models live in the fixture, so the scene (which
// refers to them) is valid as long as it is.
#pragma once

#include <Eigen/Geometry>
#include <deque>
#include <string>
#include <vector>

#include "spar/geometry/mesh.hpp"
#include "spar/geometry/object.hpp"
#include "spar/sensing/camera.hpp"
#include "spar/sensing/model_features.hpp"
#include "spar/sensing/pseiki/expected_scene.hpp"
#include "spar/sensing/scene.hpp"

namespace spar::sensing::pseiki::testing {

// A box of `size` (metres) whose frame is at the centre of its bottom face (make_box's spans
// [0, size]).
inline geometry::ObjectModel box_on_table(const std::string& name, const Eigen::Vector3d& size) {
  geometry::Mesh mesh = geometry::make_box(size);
  for (Eigen::Vector3d& v : mesh.vertices) v -= Eigen::Vector3d(size.x() / 2, size.y() / 2, 0);
  return geometry::ObjectModel(name, std::move(mesh));
}

inline Eigen::Isometry3d at(double x, double y, double yaw = 0) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, 0);
  return pose;
}

struct TestScene {
  std::deque<geometry::ObjectModel> models;  // deque: adding keeps the others' addresses
  std::deque<ObjectFeatures> features;
  Scene scene;
  Camera camera;
  ExpectationUncertainty uncertainty;

  explicit TestScene(const Camera& view) : camera(view) {}
  void add(const std::string& name, const Eigen::Vector3d& size, const Eigen::Isometry3d& pose,
           const kinematics::PoseUncertainty& half_widths) {
    models.push_back(box_on_table(name, size));
    features.push_back(object_features(models.back()));
    scene.add(name, models.back(), features.back(), pose);
    uncertainty.objects.push_back(half_widths);
  }
};

inline Camera oblique_camera() {
  return Camera(Projection::kPinhole,
                {.fx = 800, .fy = 800, .cx = 320, .cy = 240, .width = 640, .height = 480},
                look_at({0.55, -0.65, 0.75}, {0.05, 0.02, 0.05}, {0, 0, 1}));
}

// Straight down on the table from 1.1 m, f = 800 px.
inline Camera straight_down_camera() {
  return Camera(Projection::kPinhole,
                {.fx = 800, .fy = 800, .cx = 320, .cy = 240, .width = 640, .height = 480},
                look_at({0, 0, 1.1}, {0, 0, 0}, {0, 1, 0}));
}

// Two boxes on a table, each uncertain by 5 mm and 1 degree; noise 0.5 px.
inline TestScene two_boxes() {
  TestScene test(oblique_camera());
  const kinematics::PoseUncertainty uncertain{.dx = 0.005, .dy = 0.005, .dz = 0, .dtheta = 0.0175};
  test.add("block", {0.20, 0.14, 0.08}, at(0, 0), uncertain);
  test.add("tower", {0.08, 0.08, 0.18}, at(0.2, 0.15, 0.3), uncertain);
  test.uncertainty.noise_px = 0.5;
  return test;
}

}  // namespace spar::sensing::pseiki::testing
