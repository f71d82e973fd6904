#include "spar/planner/uncertainty/propagation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "spar/kinematics/joint_error.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/uncertainty/deciding.hpp"
#include "spar/planner/uncertainty/probability.hpp"

namespace spar::planner {
namespace {

using kinematics::constant_point;
using kinematics::PoseError;
using kinematics::SymbolicPoint;
using kinematics::SymbolicTransform;
using kinematics::Transform;
using symbolic::Expr;

// The space's sigmas of a block (SpaceVariable::sigma): all 0 when it is uniform.
kinematics::PoseUncertainty sigmas(const UncertaintyModel& model) {
  return model.distribution == Distribution::kGaussian ? model.sigma
                                                       : kinematics::PoseUncertainty{};
}

using Reading = ScanReading;

std::array<Expr, 4> components(const PoseError& e) { return {e.dx, e.dy, e.dz, e.dtheta}; }
std::array<double, 4> components(const kinematics::PoseUncertainty& u) {
  return {u.dx, u.dy, u.dz, u.dtheta};
}

// Two readings of one object fused (see the header comment).
Reading fused(const Reading& earlier, const Reading& latest, int object) {
  // Worst case: both boxes are centred on the nominal, so their intersection is the smaller
  // half-width per component.
  const auto as_vector = [](const kinematics::PoseUncertainty& u) {
    return Eigen::Vector4d(u.dx, u.dy, u.dz, u.dtheta);
  };
  const Eigen::Vector4d widths =
      as_vector(earlier.half_widths).cwiseMin(as_vector(latest.half_widths));
  Reading out{{widths[0], widths[1], widths[2], widths[3]}, {}};
  // Gaussian: information form (CHOLMOD) when both readings are Gaussian in every component;
  // otherwise the fused residual is taken uniform over the intersection (conservative).
  const Eigen::Vector4d s1 = as_vector(earlier.sigmas), s2 = as_vector(latest.sigmas);
  if ((s1.array() > 0).all() && (s2.array() > 0).all()) {
    const PoseReading readings[2] = {{.object = object,
                                      .covariance = s1.cwiseAbs2().asDiagonal(),
                                      .half_width = as_vector(earlier.half_widths)},
                                     {.object = object,
                                      .covariance = s2.cwiseAbs2().asDiagonal(),
                                      .half_width = as_vector(latest.half_widths)}};
    const Eigen::Vector4d sigma = fuse_readings(readings).front().covariance.diagonal().cwiseSqrt();
    out.sigmas = {sigma[0], sigma[1], sigma[2], sigma[3]};
  }
  return out;
}

// The last words of both refusals: the domain declares the effects that do not fit.
std::string effect_question(const Domain& domain) {
  return "; do the effects in " + domain.source + " fit what its actions do?";
}

}  // namespace

Propagation::Propagation(const WorldModel& world, const Domain& domain, symbolic::ExprPool& pool)
    : world_(&world),
      domain_(&domain),
      space_(pool),
      table_(world.object_count()),
      held_(world.object_count()) {
  for (std::size_t o = 0; o < world.object_count(); ++o) {
    const ObjectSpec& object = world.scenario().objects[o];
    table_[o] = TableState{
        object.initial_pose,
        space_.allocate_pose(
            object.uncertainty,
            {.source = UncertaintySource::kInitial, .object = static_cast<int>(o), .step = -1},
            object.name, sigmas(object.uncertainty_model))};
  }
}

ArmError Propagation::arm_error(const Phase2Step& step, int index) {
  std::string tag = "g";  // appended, not "g" + ...: GCC 12 warns falsely (-Wrestrict) on that
  tag += std::to_string(index);
  ArmError arm{
      space_.allocate_pose(world_->scenario().robot.uncertainty,
                           {.source = UncertaintySource::kManipulator, .object = -1, .step = index},
                           tag, sigmas(world_->scenario().robot.uncertainty_model)),
      std::nullopt};
  if (!world_->scenario().robot.joint_uncertainty.empty()) arm.joints = joint_error(step, index);
  return arm;
}

SymbolicTransform Propagation::joint_error(const Phase2Step& step, int index) {
  const RobotSpec& robot = world_->scenario().robot;
  if (step.grasp < 0)
    throw PlanError("step " + std::to_string(index) +
                    ": joint uncertainty needs the step's grasp (where the arm is)");
  // The branch the step's collisions were checked at, so the bounds hold where the arm is; no
  // other branch stands in for it (its joints would err differently).
  const std::optional<kinematics::JointSolution>& arm = step.arm;
  if (!arm)
    throw PlanError("step " + std::to_string(index) +
                    ": the step has no collision-checked arm configuration, so its joint errors "
                    "have nowhere to act");
  const bool gaussian = robot.uncertainty_model.distribution == Distribution::kGaussian;
  std::vector<Expr> dq;
  for (std::size_t i = 0; i < robot.joint_uncertainty.size(); ++i) {
    const double half_width = robot.joint_uncertainty[i];
    const std::string name = "dq" + std::to_string(i + 1) + "_g" + std::to_string(index);
    const bool prismatic = robot.arm.joints()[i].type == kinematics::JointType::kPrismatic;
    dq.push_back(space_.symbol(space_.allocate(
        {.component = prismatic ? PoseComponent::kDx : PoseComponent::kDtheta,
         .half_width = half_width,
         .sigma = gaussian ? half_width / 3 : 0.0,
         .provenance = {.source = UncertaintySource::kJoint, .object = -1, .step = index},
         .tag = name,
         .name = name})));
  }
  return kinematics::joint_error_transform(robot.arm, arm->q, robot.tool, dq);
}

SymbolicTransform Propagation::grip_after_grasp(const Phase2Step& step, const ArmError& arm) {
  symbolic::ExprPool& pool = space_.pool();
  const TableState& state = *table_[step.object];
  const Transform& grasp = world_->object(step.object).grasps[step.grasp].gripper_in_object;
  const SymbolicTransform ideal_gripper =
      SymbolicTransform::from_numeric(pool, state.ideal * grasp);
  // The grasp centre's offset from the ideal gripper (x and z kept; y becomes the arm's Δy).
  const SymbolicPoint centre = kinematics::possible_object_point_in(
      ideal_gripper, state.ideal, constant_point(pool, grasp.translation()), state.error);
  if (arm.joints) {
    // H = R_Δ^T trans(q_x - t_x, 0, q_z - t_z) for T_ΔM = (R_Δ, t) (see the header).
    const SymbolicTransform error = arm.transform();
    const SymbolicPoint& t = error.translation();
    const SymbolicPoint offset = {centre[0] - t[0], pool.integer(0), centre[2] - t[2]};
    const SymbolicTransform rotation(
        pool,
        {error.rotation(0, 0), error.rotation(0, 1), error.rotation(0, 2), error.rotation(1, 0),
         error.rotation(1, 1), error.rotation(1, 2), error.rotation(2, 0), error.rotation(2, 1),
         error.rotation(2, 2)},
        {pool.integer(0), pool.integer(0), pool.integer(0)});
    const SymbolicPoint turned = rotation.apply_inverse(offset);
    return kinematics::trans(turned[0], turned[1], turned[2]);
  }
  // H = T_ΔM^-1 trans(q_x, Δy, q_z) rotz(Δθ): its rotation cancels, leaving the translation
  // rotz(-Δθ) (q_x - Δx, 0, q_z - Δz).
  const SymbolicPoint offset = {centre[0] - arm.pose.dx, pool.integer(0), centre[2] - arm.pose.dz};
  const SymbolicPoint turned = kinematics::rotz(-arm.pose.dtheta).apply(offset);
  return kinematics::trans(turned[0], turned[1], turned[2]);
}

TableState Propagation::released(const Phase2Step& step, const ArmError& arm,
                                 const SymbolicTransform& grip) const {
  const Transform& grasp = world_->object(step.object).grasps[step.grasp].gripper_in_object;
  const SymbolicPoint origin = held_point(*world_, step, arm, grip, Eigen::Vector3d::Zero());
  const Eigen::Vector3d& t = step.object_pose.translation();
  const double approach_up = (step.object_pose * grasp).linear().col(2).z();
  return {step.object_pose,
          {origin[0] - t.x(), origin[1] - t.y(), origin[2] - t.z(),
           approach_up >= 0 ? arm.yaw() : -arm.yaw()}};
}

std::optional<Reading> Propagation::unmoved_scan(int object) const {
  const std::array<Expr, 4> error = components(table_.at(object)->error);
  Reading reading;
  double* half_widths[4] = {&reading.half_widths.dx, &reading.half_widths.dy,
                            &reading.half_widths.dz, &reading.half_widths.dtheta};
  double* sigmas[4] = {&reading.sigmas.dx, &reading.sigmas.dy, &reading.sigmas.dz,
                       &reading.sigmas.dtheta};
  for (int i = 0; i < 4; ++i) {
    const std::optional<VariableId> id = space_.id_of(error[i]);
    if (!id) return std::nullopt;
    const SpaceVariable& variable = space_.variable(*id);
    if (variable.provenance.source != UncertaintySource::kSensor ||
        variable.provenance.object != object)
      return std::nullopt;
    *half_widths[i] = variable.half_width();
    *sigmas[i] = variable.sigma;
  }
  return reading;
}

std::array<bool, 4> Propagation::corrected_by(int object,
                                              const kinematics::PoseUncertainty& reading) const {
  const std::array<Expr, 4> error = components(table_.at(object)->error);
  const std::array<double, 4> half_widths = components(reading);
  const std::vector<bounds::Interval> enclosures = natural_enclosures(error, space_);
  std::array<bool, 4> corrected;
  for (int i = 0; i < 4; ++i) {
    const bounds::Interval& known = enclosures[i];
    corrected[i] =
        known.possibly_undefined || !(known.lo >= -half_widths[i]) || !(known.hi <= half_widths[i]);
  }
  return corrected;
}

std::string Propagation::step_name(const Phase2Step& step, int index) const {
  return "step " + std::to_string(index) + " (" + domain_->actions.at(step.action).name +
         ", effect " + std::string(to_string(step.effect)) + ")";
}

void Propagation::require_on_table(const Phase2Step& step, int object, int index) const {
  if (object >= 0 && table_.at(object)) return;
  std::string what = step_name(step, index) + " needs ";
  if (object < 0) {
    what += "an object on the table";
  } else {
    what += world_->scenario().objects[object].name + " on the table";
    if (held_.at(object)) what += ", but it is held";
  }
  throw PlanError(what + effect_question(*domain_));
}

void Propagation::require_held(const Phase2Step& step, int index, const char* doing) const {
  if (step.object >= 0 && held_.at(step.object)) return;
  throw PlanError(step_name(step, index) + " " + doing + " an object it does not hold" +
                  effect_question(*domain_));
}

std::vector<Precondition> Propagation::build(const Phase2Step& step, int index,
                                             const std::optional<ArmError>& arm) const {
  std::vector<Precondition> preconditions;
  for (const Builder builder : domain_->actions.at(step.action).uncertainty) {
    std::vector<Precondition> built;
    if (builder == Builder::kAssemble) {
      require_held(step, index, "inserts");
      require_on_table(step, step.fixed_object, index);
      built = assemble_preconditions(*world_, step, *held_[step.object], *table_[step.fixed_object],
                                     *arm);
    } else {
      require_on_table(step, step.object, index);
      if (step.grasp < 0)
        throw PlanError(step_name(step, index) + ": builder " + std::string(to_string(builder)) +
                        " needs a grasp");
      built = pickup_preconditions(*world_, step, *table_[step.object], *arm, builder);
    }
    preconditions.insert(preconditions.end(), built.begin(), built.end());
  }
  return preconditions;
}

void Propagation::sense(int object, int index, int camera) {
  Reading reading;
  if (camera >= 0) {
    const CameraSensor& sensor = world_->scenario().cameras.at(static_cast<std::size_t>(camera));
    if (!sensor.residual)
      throw PlanError("step " + std::to_string(index) + ": camera '" + sensor.name +
                      "' has no residual to verify with");
    reading = {*sensor.residual, sigmas(sensor.residual_model)};
  } else if (sensor_scale_) {
    return sense_scaled(object, index);
  } else {
    const RangeScanSensor sensor = world_->scenario().range_scan.value_or(RangeScanSensor{});
    reading = {sensor.residual, sigmas(sensor.residual_model)};
  }
  const Provenance provenance{
      .source = UncertaintySource::kSensor, .object = object, .step = index, .camera = camera};
  const std::string tag = world_->scenario().objects[object].name + "_s" + std::to_string(index);
  PoseError& error = table_[object]->error;
  if (const std::optional<Reading> earlier = unmoved_scan(object)) {
    reading = fused(*earlier, reading, object);
    error = space_.allocate_pose(reading.half_widths, provenance, tag, reading.sigmas);
    return;
  }
  const std::array<bool, 4> corrected = corrected_by(object, reading.half_widths);
  const std::array<double, 4> half_widths = components(reading.half_widths),
                              sigma = components(reading.sigmas);
  Expr* slots[4] = {&error.dx, &error.dy, &error.dz, &error.dtheta};
  for (const PoseComponent component : kPoseComponents) {
    const int i = index_of(component);
    if (!corrected[i]) continue;
    *slots[i] = space_.symbol(space_.allocate({.component = component,
                                               .half_width = half_widths[i],
                                               .sigma = sigma[i],
                                               .provenance = provenance,
                                               .tag = tag}));
  }
}

void Propagation::set_sensor_scale(double scale) {
  sensor_scale_ = scale;
  for (const ScaleVariable& s : scale_variables_) {
    const double value = std::min(s.cap, scale);
    space_.set_range(s.id, value, value);
  }
}

void Propagation::sense_scaled(int object, int index) {
  const RangeScanSensor sensor = world_->scenario().range_scan.value_or(RangeScanSensor{});
  const std::array<double, 4> residual = components(sensor.residual);
  // Fusion with an unmoved earlier reading keeps the smaller half-width per component: the scale
  // is capped at the earlier one's share of the residual (the worst case only; uniform).
  std::array<double, 4> caps;
  caps.fill(std::numeric_limits<double>::infinity());
  PoseError& now = table_.at(object)->error;
  if (const std::optional<Reading> earlier = unmoved_scan(object)) {
    const std::array<double, 4> widths = components(earlier->half_widths);
    for (int i = 0; i < 4; ++i)
      if (residual[i] > 0) caps[i] = widths[i] / residual[i];
  } else if (const auto last = scaled_scans_.find(object);
             last != scaled_scans_.end() && components(last->second.error) == components(now)) {
    caps = last->second.caps;
  }
  const Provenance provenance{
      .source = UncertaintySource::kSensor, .object = object, .step = index};
  const std::string tag = world_->scenario().objects[object].name + "_s" + std::to_string(index);
  const std::string unit_tag = tag + "_unit", scale_tag = tag + "_scale";
  Expr* slots[4] = {&now.dx, &now.dy, &now.dz, &now.dtheta};
  for (const PoseComponent component : kPoseComponents) {
    const int i = index_of(component);
    const double value = std::min(caps[i], *sensor_scale_);
    const VariableId scale = space_.allocate(
        {.component = component, .half_width = 0.0, .provenance = provenance, .tag = scale_tag});
    space_.set_range(scale, value, value);
    scale_variables_.push_back({scale, caps[i]});
    const VariableId unit = space_.allocate({.component = component,
                                             .half_width = residual[i],
                                             .provenance = provenance,
                                             .tag = unit_tag});
    *slots[i] = space_.symbol(scale) * space_.symbol(unit);
  }
  scaled_scans_[object] = {now, caps};
}

void Propagation::apply(const Phase2Step& step, int index, const std::optional<ArmError>& arm) {
  switch (step.effect) {
    case Effect::kGrasp:
      require_on_table(step, step.object, index);
      held_[step.object] = HeldState{step.grasp, grip_after_grasp(step, *arm)};
      table_[step.object].reset();
      break;
    case Effect::kReduce: {
      require_on_table(step, step.object, index);
      Phase2Step in_place = step;
      in_place.object_pose = table_[step.object]->ideal;
      table_[step.object] = released(in_place, *arm, grip_after_grasp(step, *arm));
      break;
    }
    case Effect::kRelease:
      require_held(step, index, "puts down");
      table_[step.object] = released(step, *arm, held_[step.object]->grip);
      held_[step.object].reset();
      break;
    case Effect::kInsert:
      require_held(step, index, "inserts");
      require_on_table(step, step.fixed_object, index);
      held_[step.object].reset();
      break;
    case Effect::kSense:
      require_on_table(step, step.object, index);
      sense(step.object, index, step.camera);
      break;
    case Effect::kNone:
      break;
  }
}

std::optional<ArmError> Propagation::arm_for(const Phase2Step& step, int index) {
  if (moves_arm(step.effect) || !domain_->actions.at(step.action).uncertainty.empty())
    return arm_error(step, index);
  return std::nullopt;
}

std::vector<Precondition> Propagation::step(const Phase2Step& step, int index) {
  const std::optional<ArmError> arm = arm_for(step, index);
  std::vector<Precondition> preconditions = build(step, index, arm);
  apply(step, index, arm);
  return preconditions;
}

DeferredStep Propagation::step_deferred(const Phase2Step& step, int index) {
  std::optional<ArmError> arm = arm_for(step, index);
  DeferredStep deferred(*this, step, index, arm);
  apply(step, index, arm);
  return deferred;
}

}  // namespace spar::planner
