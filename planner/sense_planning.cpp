#include "spar/planner/sense_planning.hpp"

#include <algorithm>

#include "spar/planner/error.hpp"
#include "spar/sensing/evidence.hpp"

namespace spar::planner {
namespace {

// The object's bounding radius (metres), for the match tolerances.
double bounding_radius(const geometry::ObjectModel& model) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& vertex : model.mesh().vertices) box.extend(vertex);
  return box.diagonal().norm() / 2;
}

}  // namespace

std::vector<sensing::SensorModel> scenario_sensors(const Scenario& scenario) {
  std::vector<sensing::SensorModel> out;
  if (scenario.range_scan) out.push_back(scenario.range_scan->model);
  for (const CameraSensor& camera : scenario.cameras) out.push_back(camera.sensor_model());
  return out;
}

SensingContext::SensingContext(const Scenario& scenario, const WorldModel& world)
    : scenario_(scenario), world_(world), sensors_(scenario_sensors(scenario)) {
  for (const ObjectSpec& object : scenario.objects) {
    std::vector<const geometry::ObjectModel*> models;
    if (object.identities.empty()) {
      models.push_back(&object.model);
    } else {
      for (const ObjectIdentity& identity : object.identities) models.push_back(&identity.model);
    }
    std::vector<std::size_t> indices;
    for (const geometry::ObjectModel* model : models) {
      Shape& shape = shapes_.emplace_back();
      shape.model = model;
      shape.features = sensing::object_features(*model);
      if (object.uncertain()) shape.aspects = sensing::compute_aspects(*model);
      indices.push_back(shapes_.size() - 1);
    }
    shape_of_.push_back(std::move(indices));
  }
}

const SensingContext::Shape& SensingContext::shape(std::size_t object, int identity) const {
  return shapes_[shape_of_.at(object).at(static_cast<std::size_t>(identity))];
}

const sensing::AspectSet& SensingContext::aspects(std::size_t object, int identity) const {
  return shape(object, identity).aspects;
}

sensing::SelectionProblem SensingContext::problem(std::size_t index) const {
  const ObjectSpec& target = scenario_.objects.at(index);
  if (!target.uncertain())
    throw ScenarioError("object '" + target.name + "' is certain: nothing to disambiguate");
  if (sensors_.empty())
    throw ScenarioError(target.location.str() + ": object '" + target.name + "' is uncertain (" +
                        std::to_string(target.hypotheses.size()) +
                        " hypotheses) but the scenario has no sensor to look at it: add "
                        "sensors.range_scan or sensors.cameras");
  sensing::SelectionProblem problem;
  problem.sensors = sensors_;
  for (const ObjectHypothesis& hypothesis : target.hypotheses) {
    sensing::HypothesisWorld world;
    world.label = hypothesis.label;
    for (std::size_t o = 0; o < scenario_.objects.size(); ++o) {
      const ObjectSpec& object = scenario_.objects[o];
      // The target as this hypothesis has it; other uncertain objects as their first hypothesis.
      const ObjectHypothesis* as = o == index           ? &hypothesis
                                   : object.uncertain() ? &object.hypotheses.front()
                                                        : nullptr;
      const Shape& model = shape(o, as ? as->identity : 0);
      const int added = world.scene.add(object.name, *model.model, model.features,
                                        as ? as->pose : object.initial_pose);
      if (o == index) {
        world.target = added;
        world.aspects = &model.aspects;
      }
    }
    problem.hypotheses.push_back(std::move(world));
  }
  // Tolerances: the sensor's noise and the object's pose uncertainty, seen from the standoff
  // (wrist) or from where the sensor is (fixed).
  double radius = 0;
  if (target.identities.empty()) {
    radius = bounding_radius(target.model);
  } else {
    for (const ObjectIdentity& identity : target.identities)
      radius = std::max(radius, bounding_radius(identity.model));
  }
  const Eigen::Vector3d centre = target.initial_pose.translation();
  for (const sensing::SensorModel& sensor : sensors_) {
    const double distance = sensor.mount == sensing::Mount::kWrist
                                ? scenario_.sensing.standoff
                                : (sensor.pose.translation() - centre).norm();
    const kinematics::PoseUncertainty& u = target.uncertainty;
    problem.tolerances.push_back(
        sensing::match_tolerances(sensor, u.dx, u.dy, u.dz, u.dtheta, radius, distance));
  }
  // Vacuous over the identities, refined to the hypotheses.
  const int identities = std::max<int>(1, static_cast<int>(target.identities.size()));
  const int count = static_cast<int>(target.hypotheses.size());
  std::vector<sensing::FocalSet> refining(static_cast<std::size_t>(identities),
                                          sensing::FocalSet(count));
  for (int h = 0; h < count; ++h)
    refining[static_cast<std::size_t>(target.hypotheses[static_cast<std::size_t>(h)].identity)]
        .insert(h);
  // An identity without a hypothesis (none of its stable poses was listed) drops out.
  refining.erase(std::remove_if(refining.begin(), refining.end(),
                                [](const sensing::FocalSet& set) { return set.empty(); }),
                 refining.end());
  problem.prior =
      sensing::refine(sensing::MassFunction::vacuous(static_cast<int>(refining.size())), refining);
  return problem;
}

