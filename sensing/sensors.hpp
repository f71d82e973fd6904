// Simulated sensors: what a range scanner or a camera reports of a scene (the renderer of
// render.hpp, so objects occlude each other), either as predicted (noise-free, every feature
// found) or as measured (noise, features missed).
//
// A sensor is a camera geometry (camera.hpp: projection, intrinsics) with a pose that is fixed in
// the world or carried on the robot's wrist (then sensing operations move it to viewpoints), and
// a noise model:
//   range scanner  reports faces: for each face it sees within `max_angle` of the face's normal
//                  (the scanner gets no surface from a grazing view) and with at least
//                  kMinFaceSamples samples, the face's outward normal, the centroid of its visible
//                  part and its visible area (world frame). Noise: N(0, normal_noise²) added to
//                  each component of the normal, renormalised (normal_noise in rad: the turn is
//                  about that per axis), the centroid moved by N(0, position_noise²) per axis
//                  (m), the area scaled by N(1, 0.05²).
//   camera         reports edges: each visible piece of a model edge (hidden lines removed, at
//                  least kMinEdgePixels long), endpoints in pixels. Noise: each endpoint moved by
//                  N(0, noise_px²) per axis.
// Both: each feature is found independently with probability `detection_probability`.
// Prominence (the survey's weight of an expected feature: how surely a sensor finds it, so how
// much its absence says), the same for predictions here and for aspects (aspects.hpp):
//   face  min(1, a / (0.1 A)): a its visible area projected on the image plane, A the sum of a
//         over the object's faces in the view; a face filling a tenth of the object's image is
//         fully prominent, a sliver seen through a hole hardly at all.
//   edge  c · min(1, l / (0.1 D)): l its visible projected length, D the object's projected
//         diameter (twice its bounding radius, at its centre's depth for a pinhole), c its
//         contrast (render.hpp: 1 on the silhouette, else the difference of its faces' shading).
// A feature remembers which object and model face or edge it came from (`truth_*`), for tests and
// reports only: hypothesis generation (hypotheses.hpp) never reads it.
//
// Example:
//   const SensorModel scanner = default_range_scanner();
//   const Observation seen = predict(scene, scanner, sensor_pose);        // noise-free
//   std::mt19937_64 random(1);
//   const Observation measured = measure(scene, scanner, sensor_pose, random);
#pragma once

#include <Eigen/Geometry>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "spar/sensing/camera.hpp"
#include "spar/sensing/scene.hpp"

namespace spar::sensing {

// A range scanner's segmentation reports planar patches of at least this many samples; a camera's
// edge detector reports segments at least this long.
inline constexpr int kMinFaceSamples = 30;
inline constexpr double kMinEdgePixels = 5.0;

enum class SensorKind { kRangeScanner, kCamera };
enum class Mount { kFixed, kWrist };
[[nodiscard]] const char* to_string(SensorKind kind);  // "range scanner", "camera"
[[nodiscard]] const char* to_string(Mount mount);      // "fixed", "wrist"

struct SensorModel {
  std::string name;
  SensorKind kind{SensorKind::kCamera};
  Projection projection{Projection::kPinhole};
  Intrinsics intrinsics{};
  // Fixed: the sensor frame (camera.hpp's convention) in the world. Wrist: in the gripper frame.
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};
  Mount mount{Mount::kFixed};
  double max_angle{75 * std::numbers::pi / 180};  // range scanner: faces seen within this
  double noise_px{0.5};                           // camera: endpoint standard deviation, pixels
  double position_noise{0.001};                   // range scanner: metres
  double normal_noise{0.01};                      // range scanner: radians
  double detection_probability{0.95};             // in (0, 1]
};

// A wrist-mounted range scanner with a 320 x 240 pinhole depth image of about 60° x 47° field of
// view, 1 mm and 0.01 rad noise, finding 95% of the faces it sees.
[[nodiscard]] SensorModel default_range_scanner();

struct SensedFace {
  Eigen::Vector3d normal{Eigen::Vector3d::UnitZ()};   // unit, world frame
  Eigen::Vector3d position{Eigen::Vector3d::Zero()};  // visible part's centroid, world frame
  double area{0};                                     // visible area, m²
  double prominence{0};                               // as above, in [0, 1] (predicted)
  int truth_object{-1}, truth_face{0};
};

struct SensedEdge {
  Eigen::Vector2d u0{Eigen::Vector2d::Zero()}, u1{Eigen::Vector2d::Zero()};  // pixels
  double contrast{0};
  double prominence{0};  // as above, in [0, 1] (predicted)
  int truth_object{-1}, truth_edge{0};
};

struct Observation {
  std::string sensor;
  SensorKind kind{SensorKind::kCamera};
  Eigen::Isometry3d sensor_pose{Eigen::Isometry3d::Identity()};  // where it was, world frame
  std::vector<SensedFace> faces;                                 // range scanner
  std::vector<SensedEdge> edges;                                 // camera
};

// The sensor at `sensor_pose` (world) as a camera.
[[nodiscard]] Camera place(const SensorModel& sensor, const Eigen::Isometry3d& sensor_pose);

// What the sensor reports of every object of the scene without noise or misses, with each
// feature's prominence.
[[nodiscard]] Observation predict(const Scene& scene, const SensorModel& sensor,
                                  const Eigen::Isometry3d& sensor_pose);
// A measurement: the prediction with misses and noise drawn from `random`.
[[nodiscard]] Observation measure(const Scene& scene, const SensorModel& sensor,
                                  const Eigen::Isometry3d& sensor_pose, std::mt19937_64& random);

[[nodiscard]] double face_prominence(double projected_area, double object_projected_area);
[[nodiscard]] double edge_prominence(double projected_length, double contrast,
                                     double object_diameter);

// SensingError unless the model's numbers are in range (noise >= 0, detection probability in
// (0, 1], max_angle in (0, 90°], a valid camera).
void check_sensor(const SensorModel& sensor);

}  // namespace spar::sensing
