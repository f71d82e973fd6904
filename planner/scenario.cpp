#include "spar/planner/scenario.hpp"

#include "spar/common/input_file.hpp"
#include "spar/common/units.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/internal/scenario_yaml.hpp"

namespace spar::planner {

double Units::metres_per_length_unit() const {
  switch (length) {
    case LengthUnit::kMetre:
      return units::kMetre;
    case LengthUnit::kMillimetre:
      return units::kMillimetre;
    case LengthUnit::kInch:
      return units::kInch;
  }
  return units::kMetre;
}

double Units::radians_per_angle_unit() const {
  return angle == AngleUnit::kDegree ? units::kDegree : units::kRadian;
}

const char* to_string(Distribution distribution) {
  return distribution == Distribution::kGaussian ? "gaussian" : "uniform";
}

std::string_view Units::length_name() const {
  switch (length) {
    case LengthUnit::kMetre:
      return "m";
    case LengthUnit::kMillimetre:
      return "mm";
    case LengthUnit::kInch:
      return "in";
  }
  return "m";
}

std::string_view Units::angle_name() const { return angle == AngleUnit::kDegree ? "deg" : "rad"; }

std::string SourceLocation::str() const {
  if (line <= 0) return file;
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

const ObjectSpec& Scenario::object(std::string_view name) const {
  for (const ObjectSpec& object : objects)
    if (object.name == name) return object;
  std::string known;
  for (const ObjectSpec& object : objects) known += (known.empty() ? "" : ", ") + object.name;
  throw ScenarioError("scenario '" + this->name + "' has no object '" + std::string(name) +
                      "' (objects: " + (known.empty() ? "none" : known) + ")");
}

Scenario Scenario::resolved(std::string_view name, std::size_t hypothesis) const {
  Scenario out = *this;
  for (ObjectSpec& object : out.objects) {
    if (object.name != name) continue;
    if (hypothesis >= object.hypotheses.size())
      throw ScenarioError("object '" + object.name + "' has no hypothesis " +
                          std::to_string(hypothesis) + " (it has " +
                          std::to_string(object.hypotheses.size()) + ")");
    const ObjectHypothesis chosen = object.hypotheses[hypothesis];
    if (!object.identities.empty()) {
      const ObjectIdentity& identity = object.identities[static_cast<std::size_t>(chosen.identity)];
      object.shape = identity.shape;
      object.model = identity.model;
      object.stable_poses = identity.stable_poses;
    }
    object.initial_pose = chosen.pose;
    object.initial_stable_pose = chosen.stable_pose;
    object.identities.clear();
    object.hypotheses.clear();
    return out;
  }
  (void)object(name);  // throws, naming the objects
  return out;
}

sensing::SensorModel CameraSensor::sensor_model() const {
  sensing::SensorModel out;
  out.name = name;
  out.kind = sensing::SensorKind::kCamera;
  out.projection = projection;
  out.intrinsics = intrinsics;
  out.pose = pose;
  out.mount = mount;
  out.noise_px = noise_px;
  out.detection_probability = detection_probability;
  return out;
}

int Scenario::place_index(std::string_view name) const {
  for (std::size_t p = 0; p < places.size(); ++p)
    if (places[p].name == name) return static_cast<int>(p);
  return -1;
}

kinematics::Transform place_pose(const Place& place, double yaw,
                                 const kinematics::Transform& resting) {
  return Eigen::Translation3d(place.x, place.y, 0.0) *
         Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * resting;
}

std::optional<std::size_t> resting_yaw(const ObjectSpec& object, const Place& place) {
  if (!object.initial_stable_pose) return std::nullopt;
  const geometry::StablePose& stable = object.stable_poses[*object.initial_stable_pose];
  for (std::size_t k = 0; k < place.yaws.size(); ++k)
    if ((place_pose(place, place.yaws[k], stable.object_to_world).matrix() -
         object.initial_pose.matrix())
            .cwiseAbs()
            .maxCoeff() <= 1e-7)
      return k;
  return std::nullopt;
}

std::string describe(const Goal& goal) {
  if (const auto* assembled = std::get_if<AssembledGoal>(&goal))
    return "assembled(" + assembled->held + ", " + assembled->fixed + ")";
  const AtGoal& at = std::get<AtGoal>(goal);
  return "at(" + at.object + ", " + at.place + ")";
}

const SourceLocation& location(const Goal& goal) {
  return std::visit([](const auto& g) -> const SourceLocation& { return g.location; }, goal);
}

const CameraSensor& Scenario::camera(std::string_view name) const {
  for (const CameraSensor& camera : cameras)
    if (camera.name == name) return camera;
  std::string known;
  for (const CameraSensor& camera : cameras) known += (known.empty() ? "" : ", ") + camera.name;
  throw ScenarioError("scenario '" + this->name + "' has no camera '" + std::string(name) +
                      "' (cameras: " + (known.empty() ? "none" : known) + ")");
}

Scenario load_scenario(const std::filesystem::path& path) {
  std::string text;
  try {
    text = read_input_file(path, "scenario file", kMaxYamlFileBytes);
  } catch (const InputError& error) {
    throw ScenarioError(error.what());
  }
  Scenario scenario = parse_scenario(text, path.string(), path.parent_path());
  scenario.path = path;
  return scenario;
}

Scenario parse_scenario(std::string_view text, const std::string& source,
                        const std::filesystem::path& base_dir) {
  return internal::read_scenario_yaml(text, source, base_dir);
}

}  // namespace spar::planner
