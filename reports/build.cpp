#include "spar/reports/build.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "spar/kinematics/puma.hpp"
#include "spar/reports/internal/cell.hpp"
#include "spar/reports/sensing.hpp"

namespace spar::reports {
namespace {

using planner::ParameterType;

Matrix matrix(const Eigen::Isometry3d& pose, double length_scale) {
  Matrix out{};
  const Eigen::Matrix4d m = pose.matrix();
  for (int row = 0; row < 4; ++row)
    for (int column = 0; column < 4; ++column)
      out[row][column] = column == 3 && row < 3 ? m(row, column) * length_scale : m(row, column);
  return out;
}

// Lengths in the scenario's unit: metres times this.
double length_scale(const planner::PlanResult& result) {
  return 1.0 / result.world.scenario().units.metres_per_length_unit();
}

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

Family build_family(const planner::PlanResult& result) {
  const planner::PlanFamily& family = result.family;
  Family out;
  for (const planner::FamilyStep& step : family.steps) {
    FamilyStep& row = out.steps.emplace_back();
    row.id = step.id;
    row.action = step.action < 0 ? (step.id == 0 ? "start" : "finish")
                                 : result.domain.actions[step.action].name;
    if (step.action >= 0)
      row.effect = std::string(planner::to_string(result.domain.actions[step.action].effect));
    for (const planner::Term& term : step.args)
      row.args.push_back(family.term_name(term, result.world));
    row.text = family.describe(step, result.world, result.domain);
  }
  for (const auto& [before, after] : family.ordering.transitive_reduction())
    out.ordering.push_back({before, after});
  for (int v = 0; v < family.network.variable_count(); ++v) {
    if (family.network.representative(v) != v) continue;
    const planner::PlanVariable& meta = family.variables[v];
    PlanVariable& variable = out.variables.emplace_back();
    variable.name = meta.name;
    variable.type = type_name(meta.type);
    variable.object = result.world.scenario().objects[meta.object].name;
    for (const int label : family.network.labels(v))
      variable.labels.push_back(label_name(result, v, label));
  }
  for (const planner::cms::ArcPairs& arc : family.network.arcs()) {
    Arc& row = out.arcs.emplace_back();
    row.variables = {family.variables[arc.first].name, family.variables[arc.second].name};
    for (const auto& [a, b] : arc.pairs)
      row.pairs.push_back({label_name(result, arc.first, a), label_name(result, arc.second, b)});
  }
  for (const planner::SatisfiedGoal& goal : family.satisfied)
    out.goals.push_back(
        {goal.level == planner::SatisfiedGoal::Level::kOperational ? "operational" : "geometric",
         goal.condition, goal.step, goal.how});
  out.search = {family.stats.expanded, family.stats.generated, family.stats.seconds};
  return out;
}

Step build_step(const planner::PlanResult& result, const planner::InstanceStep& step) {
  const planner::Scenario& scenario = result.world.scenario();
  const double scale = length_scale(result);
  Step out;
  out.id = step.step;
  out.action = step.action_name;
  out.effect = planner::to_string(result.domain.actions.at(step.action).effect);
  if (step.object >= 0) out.object = scenario.objects[step.object].name;
  if (step.grasp >= 0) {
    const geometry::Grasp& grasp = result.world.object(step.object).grasps[step.grasp];
    out.grasp = Grasp{grasp.label,
                      {grasp.face_plus_y, grasp.face_minus_y},
                      grasp.width * scale,
                      matrix(grasp.gripper_in_object, scale)};
  }
  if (step.position >= 0) {
    out.object_pose = matrix(step.object_pose, scale);
    const auto& poses = scenario.objects[step.object].stable_poses;
    out.stable_pose = step.stable_pose >= 0 && !step.is_assembly()
                          ? Nullable<std::string>(poses[step.stable_pose].label)
                          : Nullable<std::string>();
  }
  if (step.grasp >= 0) {
    out.gripper_pose = matrix(step.gripper_pose, scale);
    out.joints.emplace();
    out.configuration.emplace();
    if (step.reach.solution) {
      const auto& q = step.reach.solution->q;
      *out.joints = std::vector<double>(q.data(), q.data() + q.size());
      *out.configuration = step.reach.solution->configuration;
    }
  }
  if (step.is_assembly()) {
    out.fixed_object = scenario.objects[step.fixed_object].name;
    out.fixed_pose = matrix(step.fixed_pose, scale);
    out.held_pose = matrix(step.held_pose, scale);
  }
  if (step.grasp >= 0)
    out.clearance =
        Clearance{step.collision.clearance,
                  step.collision.nearest >= 0
                      ? Nullable<std::string>(scenario.objects[step.collision.nearest].name)
                      : Nullable<std::string>()};
  for (const int part : step.carried) out.carried.push_back(scenario.objects[part].name);
  return out;
}

// The SI unit of a precondition's expression: SPAR's pickup inequalities and the insertion
// offsets are lengths; the misalignment condition compares cosines (dimensionless).
const char* precondition_unit(const planner::PreconditionResult& result) {
  return result.length ? "m" : "1";
}

// `max_scale`: the reverse analysis' search cap (a scale equal to it may be exceeded).
Precondition build_precondition(const planner::Scenario& scenario,
                                const planner::PreconditionResult& result,
                                const std::vector<planner::SpaceVariable>& space,
                                double max_scale) {
  Precondition out;
  out.name = result.inequality.name;
  out.kind = planner::to_string(result.kind);
  out.relation = bounds::to_string(result.inequality.relation);
  out.threshold = result.inequality.threshold;
  out.unit = precondition_unit(result);
  out.expression = planner::printed_expression(result);
  out.nodes = result.nodes;
  out.lo = result.bound.lo;
  out.hi = result.bound.hi;
  if (result.bound.has_inner_range()) {
    out.inner_lo = result.bound.inner_lo;
    out.inner_hi = result.bound.inner_hi;
  } else {
    out.no_inner_range = std::string(result.bound.why_no_inner_range());
  }
  out.verdict = bounds::to_string(result.verdict);
  const auto name_of = [&](planner::VariableId id) { return space.at(id.index).name; };
  for (std::size_t v = 0; v < result.witness.size() && v < result.variables.size(); ++v)
    out.witness.emplace_back(name_of(result.variables[v]), result.witness[v]);
  for (std::size_t v = 0; v < result.variables.size(); ++v)
    out.box.emplace_back(name_of(result.variables[v]),
                         std::array<double, 2>{result.box[v].lo, result.box[v].hi});
  const bool length = out.unit == "m";
  const double scale = length ? 1.0 / scenario.units.metres_per_length_unit() : 1.0;
  out.display = {length ? std::string(scenario.units.length_name()) : out.unit,
                 result.inequality.threshold * scale, result.bound.lo * scale,
                 result.bound.hi * scale};
  if (out.inner_lo) {
    out.display.inner_lo = *out.inner_lo * scale;
    out.display.inner_hi = *out.inner_hi * scale;
  }
  if (!result.blame.empty()) {
    out.blame.emplace();
    for (const auto& entry : result.blame)
      out.blame->push_back({name_of(entry.variable), entry.share});
  }
  if (result.holds_up_to_scale) {
    // The scaled uncertainty as half-widths: the widest scaled displacement and rotation among
    // the variables reverse analysis scales (the objects' initial and sensed ones).
    const double s = *result.holds_up_to_scale;
    double displacement = 0.0, rotation = 0.0;
    for (std::size_t v = 0; v < result.variables.size(); ++v) {
      const planner::SpaceVariable& variable = space.at(result.variables[v].index);
      if (planner::of_the_arm(variable.provenance.source)) continue;
      const double half_width = std::max(-result.box[v].lo, result.box[v].hi) * s;
      double& widest = variable.angle() ? rotation : displacement;
      widest = std::max(widest, half_width);
    }
    out.holds_up_to_scale = s;
    out.holds_up_to_capped = s >= max_scale;
    out.margin =
        Margin{scenario.units.to_file_length(displacement), scenario.units.to_file_angle(rotation)};
  }
  out.monte_carlo_violation = result.monte_carlo_violation;
  if (result.monte_carlo_violation) out.monte_carlo_samples = result.monte_carlo_samples;
  return out;
}

// What PSEIKI must see, with the rendered scene (pixels to 0.01: the drawing needs no more).
VisionCheck vision_of(const planner::VisionCheck& check) {
  const auto pixel = [](double value) { return std::round(100 * value) / 100; };
  VisionView view{check.width, check.height, {}};
  for (const planner::VisionEdge& edge : check.drawing) {
    VisionViewEdge& drawn = view.edges.emplace_back(VisionViewEdge{edge.id, edge.object, {}});
    for (const sensing::pseiki::Segment& piece : edge.pieces)
      drawn.pieces.push_back(
          {pixel(piece.p0.x()), pixel(piece.p0.y()), pixel(piece.p1.x()), pixel(piece.p1.y())});
  }
  return {check.camera, check.object, check.edges, check.acceptance, std::move(view)};
}

// Verification sensing of a failed step and, per outcome, its recovery plan.
void add_verification(const std::vector<planner::VerificationPlan>& plans, Step& step) {
  step.verification.emplace();
  step.recovery.emplace();
  for (const planner::VerificationPlan& plan : plans) {
    Verification& verification = step.verification->emplace_back();
    verification.name = plan.name;
    verification.sense = plan.sense;
    verification.expect = plan.expect;
    if (plan.vision) verification.vision = vision_of(*plan.vision);
    for (const auto& outcome : plan.outcomes) {
      verification.outcomes.push_back({outcome.when, outcome.error, outcome.recovery});
      step.recovery->push_back({outcome.error, outcome.recovery, outcome.recovery_steps});
    }
  }
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
    if (analysed.step.arm) step.reach.solution = analysed.step.arm;  // what phase 2 analysed
  }
  return step;
}

// Precondition references of the planner's (instance step, index) as chosen-step indices.
std::vector<PreconditionRef> turned_refs(const planner::InstanceAnalysis& analysis,
                                         const std::vector<planner::PreconditionRef>& refs) {
  std::vector<PreconditionRef> out;
  for (const planner::PreconditionRef& ref : refs)
    for (std::size_t s = 0; s < analysis.steps.size(); ++s)
      if (!analysis.steps[s].inserted && analysis.steps[s].step.instance_step == ref.instance_step)
        out.push_back({s, ref.index});
  return out;
}

std::vector<Step> analysed_steps(const planner::PlanResult& result,
                                 const planner::PlanInstance& instance,
                                 const planner::InstanceAnalysis& analysis) {
  const planner::Scenario& scenario = result.world.scenario();
  std::vector<Step> steps;
  int next_id = static_cast<int>(result.family.steps.size());
  for (std::size_t k = 0; k < analysis.steps.size(); ++k) {
    const planner::AnalysedStep& analysed = analysis.steps[k];
    Step out;
    if (analysed.inserted) {
      planner::InstanceStep step = inserted_step(result, analysed);
      std::tie(step.collision, step.carried) = result.chosen_checks.at(k);
      out = build_step(result, step);
      out.id = next_id++;
      out.stable_pose = Nullable<std::string>();
    } else {
      out = build_step(result, instance.steps[analysed.step.instance_step]);
    }
    out.inserted = analysed.inserted;
    if (analysed.inserted && analysed.step.repair >= 0)
      out.turned = turned_refs(analysis, analysis.repairs.at(analysed.step.repair).turned);
    if (analysed.step.effect == planner::Effect::kSense) {
      out.corrects.emplace();
      for (const PoseComponent component : analysed.corrects)
        out.corrects->emplace_back(to_string(component));
    }
    if (analysed.step.grasp >= 0 && (analysed.step.effect == planner::Effect::kGrasp ||
                                     analysed.step.effect == planner::Effect::kReduce))
      out.finger_opening = result.world.gripper().max_opening * length_scale(result);
    out.preconditions.emplace();
    for (const planner::PreconditionResult& precondition : analysed.preconditions)
      out.preconditions->push_back(build_precondition(scenario, precondition, analysis.variables,
                                                      result.analysis.max_scale));
    out.failed = analysed.failed;
    if (analysed.camera_verification) out.vision = vision_of(*analysed.camera_verification);
    if (analysed.sensor_scale_needed && scenario.range_scan) {
      // The range-scan residual (scenario units) that would make this failed step hold.
      const planner::Units& units = scenario.units;
      const kinematics::PoseUncertainty& r = scenario.range_scan->residual;
      const double f = *analysed.sensor_scale_needed;
      out.sensor_residual_needed = SensorResidual{f,
                                                  f >= result.analysis.max_scale,
                                                  units.to_file_length(r.dx * f),
                                                  units.to_file_length(r.dy * f),
                                                  units.to_file_length(r.dz * f),
                                                  units.to_file_angle(r.dtheta * f)};
    }
    if (analysed.failed) add_verification(analysed.verification, out);
    steps.push_back(std::move(out));
  }
  return steps;
}

std::vector<Repair> build_repairs(const planner::PlanResult& result,
                                  const planner::PlanInstance& instance,
                                  const planner::InstanceAnalysis& analysis) {
  std::vector<Repair> repairs;
  for (const planner::RepairAttempt& attempt : analysis.repairs) {
    // The failing step's preconditions, in the order of `before` and `after`.
    const auto failing =
        std::find_if(analysis.steps.begin(), analysis.steps.end(), [&](const auto& step) {
          return !step.inserted && step.step.instance_step == attempt.for_instance_step;
        });
    const auto bounds_of = [&](const std::vector<bounds::BoundResult>& bounds,
                               const std::vector<bounds::Verdict>& verdicts) {
      std::vector<RepairBound> out;
      for (std::size_t i = 0; i < bounds.size(); ++i) {
        RepairBound& entry = out.emplace_back();
        if (failing != analysis.steps.end() && i < failing->preconditions.size()) {
          entry.name = failing->preconditions[i].inequality.name;
          entry.unit = precondition_unit(failing->preconditions[i]);
        }
        entry.lo = bounds[i].lo;
        entry.hi = bounds[i].hi;
        entry.verdict = bounds::to_string(verdicts[i]);
      }
      return out;
    };
    repairs.push_back({attempt.action, result.world.scenario().objects.at(attempt.object).name,
                       instance.steps.at(attempt.for_instance_step).step, attempt.helped,
                       turned_refs(analysis, attempt.turned),
                       bounds_of(attempt.before, attempt.verdicts_before),
                       bounds_of(attempt.after, attempt.verdicts_after)});
  }
  return repairs;
}

std::vector<RepairSearch> build_repair_searches(const planner::PlanInstance& instance,
                                                const planner::InstanceAnalysis& analysis) {
  std::vector<RepairSearch> searches;
  for (const planner::RepairSearch& search : analysis.repair_searches) {
    RepairSearch& out = searches.emplace_back();
    out.for_step = instance.steps.at(search.for_instance_step).step;
    out.candidates = search.candidates;
    out.sets_tried = search.sets_tried;
    out.kept = search.kept;
    for (const auto& [kind, count] : search.dropped) out.dropped.emplace_back(kind, count);
    out.holds = search.holds;
  }
  return searches;
}

std::vector<UncertaintyVariable> build_variables(const planner::PlanResult& result,
                                                 const planner::InstanceAnalysis& analysis) {
  const planner::Scenario& scenario = result.world.scenario();
  const planner::Units& units = scenario.units;
  std::vector<UncertaintyVariable> variables;
  for (const planner::SpaceVariable& v : analysis.variables) {
    const bool angle = v.angle();
    const auto convert = [&](double value) {
      return angle ? units.to_file_angle(value) : units.to_file_length(value);
    };
    UncertaintyVariable& out = variables.emplace_back();
    out.name = v.name;
    out.lo = v.lower;
    out.hi = v.upper;
    out.unit = angle ? "rad" : "m";
    out.source = planner::to_string(v.provenance.source);
    if (v.provenance.object >= 0) out.object = scenario.objects[v.provenance.object].name;
    if (v.provenance.step >= 0) out.step = v.provenance.step;
    out.display = {angle ? std::string(units.angle_name()) : std::string(units.length_name()),
                   convert(v.lower), convert(v.upper)};
  }
  return variables;
}

ExaminedInstance build_examined(const planner::InstanceAnalysis& analysis) {
  ExaminedInstance out;
  out.index = analysis.instance;
  out.errors = analysis.errors;
  out.steps = analysis.steps.size();
  for (const planner::AnalysedStep& step : analysis.steps) {
    out.inserted += step.inserted ? 1 : 0;
    for (const planner::PreconditionResult& precondition : step.preconditions) {
      ++out.preconditions;
      out.failed_preconditions += precondition.verdict == bounds::Verdict::kSatisfied ? 0 : 1;
    }
  }
  return out;
}

// The chosen instance's probabilistic analysis and tolerance allocation.
Probability build_probability(const planner::PlanResult& result,
                              const planner::InstanceAnalysis& analysis) {
  const planner::ProbabilityAnalysis& p = *result.probability;
  const planner::ToleranceAllocation& t = *result.tolerances;
  const planner::Units& units = result.world.scenario().units;
  Probability out;
  out.jacobian = {
      p.rows, p.cols, p.nonzeros, p.density, p.covariance_nonzeros, p.non_differentiable};
  out.samples = p.samples;
  out.plan = {p.p_plan, {p.p_plan_ci_lo, p.p_plan_ci_hi}};
  for (const planner::PreconditionProbability& q : p.preconditions) {
    const auto miss = std::find_if(t.misses.begin(), t.misses.end(), [&](const auto& m) {
      return m.step == q.step && m.precondition == q.precondition;
    });
    PreconditionProbability& row = out.preconditions.emplace_back();
    row.step = q.step;
    row.index = q.precondition;
    row.name = analysis.steps[q.step].preconditions[q.precondition].inequality.name;
    row.nominal = q.nominal;
    row.mean = q.mean;
    row.second_order_mean = q.second_order_mean;
    row.sigma = q.sigma;
    row.p_first_order = q.p_first_order;
    row.p_second_order = q.p_second_order;
    row.p_monte_carlo = q.p_monte_carlo;
    row.ci = {q.ci_lo, q.ci_hi};
    row.violations = q.violations;
    row.samples = q.samples;
    row.proved = q.proved;
    row.agrees = q.agrees;
    row.note = q.note;
    if (miss != t.misses.end()) row.allocation_miss = miss->by;
  }
  out.tolerances.status = planner::to_string(t.status);
  out.tolerances.cost = t.cost;
  out.tolerances.rounds = t.rounds;
  for (const planner::ToleranceParameter& q : t.parameters) {
    const bool angle = is_angle(q.component);
    const auto shown = [&](double value) {
      return angle ? units.to_file_angle(value) : units.to_file_length(value);
    };
    out.tolerances.parameters.push_back(
        {q.name, planner::to_string(q.source), angle ? "rad" : "m", q.half_width, q.allocated,
         q.cost,
         ToleranceDisplay{
             angle ? std::string(units.angle_name()) : std::string(units.length_name()),
             shown(q.half_width), shown(q.allocated)}});
  }
  return out;
}

}  // namespace

