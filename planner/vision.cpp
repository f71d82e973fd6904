#include "spar/planner/vision.hpp"

#include <algorithm>
#include <cmath>

#include "spar/common/units.hpp"
#include "spar/geometry/collision.hpp"
#include "spar/geometry/mesh.hpp"
#include "spar/planner/error.hpp"

namespace spar::planner {
namespace {

// PSEIKI renders from a pose in the world; a wrist camera's depends on where the robot is.
sensing::Camera camera_of(const CameraSensor& sensor) {
  if (sensor.mount == sensing::Mount::kWrist)
    throw ScenarioError(sensor.location.str() + ": camera '" + sensor.name +
                        "' is on the wrist (mount: wrist); vision needs a fixed camera, posed "
                        "in the world");
  return sensing::Camera(sensor.projection, sensor.intrinsics, sensor.pose);
}

// The scene at a verification step: the object first (scene index 0), then the other objects
// where they rest, then the gripper's boxes. Owns the models and features the scene points to.
class StepScene {
 public:
  StepScene(const Scenario& scenario, int object, const kinematics::Transform& pose,
            const VisionOccluders& occluders) {
    add_object(scenario.objects.at(static_cast<std::size_t>(object)), pose);
    for (const auto& [other, at] : occluders.objects)
      if (other != object) add_object(scenario.objects.at(static_cast<std::size_t>(other)), at);
    if (occluders.gripper)
      add_gripper(*occluders.gripper, occluders.gripper_pose, occluders.opening);
  }
  [[nodiscard]] const sensing::Scene& scene() const { return scene_; }
  // The uncertainties the panel's tolerances need: the object's, the camera's and its noise
  // (occluders exact: only the object's edges are listed).
  [[nodiscard]] sensing::pseiki::ExpectationUncertainty uncertainty(
      const CameraSensor& sensor) const {
    sensing::pseiki::ExpectationUncertainty out{
        .objects = {}, .camera = sensor.uncertainty, .noise_px = sensor.noise_px};
    out.objects.resize(scene_.objects().size());
    out.objects.front() = object_uncertainty_;
    return out;
  }

 private:
  void add_object(const ObjectSpec& spec, const kinematics::Transform& pose) {
    if (scene_.objects().empty()) object_uncertainty_ = spec.uncertainty;
    const sensing::ObjectFeatures& features = *features_.emplace_back(
        std::make_unique<sensing::ObjectFeatures>(sensing::object_features(spec.model)));
    scene_.add(spec.name, spec.model, features, pose);
  }
  // geometry::gripper_body's three boxes, each an object of its own (the renderer draws closed
  // meshes; a box model is cheap).
  void add_gripper(const geometry::GripperSpec& gripper, const kinematics::Transform& pose,
                   double opening) {
    static const char* const kNames[] = {"gripper/finger+y", "gripper/finger-y", "gripper/palm"};
    const geometry::Body body = geometry::gripper_body(gripper, opening);
    for (std::size_t p = 0; p < body.parts().size(); ++p) {
      const geometry::BodyPart& part = body.parts()[p];
      const Eigen::AlignedBox3d& box = part.shape.bounds();
      const geometry::ObjectModel& model = *models_.emplace_back(
          std::make_unique<geometry::ObjectModel>(kNames[p], geometry::make_box(box.sizes())));
      const sensing::ObjectFeatures& features = *features_.emplace_back(
          std::make_unique<sensing::ObjectFeatures>(sensing::object_features(model)));
      scene_.add(kNames[p], model, features, pose * part.pose * Eigen::Translation3d(box.min()));
    }
  }

