#include "spar/planner/uncertainty/builders.hpp"

#include <cmath>

#include "spar/kinematics/pickup.hpp"
#include "spar/planner/error.hpp"

namespace spar::planner {
namespace {

using kinematics::constant_point;
using kinematics::SymbolicPoint;
using kinematics::SymbolicTransform;
using kinematics::Transform;
using symbolic::Expr;

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

// The fixed object's actual frame: a world point X in it is R_O^T rotz(-θ) (X - t_O - d). The
// rotation is built once, when the frame is (its nodes come first in the pool: the printed form
// of later expressions follows the pool's order).
class FixedFrame {
 public:
  explicit FixedFrame(const TableState& fixed)
      : fixed_(fixed),
        rotation_(kinematics::rotz(fixed.error.dtheta) *
                  SymbolicTransform::from_numeric(fixed.error.dx.pool(),
                                                  Transform(fixed.ideal.linear()))) {}
  [[nodiscard]] SymbolicPoint operator()(const SymbolicPoint& world_point) const {
    const Eigen::Vector3d& t = fixed_.ideal.translation();
    const SymbolicPoint shifted = {world_point[0] - fixed_.error.dx - t.x(),
                                   world_point[1] - fixed_.error.dy - t.y(),
                                   world_point[2] - fixed_.error.dz - t.z()};
    return rotation_.apply_inverse(shifted);
  }

 private:
  const TableState& fixed_;
  SymbolicTransform rotation_;
};

}  // namespace

SymbolicTransform ArmError::transform() const {
  const SymbolicTransform eq1 = kinematics::manipulator_error_transform(pose);
  return joints ? *joints * eq1 : eq1;
}

Expr ArmError::yaw() const {
  if (!joints) return pose.dtheta;
  const SymbolicTransform error = transform();
  return atan2(error.rotation(1, 0), error.rotation(0, 0));
}

SymbolicPoint held_point(const WorldModel& world, const Phase2Step& step, const ArmError& arm,
                         const SymbolicTransform& grip, const Eigen::Vector3d& local) {
  // No transform product is built: each coordinate stays a short sum.
  symbolic::ExprPool& pool = arm.pose.dx.pool();
  const Transform& grasp = world.object(step.object).grasps[step.grasp].gripper_in_object;
  const SymbolicPoint in_grasp =
      grip.apply(constant_point(pool, grasp.inverse(Eigen::Isometry) * local));
  const SymbolicPoint in_ideal = arm.transform().apply(in_grasp);
  return SymbolicTransform::from_numeric(pool, step.object_pose * grasp).apply(in_ideal);
}

std::vector<Precondition> pickup_preconditions(const WorldModel& world, const Phase2Step& step,
                                               const TableState& state, const ArmError& arm,
                                               Builder kind) {
  const geometry::Grasp& grasp = world.object(step.object).grasps[step.grasp];
  const kinematics::PickupGeometry geometry{.object_pose = state.ideal,
                                            .grasp = grasp.gripper_in_object,
                                            .finger_opening = world.gripper().max_opening,
                                            .object_width = grasp.width};
  std::vector<Precondition> out;
  // Without joints, eq. 1's four as SPAR (the pickup header's expressions, unchanged).
  const std::array<kinematics::PickupCondition, 4> conditions =
      arm.joints ? kinematics::pickup_conditions(geometry, arm.transform(), state.error)
                 : kinematics::pickup_conditions(geometry, arm.pose, state.error);
  for (const kinematics::PickupCondition& condition : conditions)
    out.push_back(
        {kind,
         {condition.name, condition.expression,
          condition.positive ? bounds::Relation::kGreater : bounds::Relation::kLess, 0.0}});
  return out;
}

std::vector<Precondition> assemble_preconditions(const WorldModel& world, const Phase2Step& step,
                                                 const HeldState& held, const TableState& fixed,
                                                 const ArmError& arm) {
  const GoalWorld* tables = world.goal(step.object, step.fixed_object);
  if (tables == nullptr) throw PlanError("internal: an insertion no goal names");
  const AssembledGoal& goal =
      std::get<AssembledGoal>(world.scenario().goals[tables - world.goals().data()]);
  const FixedFrame in_fixed(fixed);
  const Eigen::Vector3d mating_point =
      faces_centroid(world.scenario().objects[step.object].model, goal.held_faces);
  const Eigen::Vector3d ideal_point = goal.relative * mating_point;
  const SymbolicPoint actual_point =
      in_fixed(held_point(world, step, arm, held.grip, mating_point));
  const SymbolicPoint offset = {actual_point[0] - ideal_point.x(),
                                actual_point[1] - ideal_point.y(),
                                actual_point[2] - ideal_point.z()};
  const Eigen::Vector3d v = goal.mating_vector.normalized();
  const Eigen::Vector3d u1 = v.unitOrthogonal(), u2 = v.cross(u1);
  std::vector<Precondition> out;
  const Expr along[2] = {dot(offset, u1), dot(offset, u2)};
  for (int axis = 0; axis < 2; ++axis) {
    const std::string name =
        "offset along u" + std::to_string(axis + 1) + " (perpendicular to the mating vector)";
    out.push_back(
        {Builder::kAssemble,
         {name + " <= clearance", along[axis], bounds::Relation::kLessEqual, goal.clearance}});
    out.push_back(
        {Builder::kAssemble,
         {name + " >= -clearance", along[axis], bounds::Relation::kGreaterEqual, -goal.clearance}});
  }
  if (goal.angular_clearance > 0) {
    const Eigen::Vector3d held_axis = goal.relative.linear().transpose() * v;
    const SymbolicPoint tip =
        in_fixed(held_point(world, step, arm, held.grip, mating_point + held_axis));
    const SymbolicPoint axis = {tip[0] - actual_point[0], tip[1] - actual_point[1],
                                tip[2] - actual_point[2]};
    out.push_back({Builder::kAssemble,
                   {"cos(misalignment) >= cos(angular clearance)", dot(axis, v),
                    bounds::Relation::kGreaterEqual, std::cos(goal.angular_clearance)},
                   /*length=*/false});
  }
  return out;
}

}  // namespace spar::planner