Chosen build_chosen(const planner::PlanResult& result, std::size_t instance_index,
                    const planner::InstanceAnalysis* analysis) {
  const planner::PlanInstance& instance = result.instances.instances.at(instance_index);
  Chosen out;
  out.index = instance_index;
  if (analysis == nullptr) {
    for (const planner::InstanceStep& step : instance.steps)
      out.steps.push_back(build_step(result, step));
    return out;
  }
  out.steps = analysed_steps(result, instance, *analysis);
  out.errors = analysis->errors;
  out.repairs = build_repairs(result, instance, *analysis);
  out.repair_searches = build_repair_searches(instance, *analysis);
  out.uncertainty_variables = build_variables(result, *analysis);
  if (instance_index == result.chosen_index && analysis == result.chosen_analysis() &&
      result.probability && result.tolerances)
    out.probability = build_probability(result, *analysis);
  return out;
}

namespace {

// An uncertain object's sensing steps (the report's chosen steps), its sense plan and one branch
// per outcome.
void add_sensing(const planner::PlanResult& result, Report& out) {
  const ObjectSensing sensed = build_object_sensing(*result.sensing);
  Chosen sensing;
  for (const SensingOperation& operation : sensed.sequence) {
    Step& step = sensing.steps.emplace_back();
    step.id = static_cast<int>(sensing.steps.size());
    step.action = "sense";
    step.effect = "sense";
    step.object = sensed.object;
    step.sensing = SensingChoice{.sensor = operation.sensor,
                                 .viewpoint = operation.viewpoint,
                                 .aspect = operation.aspect,
                                 .predicted_max_ambiguity = operation.predicted_max_ambiguity};
  }
  if (!result.branches.empty()) out.chosen = std::move(sensing);
  out.sensing = std::vector<ObjectSensing>{sensed};
  out.branches.emplace();
  for (const planner::PlanBranch& branch : result.branches) {
    Report planned = build_report(branch.result);
    Branch& row = out.branches->emplace_back();
    row.outcome = branch.outcome;
    row.object = branch.object;
    row.status = planned.status;
    if (planned.chosen) {
      row.steps = std::move(planned.chosen->steps);
      row.errors = planned.chosen->errors;
    }
    if (!out.reason && planned.reason)
      out.reason = "branch " + branch.outcome + ": " + *planned.reason;
  }
}

}  // namespace

