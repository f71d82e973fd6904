#include "spar/reports/plan_json.hpp"

#include <algorithm>
#include <tuple>

#include "spar/reports/json_values.hpp"

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
    for (const planner::Term& term : step.args)
      args.push_back(family.term_name(term, result.world));
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
    arcs.push_back(
        {{"variables", {family.variables[arc.first].name, family.variables[arc.second].name}},
         {"pairs", pairs}});
  }
  ordered_json goals = ordered_json::array();
  for (const planner::SatisfiedGoal& goal : family.satisfied)
    goals.push_back(
        {{"level",
          goal.level == planner::SatisfiedGoal::Level::kOperational ? "operational" : "geometric"},
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
  // Issue 21 (normative): the step's clearance in metres and what it carries.
  out["clearance"] =
      step.grasp < 0 ? ordered_json(nullptr)
                     : ordered_json{{"min_distance", number_json(step.collision.clearance)},
                                    {"to", step.collision.nearest >= 0
                                               ? ordered_json(scenario.objects[step.collision.nearest].name)
                                               : ordered_json(nullptr)}};
  ordered_json carried = ordered_json::array();
  for (const int part : step.carried) carried.push_back(scenario.objects[part].name);
  out["carried"] = carried;
  return out;
}

// The SI unit of a precondition's expression: SPAR's pickup inequalities and the insertion
// offsets are lengths; the misalignment condition compares cosines (dimensionless).
const char* precondition_unit(const planner::PreconditionResult& result) {
  return result.length ? "m" : "1";
}

ordered_json precondition_json(const planner::Scenario& scenario,
                               const planner::PreconditionResult& result,
                               const std::vector<planner::SpaceVariable>& space) {
  ordered_json witness = ordered_json::object();
  for (std::size_t v = 0; v < result.witness.size() && v < result.variables.size(); ++v)
    witness[result.variables[v]] = number_json(result.witness[v]);
  ordered_json box = ordered_json::object();
  for (std::size_t v = 0; v < result.variables.size(); ++v)
    box[result.variables[v]] = {number_json(result.box[v].lo), number_json(result.box[v].hi)};
  const std::string unit = precondition_unit(result);
  const double scale = unit == "m" ? 1.0 / scenario.units.metres_per_length_unit() : 1.0;
  const auto shown = [&](double value) { return number_json(value * scale); };
  ordered_json out = {{"name", result.inequality.name},
                      {"kind", result.kind},
                      {"relation", bounds::to_string(result.inequality.relation)},
                      {"threshold", number_json(result.inequality.threshold)},
                      {"unit", unit},
                      {"expression", result.expression},
                      {"nodes", result.nodes},
                      {"lo", number_json(result.bound.lo)},
                      {"hi", number_json(result.bound.hi)},
                      {"inner_lo", number_json(result.bound.inner_lo)},
                      {"inner_hi", number_json(result.bound.inner_hi)},
                      {"verdict", bounds::to_string(result.verdict)},
                      {"witness", witness},
                      {"box", box},
                      {"display",
                       {{"unit", unit == "m" ? std::string(scenario.units.length_name()) : unit},
                        {"threshold", shown(result.inequality.threshold)},
                        {"lo", shown(result.bound.lo)},
                        {"hi", shown(result.bound.hi)},
                        {"inner_lo", shown(result.bound.inner_lo)},
                        {"inner_hi", shown(result.bound.inner_hi)}}}};
  if (!result.blame.empty()) {
    ordered_json blame = ordered_json::array();
    for (const auto& entry : result.blame)
      blame.push_back({{"variable", entry.variable}, {"share", number_json(entry.share)}});
    out["blame"] = blame;
  }
  if (result.holds_up_to_scale) {
    // The scaled uncertainty as half-widths: the widest scaled displacement and rotation among
    // the variables reverse analysis scales (the objects' initial and sensed ones).
    const double s = *result.holds_up_to_scale;
    double displacement = 0.0, rotation = 0.0;
    for (std::size_t v = 0; v < result.variables.size(); ++v) {
      const auto found = std::find_if(space.begin(), space.end(), [&](const auto& variable) {
        return variable.name == result.variables[v];
      });
      if (found == space.end() ||
          found->provenance.source == planner::UncertaintySource::kManipulator)
        continue;
      const double half_width = std::max(-result.box[v].lo, result.box[v].hi) * s;
      double& widest = found->component == 't' ? rotation : displacement;
      widest = std::max(widest, half_width);
    }
    out["holds_up_to_scale"] = number_json(s);
    out["margin"] = {{"displacement", number_json(scenario.units.to_file_length(displacement))},
                     {"rotation", number_json(scenario.units.to_file_angle(rotation))}};
  }
  if (result.monte_carlo_violation)
    out["monte_carlo_violation"] = number_json(*result.monte_carlo_violation);
  return out;
}

ordered_json verification_json(const std::vector<planner::VerificationPlan>& plans,
                               ordered_json& recovery) {
  ordered_json verification = ordered_json::array();
  for (const planner::VerificationPlan& plan : plans) {
    ordered_json outcomes = ordered_json::array();
    for (const auto& outcome : plan.outcomes) {
      outcomes.push_back(
          {{"when", outcome.when}, {"error", outcome.error}, {"recovery", outcome.recovery}});
      recovery.push_back({{"error", outcome.error},
                          {"plan", outcome.recovery},
                          {"steps", outcome.recovery_steps}});
    }
    verification.push_back({{"name", plan.name},
                            {"sense", plan.sense},
                            {"expect", plan.expect},
                            {"outcomes", outcomes}});
  }
  return verification;
}

// A step phase 2 inserted (range-scan, squeeze): what the instance step would say.
planner::InstanceStep inserted_step(const planner::PlanResult& result,
                                    const planner::AnalysedStep& analysed) {
  planner::InstanceStep step;
  step.step = -1;
  step.action = analysed.step.action;
  step.action_name = analysed.action;
  step.object = analysed.step.object;
  step.grasp = analysed.step.grasp;
  step.object_pose = analysed.step.object_pose;
  step.position = 0;
  if (step.grasp >= 0) {
    step.gripper_pose =
        step.object_pose * result.world.object(step.object).grasps[step.grasp].gripper_in_object;
    step.reach = result.world.reach(step.gripper_pose);
  }
  return step;
}

ordered_json chosen_steps_json(const planner::PlanResult& result) {
  const planner::PlanInstance& instance = result.chosen();
  const planner::InstanceAnalysis* analysis = result.chosen_analysis();
  ordered_json steps = ordered_json::array();
  if (analysis == nullptr) {
    for (const planner::InstanceStep& step : instance.steps)
      steps.push_back(step_json(result, step));
    return steps;
  }
  int next_id = static_cast<int>(result.family.steps.size());
  for (std::size_t k = 0; k < analysis->steps.size(); ++k) {
    const planner::AnalysedStep& analysed = analysis->steps[k];
    ordered_json out;
    if (analysed.inserted) {
      planner::InstanceStep step = inserted_step(result, analysed);
      std::tie(step.collision, step.carried) = result.chosen_checks.at(k);
      out = step_json(result, step);
      out["id"] = next_id++;
      out["stable_pose"] = nullptr;
    } else {
      out = step_json(result, instance.steps[analysed.step.instance_step]);
    }
    out["inserted"] = analysed.inserted;
    if (analysed.step.grasp >= 0 && (analysed.step.effect == planner::StepEffect::kGrasp ||
                                     analysed.step.effect == planner::StepEffect::kSqueeze))
      out["finger_opening"] = result.world.gripper().max_opening /
                              result.world.scenario().units.metres_per_length_unit();
    ordered_json preconditions = ordered_json::array();
    for (const planner::PreconditionResult& precondition : analysed.preconditions)
      preconditions.push_back(
          precondition_json(result.world.scenario(), precondition, analysis->variables));
    out["preconditions"] = preconditions;
    out["failed"] = analysed.failed;
    if (analysed.sensor_scale_needed && result.world.scenario().range_scan) {
      // The range-scan residual (scenario units) that would make this failed step hold.
      const planner::Units& units = result.world.scenario().units;
      const kinematics::PoseUncertainty& r = result.world.scenario().range_scan->residual;
      const double f = *analysed.sensor_scale_needed;
      out["sensor_residual_needed"] = {{"scale", f},
                                       {"dx", units.to_file_length(r.dx * f)},
                                       {"dy", units.to_file_length(r.dy * f)},
                                       {"dz", units.to_file_length(r.dz * f)},
                                       {"dtheta", units.to_file_angle(r.dtheta * f)}};
    }
    if (analysed.failed) {
      ordered_json recovery = ordered_json::array();
      out["verification"] = verification_json(analysed.verification, recovery);
      out["recovery"] = recovery;
    }
    steps.push_back(std::move(out));
  }
  return steps;
}

ordered_json repairs_json(const planner::PlanResult& result,
                          const planner::InstanceAnalysis& analysis) {
  ordered_json repairs = ordered_json::array();
  for (const planner::RepairAttempt& attempt : analysis.repairs) {
    // The failing step's preconditions, in the order of `before` and `after`.
    const auto failing =
        std::find_if(analysis.steps.begin(), analysis.steps.end(), [&](const auto& step) {
          return !step.inserted && step.step.instance_step == attempt.for_instance_step;
        });
    const auto bounds_json = [&](const std::vector<bounds::BoundResult>& bounds,
                                 const std::vector<bounds::Verdict>& verdicts) {
      ordered_json out = ordered_json::array();
      for (std::size_t i = 0; i < bounds.size(); ++i) {
        const bool named = failing != analysis.steps.end() && i < failing->preconditions.size();
        out.push_back({{"name", named ? ordered_json(failing->preconditions[i].inequality.name)
                                      : ordered_json(nullptr)},
                       {"unit", named ? ordered_json(precondition_unit(failing->preconditions[i]))
                                      : ordered_json(nullptr)},
                       {"lo", number_json(bounds[i].lo)},
                       {"hi", number_json(bounds[i].hi)},
                       {"verdict", bounds::to_string(verdicts[i])}});
      }
      return out;
    };
    const ordered_json before = bounds_json(attempt.before, attempt.verdicts_before);
    const ordered_json after = bounds_json(attempt.after, attempt.verdicts_after);
    repairs.push_back({{"action", attempt.action},
                       {"object", result.world.scenario().objects.at(attempt.object).name},
                       {"for_step", result.chosen().steps.at(attempt.for_instance_step).step},
                       {"helped", attempt.helped},
                       {"before", before},
                       {"after", after}});
  }
  return repairs;
}

// A variable's range in the scenario's units.
ordered_json display_range(const planner::Units& units, const planner::SpaceVariable& variable) {
  const bool angle = variable.component == 't';
  const auto convert = [&](double value) {
    return number_json(angle ? units.to_file_angle(value) : units.to_file_length(value));
  };
  return {{"unit", angle ? units.angle_name() : units.length_name()},
          {"lo", convert(variable.lower)},
          {"hi", convert(variable.upper)}};
}

ordered_json variables_json(const planner::PlanResult& result,
                            const planner::InstanceAnalysis& analysis) {
  ordered_json variables = ordered_json::array();
  for (const planner::SpaceVariable& v : analysis.variables)
    variables.push_back(
        {{"name", v.name},
         {"lo", number_json(v.lower)},
         {"hi", number_json(v.upper)},
         {"unit", v.component == 't' ? "rad" : "m"},
         {"source", planner::to_string(v.provenance.source)},
         {"object", v.provenance.object >= 0
                        ? ordered_json(result.world.scenario().objects[v.provenance.object].name)
                        : ordered_json(nullptr)},
         {"step", v.provenance.step >= 0 ? ordered_json(v.provenance.step) : ordered_json(nullptr)},
         {"display", display_range(result.world.scenario().units, v)}});
  return variables;
}

ordered_json examined_json(const planner::InstanceAnalysis& analysis) {
  const auto count = [&](auto predicate) {
    return std::count_if(analysis.steps.begin(), analysis.steps.end(), predicate);
  };
  std::size_t preconditions = 0, failed = 0;
  for (const planner::AnalysedStep& step : analysis.steps)
    for (const planner::PreconditionResult& precondition : step.preconditions) {
      ++preconditions;
      failed += precondition.verdict == bounds::Verdict::kSatisfied ? 0 : 1;
    }
  return {{"index", analysis.instance},
          {"errors", analysis.errors},
          {"steps", analysis.steps.size()},
          {"inserted", count([](const auto& step) { return step.inserted; })},
          {"preconditions", preconditions},
          {"failed_preconditions", failed}};
}

// ---- probability (issue 15): the chosen instance's probabilistic analysis and tolerance
// allocation (planner/uncertainty/probability.hpp), in one block `chosen.probability` ----

ordered_json probability_json(const planner::PlanResult& result,
                              const planner::InstanceAnalysis& analysis) {
  const planner::ProbabilityAnalysis& p = *result.probability;
  const planner::ToleranceAllocation& t = *result.tolerances;
  const planner::Units& units = result.world.scenario().units;
  ordered_json preconditions = ordered_json::array();
  for (const planner::PreconditionProbability& q : p.preconditions) {
    const auto miss = std::find_if(t.misses.begin(), t.misses.end(), [&](const auto& m) {
      return m.step == q.step && m.precondition == q.precondition;
    });
    preconditions.push_back(
        {{"step", q.step},
         {"index", q.precondition},
         {"name", analysis.steps[q.step].preconditions[q.precondition].inequality.name},
         {"nominal", number_json(q.nominal)},
         {"mean", number_json(q.mean)},
         {"second_order_mean", number_json(q.second_order_mean)},
         {"sigma", number_json(q.sigma)},
         {"p_first_order", number_json(q.p_first_order)},
         {"p_second_order", number_json(q.p_second_order)},
         {"p_monte_carlo", number_json(q.p_monte_carlo)},
         {"ci", {number_json(q.ci_lo), number_json(q.ci_hi)}},
         {"violations", q.violations},
         {"proved", q.proved},
         {"agrees", q.agrees},
         {"note", q.note},
         {"allocation_miss",
          miss == t.misses.end() ? ordered_json(nullptr) : number_json(miss->by)}});
  }
  ordered_json parameters = ordered_json::array();
  for (const planner::ToleranceParameter& q : t.parameters) {
    const bool angle = q.component == 't';
    const auto shown = [&](double value) {
      return number_json(angle ? units.to_file_angle(value) : units.to_file_length(value));
    };
    parameters.push_back({{"name", q.name},
                          {"source", planner::to_string(q.source)},
                          {"unit", angle ? "rad" : "m"},
                          {"half_width", number_json(q.half_width)},
                          {"allocated", number_json(q.allocated)},
                          {"cost", number_json(q.cost)},
                          {"display",
                           {{"unit", angle ? units.angle_name() : units.length_name()},
                            {"half_width", shown(q.half_width)},
                            {"allocated", shown(q.allocated)}}}});
  }
  return {{"jacobian",
           {{"rows", p.rows},
            {"cols", p.cols},
            {"nonzeros", p.nonzeros},
            {"density", number_json(p.density)},
            {"covariance_nonzeros", p.covariance_nonzeros},
            {"non_differentiable", p.non_differentiable}}},
          {"samples", p.samples},
          {"plan",
           {{"p_monte_carlo", number_json(p.p_plan)},
            {"ci", {number_json(p.p_plan_ci_lo), number_json(p.p_plan_ci_hi)}}}},
          {"preconditions", preconditions},
          {"tolerances",
           {{"status", planner::to_string(t.status)},
            {"cost", number_json(t.cost)},
            {"rounds", t.rounds},
            {"parameters", parameters}}}};
}

}  // namespace

