#include "spar/sensing/sensors.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "spar/common/number.hpp"
#include "spar/sensing/error.hpp"
#include "spar/sensing/render.hpp"

namespace spar::sensing {

const char* to_string(SensorKind kind) {
  return kind == SensorKind::kRangeScanner ? "range scanner" : "camera";
}

const char* to_string(Mount mount) { return mount == Mount::kFixed ? "fixed" : "wrist"; }

SensorModel default_range_scanner() {
  SensorModel scanner;
  scanner.name = "range_scan";
  scanner.kind = SensorKind::kRangeScanner;
  scanner.intrinsics = {.fx = 277, .fy = 277, .cx = 160, .cy = 120, .width = 320, .height = 240};
  scanner.mount = Mount::kWrist;
  return scanner;
}

void check_sensor(const SensorModel& sensor) {
  const auto fail = [&](const std::string& what) {
    throw SensingError("sensor '" + sensor.name + "': " + what);
  };
  if (!(sensor.detection_probability > 0 && sensor.detection_probability <= 1))
    fail("detection_probability must be in (0, 1], got " +
         format_number(sensor.detection_probability));
  for (const auto& [value, name] :
       {std::pair{sensor.noise_px, "noise_px"}, std::pair{sensor.position_noise, "position noise"},
        std::pair{sensor.normal_noise, "normal noise"}})
    if (!(value >= 0 && std::isfinite(value)))
      fail(std::string(name) + " must be a finite number >= 0, got " + format_number(value));
  if (!(sensor.max_angle > 0 && sensor.max_angle <= std::numbers::pi / 2 + 1e-12))
    fail("max_angle must be in (0, 90] degrees");
  try {
    (void)Camera(sensor.projection, sensor.intrinsics, Eigen::Isometry3d::Identity());
  } catch (const SensingError& error) {
    fail(error.what());
  }
}

double face_prominence(double projected_area, double object_projected_area) {
  return object_projected_area > 0 ? std::min(1.0, projected_area / (0.1 * object_projected_area))
                                   : 0.0;
}

double edge_prominence(double projected_length, double contrast, double object_diameter) {
  return object_diameter > 0 ? contrast * std::min(1.0, projected_length / (0.1 * object_diameter))
                             : 0.0;
}

Camera place(const SensorModel& sensor, const Eigen::Isometry3d& sensor_pose) {
  return Camera(sensor.projection, sensor.intrinsics, sensor_pose);
}

Observation predict(const Scene& scene, const SensorModel& sensor,
                    const Eigen::Isometry3d& sensor_pose) {
  const Camera camera = place(sensor, sensor_pose);
  const bool scanner = sensor.kind == SensorKind::kRangeScanner;
  RenderOptions options;
  options.faces = scanner;
  options.edges = !scanner;
  const Rendering seen = render(scene, camera, options);
  Observation out{.sensor = sensor.name,
                  .kind = sensor.kind,
                  .sensor_pose = sensor_pose,
                  .faces = {},
                  .edges = {}};
  if (scanner) {
    std::map<int, double> projected;  // per object: its faces' visible projected area
    for (const FaceView& view : seen.faces) {
      if (view.samples < kMinFaceSamples || !(view.angle < sensor.max_angle)) continue;
      const SceneObject& object = scene.objects()[static_cast<std::size_t>(view.object)];
      SensedFace face;
      face.normal = object.face_normals[static_cast<std::size_t>(view.face - 1)];
      face.position = view.centroid;
      face.area = view.visible_area;
      face.truth_object = view.object;
      face.truth_face = view.face;
      face.prominence = view.visible_area * std::cos(view.angle);  // projected, for now
      projected[view.object] += face.prominence;
      out.faces.push_back(face);
    }
    for (SensedFace& face : out.faces)
      face.prominence = face_prominence(face.prominence, projected[face.truth_object]);
    return out;
  }
  for (const EdgeView& view : seen.edges) {
    const double length = (view.u1 - view.u0).norm();
    if (length < kMinEdgePixels) continue;
    const SceneObject& object = scene.objects()[static_cast<std::size_t>(view.object)];
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& vertex : object.vertices) box.extend(vertex);
    const double depth = std::max(camera.to_camera(box.center()).z(), kNearPlane);
    const double diameter = box.diagonal().norm() * camera.intrinsics().fx /
                            (sensor.projection == Projection::kPinhole ? depth : 1.0);
    out.edges.push_back({.u0 = view.u0,
                         .u1 = view.u1,
                         .contrast = view.contrast,
                         .prominence = edge_prominence(length, view.contrast, diameter),
                         .truth_object = view.object,
                         .truth_edge = view.edge});
  }
  return out;
}

Observation measure(const Scene& scene, const SensorModel& sensor,
                    const Eigen::Isometry3d& sensor_pose, std::mt19937_64& random) {
  const Observation ideal = predict(scene, sensor, sensor_pose);
  std::bernoulli_distribution found(sensor.detection_probability);
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto jitter = [&](double sigma) {
    return Eigen::Vector3d(sigma * normal(random), sigma * normal(random), sigma * normal(random));
  };
  Observation out = ideal;
  out.faces.clear();
  out.edges.clear();
  for (SensedFace face : ideal.faces) {
    if (!found(random)) continue;
    face.normal = (face.normal + jitter(sensor.normal_noise)).normalized();
    face.position += jitter(sensor.position_noise);
    face.area *= std::max(0.0, 1 + 0.05 * normal(random));
    out.faces.push_back(face);
  }
  for (SensedEdge edge : ideal.edges) {
    if (!found(random)) continue;
    edge.u0 += sensor.noise_px * Eigen::Vector2d(normal(random), normal(random));
    edge.u1 += sensor.noise_px * Eigen::Vector2d(normal(random), normal(random));
    out.edges.push_back(edge);
  }
  return out;
}

}  // namespace spar::sensing