Report build_report(const planner::PlanResult& result) {
  const planner::Scenario& scenario = result.world.scenario();
  const double scale = length_scale(result);
  Report out;
  out.scenario = scenario.name;
  out.description = scenario.description;
  out.status = result.planned() ? "planned" : "no_plan";
  if (!result.planned() && !(result.sensing && !result.branches.empty()))
    out.reason = result.sensing
                     ? "sensing: " + result.family.reason
                     : std::string(to_string(result.family.status)) + ": " + result.family.reason;
  out.units = {std::string(scenario.units.length_name()), std::string(scenario.units.angle_name()),
               scenario.units.metres_per_length_unit(), scenario.units.radians_per_angle_unit()};
  out.robot.model = scenario.robot.model;
  out.robot.base = matrix(scenario.robot.base, scale);
  out.robot.tool = matrix(scenario.robot.tool, scale);
  if (scenario.robot.model == "urdf") out.robot.urdf = scenario.robot.urdf;
  const kinematics::RobotModel& arm = scenario.robot.arm;
  const std::vector<std::string_view> dh_tables = kinematics::builtin_robot_names();
  if (scenario.robot.model != "dh" &&
      std::find(dh_tables.begin(), dh_tables.end(), scenario.robot.model) == dh_tables.end()) {
    // A URDF robot's ends and joint order; the DH robots' reports stay as they were.
    out.robot.base_link = arm.base_link();
    out.robot.tip = arm.tip_link();
    out.robot.joint_names.emplace();
    for (const kinematics::MovingJoint& joint : arm.joints())
      out.robot.joint_names->push_back(joint.name);
  }
  out.family = build_family(result);
  out.instances.count = result.instances.instances.size();
  out.instances.limit_reached = result.instances.limit_reached;
  for (const planner::InstanceAnalysis& analysis : result.examined)
    out.instances.examined.push_back(build_examined(analysis));
  if (result.planned() && !result.instances.instances.empty()) {
    out.chosen = build_chosen(result, result.chosen_index, result.chosen_analysis());
    out.cell = internal::build_cell(result, *out.chosen, result.chosen(), result.chosen_analysis());
  }
  if (result.sensing) add_sensing(result, out);
  return out;
}

BoundRecord bound_record(const bounds::Box& box, const bounds::BoundResult& result, double seconds,
                         std::optional<std::string> name) {
  BoundRecord out;
  out.name = std::move(name);
  out.lo = result.lo;
  out.hi = result.hi;
  if (result.has_inner_range()) {
    out.inner_lo = result.inner_lo;
    out.inner_hi = result.inner_hi;
  } else {
    out.no_inner_range = std::string(result.why_no_inner_range());
  }
  for (std::size_t i = 0; i < result.argmin.size(); ++i)
    out.argmin.emplace_back(std::string(box.variables[i].name()), result.argmin[i]);
  for (std::size_t i = 0; i < result.argmax.size(); ++i)
    out.argmax.emplace_back(std::string(box.variables[i].name()), result.argmax[i]);
  out.status = bounds::to_string(result.status);
  out.possibly_undefined = result.possibly_undefined;
  out.time_limited = result.time_limited;
  out.relative_gap = result.relative_gap();
  out.evaluations = result.evaluations;
  out.seconds = seconds;
  return out;
}

}  // namespace spar::reports