ordered_json plan_json(const planner::PlanResult& result) {
  const planner::Scenario& scenario = result.world.scenario();
  const double scale = 1.0 / scenario.units.metres_per_length_unit();
  ordered_json out;
  out["schema"] = kReportSchema;
  out["scenario"] = scenario.name;
  out["description"] = scenario.description;
  out["status"] = result.planned() ? "planned" : "no_plan";
  if (!result.planned())
    out["reason"] = std::string(to_string(result.family.status)) + ": " + result.family.reason;
  out["units"] = {{"length", scenario.units.length_name()},
                  {"angle", scenario.units.angle_name()},
                  {"metres_per_length", scenario.units.metres_per_length_unit()},
                  {"radians_per_angle", scenario.units.radians_per_angle_unit()}};
  out["robot"] = {{"model", scenario.robot.model},
                  {"base", matrix_json(scenario.robot.base, scale)},
                  {"tool", matrix_json(scenario.robot.tool, scale)}};
  out["family"] = family_json(result);
  ordered_json examined = ordered_json::array();
  for (const planner::InstanceAnalysis& analysis : result.examined)
    examined.push_back(examined_json(analysis));
  out["instances"] = {{"count", result.instances.instances.size()},
                      {"limit_reached", result.instances.limit_reached},
                      {"examined", examined}};
  if (result.planned() && !result.instances.instances.empty()) {
    out["chosen"] = {{"index", result.chosen_index}, {"steps", chosen_steps_json(result)}};
    if (const planner::InstanceAnalysis* analysis = result.chosen_analysis()) {
      out["chosen"]["errors"] = analysis->errors;
      out["chosen"]["repairs"] = repairs_json(result, *analysis);
      out["chosen"]["uncertainty_variables"] = variables_json(result, *analysis);
      if (result.probability && result.tolerances)
        out["chosen"]["probability"] = probability_json(result, *analysis);
    }
  } else {
    out["chosen"] = nullptr;
  }
  return out;
}

}  // namespace spar::reports
