#include "spar/planner/vision.hpp"

#include <algorithm>

#include "spar/planner/error.hpp"

namespace spar::planner {
namespace {

sensing::Camera camera_of(const CameraSensor& sensor) {
  return sensing::Camera(sensor.projection, sensor.intrinsics, sensor.pose);
}

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

std::optional<VisionCheck> vision_check(const Scenario& scenario, int object,
                                        const kinematics::Transform& pose) {
  const ObjectSpec& spec = scenario.objects.at(static_cast<std::size_t>(object));
  const sensing::ObjectFeatures features = sensing::object_features(spec.model);
  sensing::Scene scene;
  scene.add(spec.name, spec.model, features, pose);
  std::optional<VisionCheck> best;
  for (const CameraSensor& sensor : scenario.cameras) {
    const sensing::pseiki::ExpectationUncertainty uncertainty{
        .objects = {spec.uncertainty}, .camera = sensor.uncertainty, .noise_px = sensor.noise_px};
    const sensing::pseiki::ModelPanel panel(scene, camera_of(sensor), uncertainty);
    VisionCheck check{sensor.name, spec.name, {}, sensing::pseiki::MatchOptions{}.acceptance};
    for (const sensing::pseiki::PanelEdge& edge : panel.edges())
      if (!edge.pieces.empty()) check.edges.push_back(edge.id);
    if (!check.edges.empty() && (!best || check.edges.size() > best->edges.size()))
      best = std::move(check);
  }
  return best;
}

}  // namespace spar::planner
