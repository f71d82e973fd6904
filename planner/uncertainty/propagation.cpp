#include "spar/planner/uncertainty/propagation.hpp"

#include <cmath>

#include "spar/kinematics/pickup.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/uncertainty/probability.hpp"

namespace spar::planner {
namespace {

using kinematics::PoseError;
using kinematics::SymbolicPoint;
using kinematics::SymbolicTransform;
using kinematics::Transform;
using symbolic::Expr;

bool has_atom(const std::vector<Atom>& atoms, std::string_view predicate) {
  return std::any_of(atoms.begin(), atoms.end(),
                     [&](const Atom& atom) { return atom.predicate == predicate; });
}

SymbolicPoint constant_point(symbolic::ExprPool& pool, const Eigen::Vector3d& p) {
  return kinematics::constant_point(pool, p.x(), p.y(), p.z());
}

Expr dot(const SymbolicPoint& p, const Eigen::Vector3d& u) {
  return p[0] * u.x() + p[1] * u.y() + p[2] * u.z();
}

// Area centroid of the given faces (object frame).
Eigen::Vector3d faces_centroid(const geometry::ObjectModel& model, const std::vector<int>& faces) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0;
  for (const int id : faces) {
    const geometry::Face& face = model.face(id);
    sum += face.area * face.centroid;
    area += face.area;
  }
  return area > 0 ? Eigen::Vector3d(sum / area) : Eigen::Vector3d::Zero();
}

// The space's sigmas of a block (SpaceVariable::sigma): all 0 when it is uniform.
kinematics::PoseUncertainty sigmas(const UncertaintyModel& model) {
  return model.distribution == Distribution::kGaussian ? model.sigma
                                                       : kinematics::PoseUncertainty{};
}

}  // namespace

StepEffect step_effect(const ActionTemplate& action) {
  if (action.kind == ActionKind::kSensing) return StepEffect::kRangeScan;
  if (action.kind == ActionKind::kReduction) return StepEffect::kSqueeze;
  if (has_atom(action.add, "holding")) return StepEffect::kGrasp;
  if (has_atom(action.add, "assembled")) return StepEffect::kInsert;
  if (has_atom(action.del, "holding") && has_atom(action.add, "at")) return StepEffect::kRelease;
  return StepEffect::kNone;
}

Propagation::Propagation(const WorldModel& world, symbolic::ExprPool& pool)
    : world_(&world), space_(pool), table_(world.object_count()), held_(world.object_count()) {
  for (std::size_t o = 0; o < world.object_count(); ++o) {
    const ObjectSpec& object = world.scenario().objects[o];
    table_[o] = TableState{
        object.initial_pose,
        space_.allocate(
            object.uncertainty,
            {.source = UncertaintySource::kInitial, .object = static_cast<int>(o), .step = -1},
            object.name, sigmas(object.uncertainty_model))};
  }
}

PoseError Propagation::allocate_arm(int index) {
  return space_.allocate(world_->scenario().robot.uncertainty,
                         {.source = UncertaintySource::kManipulator, .object = -1, .step = index},
                         "g" + std::to_string(index),
                         sigmas(world_->scenario().robot.uncertainty_model));
}

SymbolicTransform Propagation::grip_after_grasp(const Phase2Step& step, const PoseError& arm) {
  symbolic::ExprPool& pool = space_.pool();
  const TableState& state = *table_[step.object];
  const Transform& grasp = world_->object(step.object).grasps[step.grasp].gripper_in_object;
  const SymbolicTransform ideal_gripper =
      SymbolicTransform::from_numeric(pool, state.ideal * grasp);
  // The grasp centre's offset from the ideal gripper (x and z kept; y becomes the arm's Δy).
  const SymbolicPoint centre = kinematics::possible_object_point_in(
      ideal_gripper, state.ideal, constant_point(pool, grasp.translation()), state.error);
  // H = T_ΔM^-1 trans(q_x, Δy, q_z) rotz(Δθ): its rotation cancels, leaving the translation
  // rotz(-Δθ) (q_x - Δx, 0, q_z - Δz).
  const SymbolicPoint offset = {centre[0] - arm.dx, pool.integer(0), centre[2] - arm.dz};
  const SymbolicPoint turned = kinematics::rotz(-arm.dtheta).apply(offset);
  return kinematics::trans(turned[0], turned[1], turned[2]);
}

