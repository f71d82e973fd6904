#include "spar/kinematics/pickup.hpp"

#include <numbers>

#include "spar/kinematics/internal/pickup_shared.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/smp.hpp"

namespace spar::kinematics {

using symbolic::Expr;
using symbolic::ExprPool;

void internal::check_pickup_geometry(const PickupGeometry& geometry) {
  if (!(geometry.finger_opening > 0.0) || !(geometry.object_width > 0.0)) {
    throw KinematicsError("pickup: finger opening and object width must be > 0 (got " +
                          std::to_string(geometry.finger_opening) + " and " +
                          std::to_string(geometry.object_width) + ")");
  }
}

std::array<PickupCondition, 4> internal::conditions_from_contacts(
    const std::array<SymbolicPoint, 2>& in_ideal, const SymbolicTransform& manipulator_error,
    const std::array<SymbolicTransform, 2>& finger_offsets) {
  ExprPool& pool = manipulator_error.rotation(0, 0).pool();
  // T_ΔM^-1 (T_O T_G)^-1 C per contact; the finger offsets only shift its y coordinate, so x and
  // y are all that is built of it.
  std::array<SymbolicPoint, 2> in_gripper;
  for (int contact = 0; contact < 2; ++contact) {
    for (int row = 0; row < 2; ++row) {
      in_gripper[contact][row] = manipulator_error.apply_inverse_coordinate(in_ideal[contact], row);
    }
    in_gripper[contact][2] = pool.integer(0);  // z: not needed for [0,1,0,0]
  }
  std::array<PickupCondition, 4> conditions;
  for (int finger = 0; finger < 2; ++finger) {
    for (int contact = 0; contact < 2; ++contact) {
      const bool positive = finger == 0;
      conditions[finger * 2 + contact] = {
          std::string(positive ? "0 < " : "0 > ") + "[0,1,0,0] P" + std::to_string(finger + 1) +
              "^-1 C" + std::to_string(contact + 1),
          finger_offsets[finger].apply_inverse_coordinate(in_gripper[contact], 1), positive};
    }
  }
  return conditions;
}

bool PickupCondition::holds_at(const std::map<std::string, double>& values) const {
  const double value = symbolic::evaluate(expression, values);
  return positive ? value > 0.0 : value < 0.0;
}

namespace {

// The four conditions; `manipulator_error()` makes T_ΔM, called where eq. 1's form always built
// it (after the ideal gripper's numbers), so that form keeps its expressions node for node.
template <class MakeError>
std::array<PickupCondition, 4> conditions_over(const PickupGeometry& geometry, ExprPool& pool,
                                               const PoseError& object,
                                               const PickupOptions& options,
                                               MakeError&& manipulator_error_of) {
  internal::check_pickup_geometry(geometry);
  if (&object.dx.pool() != &pool) {
    throw KinematicsError("pickup: gripper and object uncertainties use different pools");
  }
  const SymbolicTransform object_pose = SymbolicTransform::from_numeric(pool, geometry.object_pose);
  const SymbolicTransform grasp = SymbolicTransform::from_numeric(pool, geometry.grasp);
  const SymbolicTransform ideal_gripper = object_pose * grasp;  // constants: folds to numbers
  const SymbolicTransform manipulator_error = manipulator_error_of();

  const double half_opening = geometry.finger_opening / 2, half_width = geometry.object_width / 2;
  const SymbolicPoint contacts[2] = {grasp.apply(constant_point(pool, 0, +half_width, 0)),
                                     grasp.apply(constant_point(pool, 0, -half_width, 0))};
  const std::array<SymbolicTransform, 2> finger_offsets = {trans(pool, 0, -half_opening, 0),
                                                           trans(pool, 0, +half_opening, 0)};
  std::array<SymbolicPoint, 2> in_ideal;
  for (int contact = 0; contact < 2; ++contact) {
    in_ideal[contact] =
        possible_object_point_in(ideal_gripper, geometry.object_pose, contacts[contact], object);
  }
  std::array<PickupCondition, 4> conditions =
      internal::conditions_from_contacts(in_ideal, manipulator_error, finger_offsets);
  if (options.simplify) {
    symbolic::SimplifyOptions simplify_options;
    for (const auto& [name, width] : options.widths) simplify_options.widths[name] = width;
    for (PickupCondition& c : conditions)
      c.expression = symbolic::simplify(c.expression, simplify_options);
  }
  return conditions;
}

}  // namespace

std::array<PickupCondition, 4> pickup_conditions(const PickupGeometry& geometry,
                                                 const PoseError& manipulator,
                                                 const PoseError& object,
                                                 const PickupOptions& options) {
  return conditions_over(geometry, manipulator.dx.pool(), object, options,
                         [&] { return manipulator_error_transform(manipulator); });
}

std::array<PickupCondition, 4> pickup_conditions(const PickupGeometry& geometry,
                                                 const SymbolicTransform& manipulator_error,
                                                 const PoseError& object,
                                                 const PickupOptions& options) {
  return conditions_over(geometry, manipulator_error.pool(), object, options,
                         [&] { return manipulator_error; });
}

PickupPreconditions pickup_preconditions(const PickupGeometry& geometry,
                                         const UncertainManipulator& gripper,
                                         const UncertainObject& object,
                                         const PickupOptions& options) {
  PickupPreconditions result;
  for (const UncertaintyVariable& v : gripper.variables()) result.variables.push_back(v);
  for (const UncertaintyVariable& v : object.variables()) result.variables.push_back(v);
  PickupOptions with_widths = options;
  for (const UncertaintyVariable& v : result.variables)
    with_widths.widths[v.name] = v.upper - v.lower;
  result.conditions =
      pickup_conditions(geometry, gripper.pose_error(), object.pose_error(), with_widths);
  return result;
}

PickupGeometry peg_pickup_example() {
  constexpr double in = units::kInch;
  PickupGeometry geometry;
  geometry.object_pose = Eigen::Translation3d(20 * in, 10 * in, 0.75 * in) *
                         Eigen::AngleAxisd(30 * units::kDegree, Eigen::Vector3d::UnitZ());
  geometry.grasp = Eigen::Translation3d(1 * in, 0, 1.5 * in) *
                   Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());
  geometry.finger_opening = 4 * in;
  geometry.object_width = 3 * in;
  return geometry;
}

}  // namespace spar::kinematics
