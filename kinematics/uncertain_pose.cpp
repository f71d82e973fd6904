#include "spar/kinematics/uncertain_pose.hpp"

#include <cctype>
#include <vector>

namespace spar::kinematics {

using symbolic::Expr;
using symbolic::ExprPool;

namespace {

// R_O of T_O = Tr_O R_O.
Transform rotation_part(const Transform& pose) {
  Transform rotation = Transform::Identity();
  rotation.linear() = pose.linear();
  return rotation;
}

}  // namespace

PoseUncertaintyVariables::PoseUncertaintyVariables(ExprPool& pool, const PoseUncertainty& bounds,
                                                   std::string_view tag) {
  if (tag.empty()) throw KinematicsError("uncertainty variables need a non-empty tag");
  for (const char c : tag) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') {
      throw KinematicsError("uncertainty tag '" + std::string(tag) +
                            "' may only contain letters, digits and '_'");
    }
  }
  const char* const prefixes[] = {"dx_", "dy_", "dz_", "dtheta_"};
  const double half_widths[] = {bounds.dx, bounds.dy, bounds.dz, bounds.dtheta};
  for (int i = 0; i < 4; ++i) {
    const std::string name = prefixes[i] + std::string(tag);
    if (!(half_widths[i] >= 0.0)) {
      throw KinematicsError("uncertainty bound of " + name + " must be >= 0, got " +
                            std::to_string(half_widths[i]));
    }
    symbols_[i] = pool.variable(name);
    variables_[i] = {name, -half_widths[i], half_widths[i]};
  }
}

UncertainManipulator::UncertainManipulator(ExprPool& pool, const PoseUncertainty& bounds,
                                           std::string_view tag)
    : PoseUncertaintyVariables(pool, bounds, tag),
      error_(manipulator_error_transform(pose_error())) {}

SymbolicTransform UncertainManipulator::possible_pose(const Transform& ideal) const {
  return SymbolicTransform::from_numeric(error_.pool(), ideal) * error_;
}

SymbolicTransform UncertainObject::possible_pose(const Transform& ideal) const {
  return possible_object_pose(ideal, pose_error());
}

SymbolicPoint UncertainObject::possible_point(const Transform& ideal,
                                              const SymbolicPoint& local_point) const {
  ExprPool& pool = dx().pool();
  const Eigen::Vector3d& t = ideal.translation();
  // R_O p folds to constants with sound enclosures (Number arithmetic), never a rounded double.
  const SymbolicPoint turned = rotz(dtheta()).apply(
      SymbolicTransform::from_numeric(pool, rotation_part(ideal)).apply(local_point));
  return trans(dx() + t.x(), dy() + t.y(), dz() + t.z()).apply(turned);
}

SymbolicPoint UncertainObject::possible_point_in(const SymbolicTransform& frame,
                                                 const Transform& ideal,
                                                 const SymbolicPoint& local_point) const {
  return possible_object_point_in(frame, ideal, local_point, pose_error());
}

SymbolicTransform manipulator_error_transform(const PoseError& error) {
  return trans(error.dx, error.dy, error.dz) * rotz(error.dtheta);
}

SymbolicTransform possible_object_pose(const Transform& ideal, const PoseError& error) {
  ExprPool& pool = error.dx.pool();
  const Eigen::Vector3d& t = ideal.translation();
  return trans(error.dx, error.dy, error.dz) * trans(pool, t.x(), t.y(), t.z()) *
         rotz(error.dtheta) * SymbolicTransform::from_numeric(pool, rotation_part(ideal));
}

SymbolicPoint possible_object_point_in(const SymbolicTransform& frame, const Transform& ideal,
                                       const SymbolicPoint& local_point, const PoseError& error) {
  using symbolic::Number;
  ExprPool& pool = error.dx.pool();
  const auto constant_of = [](Expr e, const char* what) -> const Number& {
    if (!e.is_constant()) {
      throw KinematicsError(std::string("possible_point_in: ") + what +
                            " must have constant entries");
    }
    return e.constant();
  };
  // p = R_O local_point and the translations, as Numbers.
  std::array<Number, 3> p, offset;
  for (int row = 0; row < 3; ++row) {
    for (int k = 0; k < 3; ++k) {
      p[row] = p[row] + Number::real(ideal.linear()(row, k)) *
                            constant_of(local_point[k], "the local point");
    }
    offset[row] =
        Number::real(ideal.translation()(row)) - constant_of(frame.translation()[row], "the frame");
  }
  // C = (Δx + c p_x - s p_y, Δy + s p_x + c p_y, Δz + p_z) + t_O;  result = R_F^T (C - t_F).
  const Expr atoms[5] = {error.dx, error.dy, error.dz, cos(error.dtheta), sin(error.dtheta)};
  SymbolicPoint result;
  for (int row = 0; row < 3; ++row) {
    std::array<Number, 3> a;  // column `row` of R_F
    for (int k = 0; k < 3; ++k) a[k] = constant_of(frame.rotation(k, row), "the frame");
    const Number coefficients[5] = {a[0], a[1], a[2], a[0] * p[0] + a[1] * p[1],
                                    a[1] * p[0] - a[0] * p[1]};
    std::vector<Expr> terms;
    terms.push_back(pool.constant(a[0] * offset[0] + a[1] * offset[1] + a[2] * (offset[2] + p[2])));
    for (int k = 0; k < 5; ++k) {
      if (!coefficients[k].is_zero()) terms.push_back(pool.constant(coefficients[k]) * atoms[k]);
    }
    result[row] = pool.sum(terms);
  }
  return result;
}

UncertainObject::UncertainObject(ExprPool& pool, const PoseUncertainty& bounds,
                                 std::string_view tag)
    : PoseUncertaintyVariables(pool, bounds, tag) {}

}  // namespace spar::kinematics