kinematics::SymbolicPoint Propagation::held_point(const Phase2Step& step, const PoseError& arm,
                                                  const SymbolicTransform& grip,
                                                  const Eigen::Vector3d& local) const {
  // M T_ΔM H T_G^-1 local, applied right to left as points: no transform product is built, so
  // each coordinate stays a short sum.
  symbolic::ExprPool& pool = space_.pool();
  const Transform& grasp = world_->object(step.object).grasps[step.grasp].gripper_in_object;
  const SymbolicPoint in_grasp =
      grip.apply(constant_point(pool, grasp.inverse(Eigen::Isometry) * local));
  const SymbolicPoint in_ideal = kinematics::manipulator_error_transform(arm).apply(in_grasp);
  return SymbolicTransform::from_numeric(pool, step.object_pose * grasp).apply(in_ideal);
}

Propagation::TableState Propagation::released(const Phase2Step& step, const PoseError& arm,
                                              const SymbolicTransform& grip) const {
  const Transform& grasp = world_->object(step.object).grasps[step.grasp].gripper_in_object;
  const SymbolicPoint origin = held_point(step, arm, grip, Eigen::Vector3d::Zero());
  const Eigen::Vector3d& t = step.object_pose.translation();
  const double approach_up = (step.object_pose * grasp).linear().col(2).z();
  return {step.object_pose,
          {origin[0] - t.x(), origin[1] - t.y(), origin[2] - t.z(),
           approach_up >= 0 ? arm.dtheta : -arm.dtheta}};
}

std::vector<Precondition> Propagation::pickup_preconditions(const Phase2Step& step,
                                                            const PoseError& arm,
                                                            const std::string& kind) const {
  const TableState& state = *table_[step.object];
  const geometry::Grasp& grasp = world_->object(step.object).grasps[step.grasp];
  const kinematics::PickupGeometry geometry{.object_pose = state.ideal,
                                            .grasp = grasp.gripper_in_object,
                                            .finger_opening = world_->gripper().max_opening,
                                            .object_width = grasp.width};
  std::vector<Precondition> out;
  for (const kinematics::PickupCondition& condition :
       kinematics::pickup_conditions(geometry, arm, state.error))
    out.push_back(
        {kind,
         {condition.name, condition.expression,
          condition.positive ? bounds::Relation::kGreater : bounds::Relation::kLess, 0.0}});
  return out;
}

std::vector<Precondition> Propagation::assemble_preconditions(const Phase2Step& step,
                                                              const PoseError& arm) const {
  symbolic::ExprPool& pool = space_.pool();
  const GoalWorld* tables = world_->goal(step.object, step.fixed_object);
  if (tables == nullptr) throw PlanError("internal: an insertion no goal names");
  const AssembledGoal& goal =
      std::get<AssembledGoal>(world_->scenario().goals[tables - world_->goals().data()]);
  const TableState& fixed = *table_[step.fixed_object];
  const SymbolicTransform& grip = held_[step.object]->grip;
  // A world point expressed in the fixed object's actual frame: R_O^T rotz(-θ) (X - t_O - d).
  const SymbolicTransform fixed_rotation =
      kinematics::rotz(fixed.error.dtheta) *
      SymbolicTransform::from_numeric(pool, Transform(fixed.ideal.linear()));
  const Eigen::Vector3d& t_fixed = fixed.ideal.translation();
  const auto in_fixed = [&](const SymbolicPoint& world_point) {
    const SymbolicPoint shifted = {world_point[0] - fixed.error.dx - t_fixed.x(),
                                   world_point[1] - fixed.error.dy - t_fixed.y(),
                                   world_point[2] - fixed.error.dz - t_fixed.z()};
    return fixed_rotation.apply_inverse(shifted);
  };
  const Eigen::Vector3d mating_point =
      faces_centroid(world_->scenario().objects[step.object].model, goal.held_faces);
  const Eigen::Vector3d ideal_point = goal.relative * mating_point;
  const SymbolicPoint actual_point = in_fixed(held_point(step, arm, grip, mating_point));
  const SymbolicPoint offset = {actual_point[0] - ideal_point.x(),
                                actual_point[1] - ideal_point.y(),
                                actual_point[2] - ideal_point.z()};
  const Eigen::Vector3d v = goal.mating_vector.normalized();
  const Eigen::Vector3d u1 = v.unitOrthogonal(), u2 = v.cross(u1);
  std::vector<Precondition> out;
  const Expr along[2] = {dot(offset, u1), dot(offset, u2)};
  for (int axis = 0; axis < 2; ++axis) {
    const std::string name =
        "offset along u" + std::to_string(axis + 1) + " (perpendicular to " + "the mating vector)";
    out.push_back(
        {"assemble",
         {name + " <= clearance", along[axis], bounds::Relation::kLessEqual, goal.clearance}});
    out.push_back(
        {"assemble",
         {name + " >= -clearance", along[axis], bounds::Relation::kGreaterEqual, -goal.clearance}});
  }
  if (goal.angular_clearance > 0) {
    const Eigen::Vector3d held_axis = goal.relative.linear().transpose() * v;
    const SymbolicPoint tip = in_fixed(held_point(step, arm, grip, mating_point + held_axis));
    const SymbolicPoint axis = {tip[0] - actual_point[0], tip[1] - actual_point[1],
                                tip[2] - actual_point[2]};
    out.push_back({"assemble",
                   {"cos(misalignment) >= cos(angular clearance)", dot(axis, v),
                    bounds::Relation::kGreaterEqual, std::cos(goal.angular_clearance)},
                   /*length=*/false});
  }
  return out;
}