sensing::SelectionOptions SensingContext::options() const {
  sensing::SelectionOptions options;
  options.ambiguity_threshold = scenario_.sensing.ambiguity_threshold;
  options.max_operations = scenario_.sensing.max_operations;
  options.standoff = scenario_.sensing.standoff;
  const std::vector<sensing::SensorModel>& sensors = sensors_;
  const WorldModel& world = world_;
  options.reachable = [&sensors, &world, start = world.initial_state()](
                          int sensor, const Eigen::Isometry3d& sensor_pose) {
    // The gripper frame that puts the sensor there: sensor = gripper * mount; the arm and the
    // gripper must clear the objects where they start, and the table.
    const Eigen::Isometry3d gripper =
        sensor_pose * sensors[static_cast<std::size_t>(sensor)].pose.inverse(Eigen::Isometry);
    return world.still_branch(start, gripper).has_value();
  };
  return options;
}

SensePlan plan_sensing(const Scenario& scenario, const WorldModel& world) {
  const SensingContext context(scenario, world);
  SensePlan out;
  for (std::size_t index = 0; index < scenario.objects.size(); ++index) {
    const ObjectSpec& object = scenario.objects[index];
    if (!object.uncertain()) continue;
    const sensing::SelectionProblem problem = context.problem(index);
    ObjectSensePlan plan;
    plan.object = object.name;
    plan.threshold = scenario.sensing.ambiguity_threshold;
    for (const ObjectHypothesis& hypothesis : object.hypotheses) {
      plan.hypotheses.push_back(hypothesis.label);
      plan.hypothesis_identity.push_back(hypothesis.identity);
    }
    if (object.identities.empty()) {
      plan.identities.push_back(object.name);
      plan.identity_aspects.push_back(context.aspects(index, 0));
    } else {
      for (std::size_t i = 0; i < object.identities.size(); ++i) {
        plan.identities.push_back(object.identities[i].name);
        plan.identity_aspects.push_back(context.aspects(index, static_cast<int>(i)));
      }
    }
    for (const sensing::SensorModel& sensor : problem.sensors) plan.sensors.push_back(sensor.name);
    plan.beliefs_before = problem.prior.pignistic();
    plan.selection = sensing::select_operations(problem, context.options());
    for (const sensing::CandidateOperation& candidate : plan.selection.candidates) {
      std::vector<std::string> labels;
      for (std::size_t h = 0; h < candidate.viewpoint.aspects.size(); ++h) {
        const int aspect = candidate.viewpoint.aspects[h];
        const sensing::AspectSet& set =
            plan.identity_aspects[static_cast<std::size_t>(plan.hypothesis_identity[h])];
        labels.push_back(aspect < 0 ? "" : set.aspects[static_cast<std::size_t>(aspect)].label);
      }
      plan.candidate_aspects.push_back(std::move(labels));
    }
    out.objects.push_back(std::move(plan));
  }
  return out;
}

}  // namespace spar::planner
