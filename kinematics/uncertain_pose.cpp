#include "kinematics/uncertain_pose.hpp"

#include <cctype>

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
      error_(trans(dx(), dy(), dz()) * rotz(dtheta())) {}

SymbolicTransform UncertainManipulator::possible_pose(const Transform& ideal) const {
  return SymbolicTransform::from_numeric(error_.pool(), ideal) * error_;
}

SymbolicTransform UncertainObject::possible_pose(const Transform& ideal) const {
  ExprPool& pool = dx().pool();
  const Eigen::Vector3d& t = ideal.translation();
  return trans(dx(), dy(), dz()) * trans(pool, t.x(), t.y(), t.z()) * rotz(dtheta()) *
         SymbolicTransform::from_numeric(pool, rotation_part(ideal));
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

UncertainObject::UncertainObject(ExprPool& pool, const PoseUncertainty& bounds,
                                 std::string_view tag)
    : PoseUncertaintyVariables(pool, bounds, tag) {}

}  // namespace spar::kinematics