  sensing::Scene scene_;
  kinematics::PoseUncertainty object_uncertainty_{};
  std::vector<std::unique_ptr<geometry::ObjectModel>> models_;  // stable addresses
  std::vector<std::unique_ptr<sensing::ObjectFeatures>> features_;
};

}  // namespace

VisionSetup::VisionSetup(const Scenario& scenario, std::string_view camera)
    : scenario_(&scenario),
      sensor_(&scenario.camera(camera)),
      features_(std::make_unique<std::vector<sensing::ObjectFeatures>>()),
      camera_(camera_of(*sensor_)) {
  for (const ObjectSpec& object : scenario.objects)
    features_->push_back(sensing::object_features(object.model));
  for (std::size_t o = 0; o < scenario.objects.size(); ++o) {
    const ObjectSpec& object = scenario.objects[o];
    scene_.add(object.name, object.model, (*features_)[o], object.initial_pose);
    uncertainty_.objects.push_back(object.uncertainty);
  }
  uncertainty_.camera = sensor_->uncertainty;
  uncertainty_.noise_px = sensor_->noise_px;
}

sensing::pseiki::MatchOptions VisionSetup::options() const {
  sensing::pseiki::MatchOptions options;
  options.detection_probability = sensor_->detection_probability;
  return options;
}

sensing::pseiki::OutputUnits VisionSetup::units() const {
  const Units& units = scenario_->units;
  return {.metres_per_length = units.metres_per_length_unit(),
          .radians_per_angle = units.radians_per_angle_unit(),
          .length = std::string(units.length_name()),
          .angle = std::string(units.angle_name())};
}

int VisionSetup::object_index(std::string_view name) const {
  const ObjectSpec& object = scenario_->object(name);  // throws naming the objects
  return static_cast<int>(&object - scenario_->objects.data());
}

VisionSetup::ChangedScene VisionSetup::changed_scene(const std::vector<std::string>& missing,
                                                     const std::vector<Swap>& swaps) const {
  std::vector<int> left_out;
  for (const std::string& name : missing) left_out.push_back(object_index(name));
  std::vector<int> replacement(scenario_->objects.size(), -1);
  for (const Swap& swap : swaps) {
    const int at = object_index(swap.name), other = object_index(swap.other);
    if (at == other)
      throw ScenarioError("swap " + swap.name + ":" + swap.other + ": an object with itself");
    replacement[static_cast<std::size_t>(at)] = other;
  }
  ChangedScene out;
  out.uncertainty.camera = uncertainty_.camera;
  out.uncertainty.noise_px = uncertainty_.noise_px;
  for (std::size_t o = 0; o < scenario_->objects.size(); ++o) {
    if (std::find(left_out.begin(), left_out.end(), static_cast<int>(o)) != left_out.end())
      continue;
    const ObjectSpec& object = scenario_->objects[o];
    const int other = replacement[o];
    if (other < 0) {
      out.scene.add(object.name, object.model, (*features_)[o], object.initial_pose);
    } else {
      const ObjectSpec& swapped = scenario_->objects[static_cast<std::size_t>(other)];
      out.scene.add(object.name + "~" + swapped.name, swapped.model,
                    (*features_)[static_cast<std::size_t>(other)], object.initial_pose);
    }
    out.uncertainty.objects.push_back(object.uncertainty);
  }
  return out;
}

namespace {

// The check of `object` by `sensor` (a fixed camera): the object's visible edges and the drawing.
VisionCheck check_with(const Scenario& scenario, const StepScene& step, const CameraSensor& sensor,
                       int object) {
  const sensing::pseiki::ModelPanel panel(step.scene(), camera_of(sensor),
                                          step.uncertainty(sensor));
  VisionCheck check{.camera = sensor.name,
                    .object = scenario.objects.at(static_cast<std::size_t>(object)).name,
                    .edges = {},
                    .acceptance = sensing::pseiki::MatchOptions{}.acceptance,
                    .width = sensor.intrinsics.width,
                    .height = sensor.intrinsics.height,
                    .drawing = {}};
  for (const sensing::pseiki::PanelEdge& edge : panel.edges()) {
    if (edge.pieces.empty()) continue;
    const std::string& body = step.scene().objects()[static_cast<std::size_t>(edge.object)].name;
    if (edge.object == 0) check.edges.push_back(edge.id);
    check.drawing.push_back({edge.id, body, edge.pieces});
  }
  return check;
}

// Whether the object's visible edges fix its pose in the image: at least three, two of them at
// least 20 degrees apart (their longest pieces' directions, as lines: 0 and 180 degrees agree).
bool fixes_pose(const VisionCheck& check) {
  constexpr double kMinAngle = 20.0 * units::kPi / 180.0;
  std::vector<double> angles;  // in [0, pi)
  for (const VisionEdge& edge : check.drawing) {
    if (edge.object != check.object || edge.pieces.empty()) continue;
    const auto longest =
        std::max_element(edge.pieces.begin(), edge.pieces.end(),
                         [](const auto& a, const auto& b) { return a.length() < b.length(); });
    const Eigen::Vector2d d = longest->p1 - longest->p0;
    if (d.squaredNorm() == 0) continue;
    angles.push_back(std::fmod(std::atan2(d.y(), d.x()) + units::kPi, units::kPi));
  }
  if (angles.size() < 3) return false;
  for (std::size_t i = 0; i < angles.size(); ++i)
    for (std::size_t j = i + 1; j < angles.size(); ++j) {
      const double apart = std::abs(angles[i] - angles[j]);
      if (std::min(apart, units::kPi - apart) >= kMinAngle) return true;
    }
  return false;
}

}  // namespace

std::optional<VisionCheck> vision_check(const Scenario& scenario, int object,
                                        const kinematics::Transform& pose,
                                        const VisionOccluders& occluders) {
  // PSEIKI needs a camera's world pose (above): a wrist camera cannot check.
  const auto fixed = [](const CameraSensor& sensor) {
    return sensor.mount != sensing::Mount::kWrist;
  };
  if (std::none_of(scenario.cameras.begin(), scenario.cameras.end(), fixed))
    return std::nullopt;  // no scene to build
  const StepScene step(scenario, object, pose, occluders);
  std::optional<VisionCheck> best;
  for (const CameraSensor& sensor : scenario.cameras) {
    if (!fixed(sensor)) continue;
    VisionCheck check = check_with(scenario, step, sensor, object);
    if (!check.edges.empty() && (!best || check.edges.size() > best->edges.size()))
      best = std::move(check);
  }
  return best;
}

std::vector<CameraVerification> verifying_cameras(const Scenario& scenario, int object,
                                                  const kinematics::Transform& pose,
                                                  const VisionOccluders& occluders, int camera) {
  std::vector<int> candidates;
  for (int c = 0; c < static_cast<int>(scenario.cameras.size()); ++c) {
    const CameraSensor& sensor = scenario.cameras[static_cast<std::size_t>(c)];
    if ((camera < 0 || c == camera) && sensor.mount != sensing::Mount::kWrist && sensor.residual)
      candidates.push_back(c);
  }
  std::vector<CameraVerification> out;
  if (candidates.empty()) return out;  // no scene to build
  const StepScene step(scenario, object, pose, occluders);
  for (const int c : candidates) {
    VisionCheck check =
        check_with(scenario, step, scenario.cameras[static_cast<std::size_t>(c)], object);
    if (fixes_pose(check)) out.push_back({c, std::move(check)});
  }
  return out;
}

}  // namespace spar::planner
