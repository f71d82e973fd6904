// SPAR's uncertain poses: ideal poses composed with transforms over bounded uncertainty variables.
//
// Manipulator (eq. 1 of SPAR): the error is relative to the manipulator's own frame,
//     T_M+Δ = T_M T_ΔM,   T_ΔM = trans(Δx_g, Δy_g, Δz_g) rotz(Δθ_g).
// Object resting on the table (eq. 2): displacement error in world coordinates and a rotation
// about the world z axis through the object's origin,
//     T_O+Δ = Tr_ΔO Tr_O R_ΔO R_O,   Tr_ΔO = trans(Δx_o, Δy_o, Δz_o),  R_ΔO = rotz(Δθ_o),
// where Tr_O and R_O are the translation and rotation of the ideal pose T_O = Tr_O R_O.
// Each variable is a named symbolic variable with its bounds, so a planner can build a box.
//
// Example:
//   ExprPool pool;
//   const UncertainManipulator gripper(pool, {.dx = 0.001, .dy = 0.001, .dz = 0.001,
//                                             .dtheta = 0.001}, "g");
//   const SymbolicTransform possible = gripper.possible_pose(ideal_gripper_pose);  // T_M T_ΔM
//   for (const UncertaintyVariable& v : gripper.variables()) box.push_back({v.lower, v.upper});
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "spar/kinematics/symbolic_transform.hpp"

namespace spar::kinematics {

// A named uncertainty variable and its bounds: lower <= value <= upper.
struct UncertaintyVariable {
  std::string name;
  double lower{0.0};
  double upper{0.0};
};

// Symmetric half-widths of a pose's uncertainty: Δx in [-dx, dx], ..., Δθ in [-dtheta, dtheta]
// (radians). All must be >= 0.
struct PoseUncertainty {
  double dx{0.0};
  double dy{0.0};
  double dz{0.0};
  double dtheta{0.0};
};

// A pose error as a value: four expressions over any uncertainty variables (a planner's space
// allocates them, and propagation through actions makes them expressions of earlier ones).
//   manipulator (eq. 1): T_ΔM = trans(dx, dy, dz) rotz(dtheta), in the manipulator's own frame;
//   object (eq. 2): displacement (dx, dy, dz) in world coordinates and dtheta about world z
//   through the object's origin: T_O+Δ = trans(dx, dy, dz) Tr_O rotz(dtheta) R_O.
struct PoseError {
  symbolic::Expr dx, dy, dz, dtheta;
};

// The four variables Δx, Δy, Δz, Δθ of one pose, named dx_<tag>, dy_<tag>, dz_<tag>,
// dtheta_<tag> (SPAR's dxgr / dx_o); throws KinematicsError on a negative half-width or a tag
// that does not make an identifier.
class PoseUncertaintyVariables {
 public:
  PoseUncertaintyVariables(symbolic::ExprPool& pool, const PoseUncertainty& bounds,
                           std::string_view tag);

  [[nodiscard]] symbolic::Expr dx() const { return symbols_[0]; }
  [[nodiscard]] symbolic::Expr dy() const { return symbols_[1]; }
  [[nodiscard]] symbolic::Expr dz() const { return symbols_[2]; }
  [[nodiscard]] symbolic::Expr dtheta() const { return symbols_[3]; }
  [[nodiscard]] const std::array<UncertaintyVariable, 4>& variables() const { return variables_; }
  [[nodiscard]] PoseError pose_error() const { return {dx(), dy(), dz(), dtheta()}; }

 private:
  std::array<symbolic::Expr, 4>
      symbols_;  // dx, dy, dz, dtheta; variables_[i] describes symbols_[i]
  std::array<UncertaintyVariable, 4> variables_;
};

// trans(dx, dy, dz) rotz(dtheta).
[[nodiscard]] SymbolicTransform manipulator_error_transform(const PoseError& error);
// trans(dx, dy, dz) Tr_O rotz(dtheta) R_O for the ideal pose T_O = Tr_O R_O.
[[nodiscard]] SymbolicTransform possible_object_pose(const Transform& ideal,
                                                     const PoseError& error);
// frame^-1 T_O+Δ p as ONE flat sum per coordinate (see UncertainObject::possible_point_in); `frame`
// and `local_point` must have constant entries (throws KinematicsError otherwise).
[[nodiscard]] SymbolicPoint possible_object_point_in(const SymbolicTransform& frame,
                                                     const Transform& ideal,
                                                     const SymbolicPoint& local_point,
                                                     const PoseError& error);

// Manipulator uncertainty, eq. 1.
class UncertainManipulator : public PoseUncertaintyVariables {
 public:
  UncertainManipulator(symbolic::ExprPool& pool, const PoseUncertainty& bounds,
                       std::string_view tag = "g");
  // T_ΔM = trans(Δx, Δy, Δz) rotz(Δθ).
  [[nodiscard]] const SymbolicTransform& error() const { return error_; }
  // T_M T_ΔM.
  [[nodiscard]] SymbolicTransform possible_pose(const Transform& ideal) const;

 private:
  SymbolicTransform error_;
};

// Object uncertainty, eq. 2.
class UncertainObject : public PoseUncertaintyVariables {
 public:
  UncertainObject(symbolic::ExprPool& pool, const PoseUncertainty& bounds,
                  std::string_view tag = "o");
  // Tr_ΔO Tr_O R_ΔO R_O.
  [[nodiscard]] SymbolicTransform possible_pose(const Transform& ideal) const;
  // Tr_ΔO Tr_O R_ΔO R_O p for a point p in the object's frame, formed right to left
  // (R_O p is a number, then one rotation about z, then the translations), so each coordinate is
  // a flat sum linear in cos Δθ, sin Δθ, Δx, Δy, Δz.
  [[nodiscard]] SymbolicPoint possible_point(const Transform& ideal,
                                             const SymbolicPoint& local_point) const;
  // frame^-1 Tr_ΔO Tr_O R_ΔO R_O p: the possible point expressed in a known frame (the ideal
  // gripper T_O T_G for the pickup conditions). `frame` and `local_point` must have constant
  // entries (throws KinematicsError otherwise). Each coordinate is built as ONE flat sum
  //   a·Δx + b·Δy + c·Δz + d·cos Δθ + e·sin Δθ + f,
  // the numeric parts (R_F^T, R_O p, t_O - t_F) folded into a..f with Number arithmetic (sound
  // enclosures, as SymbolicTransform folds constants). Expression construction never combines
  // real constants, so composing the same thing as transforms leaves real-coefficient-times-sum
  // terms nested and every object variable repeated; here each occurs once per coordinate, and
  // R_ΔO meets no transpose of itself.
  [[nodiscard]] SymbolicPoint possible_point_in(const SymbolicTransform& frame,
                                                const Transform& ideal,
                                                const SymbolicPoint& local_point) const;
};

}  // namespace spar::kinematics