std::optional<Propagation::Reading> Propagation::unmoved_scan(int object) const {
  const PoseError& error = table_.at(object)->error;
  Reading reading;
  const Expr components[4] = {error.dx, error.dy, error.dz, error.dtheta};
  double* half_widths[4] = {&reading.half_widths.dx, &reading.half_widths.dy,
                            &reading.half_widths.dz, &reading.half_widths.dtheta};
  double* sigmas[4] = {&reading.sigmas.dx, &reading.sigmas.dy, &reading.sigmas.dz,
                       &reading.sigmas.dtheta};
  for (int i = 0; i < 4; ++i) {
    const int v = components[i].is_variable() ? space_.index_of(components[i]) : -1;
    if (v < 0) return std::nullopt;
    const SpaceVariable& variable = space_.variables()[v];
    if (variable.provenance.source != UncertaintySource::kSensor ||
        variable.provenance.object != object)
      return std::nullopt;
    *half_widths[i] = std::max(-variable.lower, variable.upper);
    *sigmas[i] = variable.sigma;
  }
  return reading;
}

Propagation::Reading Propagation::fused(const Reading& earlier, const Reading& latest,
                                        int object) const {
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

std::vector<Precondition> Propagation::step(const Phase2Step& step, int index) {
  std::vector<Precondition> preconditions;
  const auto require_on_table = [&](int object) {
    if (object < 0 || !table_.at(object))
      throw PlanError(
          "step " + std::to_string(index) + " needs " +
          (object < 0 ? std::string("an object") : world_->scenario().objects[object].name) +
          " on the table");
  };
  switch (step.effect) {
    case StepEffect::kGrasp: {
      require_on_table(step.object);
      const PoseError arm = allocate_arm(index);
      preconditions = pickup_preconditions(step, arm, "pickup");
      held_[step.object] = HeldState{step.grasp, grip_after_grasp(step, arm)};
      table_[step.object].reset();
      break;
    }
    case StepEffect::kSqueeze: {
      require_on_table(step.object);
      const PoseError arm = allocate_arm(index);
      preconditions = pickup_preconditions(step, arm, "squeeze");
      Phase2Step in_place = step;
      in_place.object_pose = table_[step.object]->ideal;
      table_[step.object] = released(in_place, arm, grip_after_grasp(step, arm));
      break;
    }
    case StepEffect::kRelease: {
      if (!held_.at(step.object))
        throw PlanError("step " + std::to_string(index) + " puts down an object it does not hold");
      const PoseError arm = allocate_arm(index);
      table_[step.object] = released(step, arm, held_[step.object]->grip);
      held_[step.object].reset();
      break;
    }
    case StepEffect::kInsert: {
      if (!held_.at(step.object))
        throw PlanError("step " + std::to_string(index) + " inserts an object it does not hold");
      require_on_table(step.fixed_object);
      const PoseError arm = allocate_arm(index);
      preconditions = assemble_preconditions(step, arm);
      held_[step.object].reset();
      break;
    }
    case StepEffect::kRangeScan: {
      require_on_table(step.object);
      const RangeScanSensor sensor = world_->scenario().range_scan.value_or(RangeScanSensor{});
      const kinematics::PoseUncertainty& r = sensor.residual;
      const kinematics::PoseUncertainty s = sigmas(sensor.residual_model);
      Reading reading{{r.dx * sensor_scale_, r.dy * sensor_scale_, r.dz * sensor_scale_,
                       r.dtheta * sensor_scale_},
                      {s.dx * sensor_scale_, s.dy * sensor_scale_, s.dz * sensor_scale_,
                       s.dtheta * sensor_scale_}};
      if (const std::optional<Reading> earlier = unmoved_scan(step.object))
        reading = fused(*earlier, reading, step.object);
      table_[step.object]->error = space_.allocate(
          reading.half_widths,
          {.source = UncertaintySource::kSensor, .object = step.object, .step = index},
          world_->scenario().objects[step.object].name + "_s" + std::to_string(index),
          reading.sigmas);
      break;
    }
    case StepEffect::kNone:
      break;
  }
  return preconditions;
}

}  // namespace spar::planner
