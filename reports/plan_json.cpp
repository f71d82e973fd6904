#include "reports/plan_json.hpp"

#include "reports/json_values.hpp"

namespace spar::reports {
namespace {

using nlohmann::ordered_json;
using planner::ParameterType;

const char* type_name(ParameterType type) {
  switch (type) {
    case ParameterType::kObject:
      return "object";
    case ParameterType::kGrasp:
      return "grasp";
    case ParameterType::kPosition:
      return "position";
    case ParameterType::kPlacement:
      return "placement";
  }
  return "?";
}

// The name of label `label` of plan variable `variable`.
std::string label_name(const planner::PlanResult& result, int variable, int label) {
  const planner::PlanVariable& meta = result.family.variables.at(variable);
  const planner::ObjectWorld& object = result.world.object(meta.object);
  return meta.type == ParameterType::kGrasp ? object.grasps.at(label).label
                                            : object.positions.at(label).name;
}

ordered_json family_json(const planner::PlanResult& result) {
  const planner::PlanFamily& family = result.family;
  ordered_json steps = ordered_json::array();
  for (const planner::FamilyStep& step : family.steps) {
    ordered_json args = ordered_json::array();
    for (const planner::Term& term : step.args) args.push_back(family.term_name(term, result.world));
    steps.push_back({{"id", step.id},
                     {"action", step.action < 0 ? (step.id == 0 ? "start" : "finish")
                                                : result.domain.actions[step.action].name},
                     {"args", args},
                     {"text", family.describe(step, result.world, result.domain)}});
  }
  ordered_json ordering = ordered_json::array();
  for (const auto& [before, after] : family.ordering.transitive_reduction())
    ordering.push_back({before, after});
  ordered_json variables = ordered_json::array();
  for (int v = 0; v < family.network.variable_count(); ++v) {
    if (family.network.representative(v) != v) continue;
    ordered_json labels = ordered_json::array();
    for (const int label : family.network.labels(v)) labels.push_back(label_name(result, v, label));
    const planner::PlanVariable& meta = family.variables[v];
    variables.push_back({{"name", meta.name},
                         {"type", type_name(meta.type)},
                         {"object", result.world.scenario().objects[meta.object].name},
                         {"labels", labels}});
  }
  ordered_json arcs = ordered_json::array();
  for (const planner::cms::ArcPairs& arc : family.network.arcs()) {
    ordered_json pairs = ordered_json::array();
    for (const auto& [a, b] : arc.pairs)
      pairs.push_back({label_name(result, arc.first, a), label_name(result, arc.second, b)});
    arcs.push_back({{"variables",
                     {family.variables[arc.first].name, family.variables[arc.second].name}},
                    {"pairs", pairs}});
  }
  ordered_json goals = ordered_json::array();
  for (const planner::SatisfiedGoal& goal : family.satisfied)
    goals.push_back(
        {{"level", goal.level == planner::SatisfiedGoal::Level::kOperational ? "operational"
                                                                              : "geometric"},
         {"condition", goal.condition},
         {"step", goal.step},
         {"how", goal.how}});
  return {{"steps", steps},
          {"ordering", ordering},
          {"variables", variables},
          {"arcs", arcs},
          {"goals", goals},
          {"search",
           {{"expanded", family.stats.expanded},
            {"generated", family.stats.generated},
            {"seconds", family.stats.seconds}}}};
}

ordered_json step_json(const planner::PlanResult& result, const planner::InstanceStep& step) {
  const planner::Scenario& scenario = result.world.scenario();
  const double scale = 1.0 / scenario.units.metres_per_length_unit();
  ordered_json out = {{"id", step.step},
                      {"action", step.action_name},
                      {"object", step.object >= 0 ? ordered_json(scenario.objects[step.object].name)
                                                  : ordered_json(nullptr)}};
  if (step.grasp >= 0) {
    const geometry::Grasp& grasp = result.world.object(step.object).grasps[step.grasp];
    out["grasp"] = {{"label", grasp.label},
                    {"faces", {grasp.face_plus_y, grasp.face_minus_y}},
                    {"width", grasp.width * scale},
                    {"gripper_in_object", matrix_json(grasp.gripper_in_object, scale)}};
  }
  if (step.position >= 0) {
    out["object_pose"] = matrix_json(step.object_pose, scale);
    const auto& poses = scenario.objects[step.object].stable_poses;
    out["stable_pose"] = step.stable_pose >= 0 && !step.is_assembly()
                             ? ordered_json(poses[step.stable_pose].label)
                             : ordered_json(nullptr);
  }
  if (step.grasp >= 0) {
    out["gripper_pose"] = matrix_json(step.gripper_pose, scale);
    if (step.reach.solution) {
      ordered_json joints = ordered_json::array();
      for (int j = 0; j < 6; ++j) joints.push_back(step.reach.solution->q[j]);
      out["joints"] = joints;
      out["configuration"] = step.reach.solution->configuration.label();
    } else {
      out["joints"] = nullptr;
      out["configuration"] = nullptr;
    }
  }
  if (step.is_assembly()) {
    out["fixed_object"] = scenario.objects[step.fixed_object].name;
    out["fixed_pose"] = matrix_json(step.fixed_pose, scale);
    out["held_pose"] = matrix_json(step.held_pose, scale);
  }
  return out;
}

}  // namespace

ordered_json plan_json(const planner::PlanResult& result) {
  const planner::Scenario& scenario = result.world.scenario();
  const double scale = 1.0 / scenario.units.metres_per_length_unit();
  ordered_json out;
  out["scenario"] = scenario.name;
  out["status"] = result.planned() ? "planned" : "no_plan";
  if (!result.planned())
    out["reason"] = std::string(to_string(result.family.status)) + ": " + result.family.reason;
  out["units"] = {{"length", scenario.units.length_name()}, {"angle", scenario.units.angle_name()}};
  out["robot"] = {{"model", scenario.robot.model},
                  {"base", matrix_json(scenario.robot.base, scale)},
                  {"tool", matrix_json(scenario.robot.tool, scale)}};
  out["family"] = family_json(result);
  out["instances"] = {{"count", result.instances.instances.size()},
                      {"limit_reached", result.instances.limit_reached}};
  if (result.planned() && !result.instances.instances.empty()) {
    ordered_json steps = ordered_json::array();
    for (const planner::InstanceStep& step : result.chosen().steps)
      steps.push_back(step_json(result, step));
    out["chosen"] = {{"index", result.chosen_index}, {"steps", steps}};
  } else {
    out["chosen"] = nullptr;
  }
  return out;
}

}  // namespace spar::reports
