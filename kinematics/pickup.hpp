// SPAR's uncertainty-reduction preconditions of the pickup action: both contact points lie between
// the fingers for every value of the uncertainty variables.
//
// With the ideal object pose T_O, the grasp T_G (gripper frame in the object frame, fingers
// opening along its y axis), the finger opening W_m and the object's width at the grasp W_g:
//   finger frames   P1,2 = T_O T_G T_ΔM trans(0, ∓W_m/2, 0)                       (eq. 1)
//   contact points  C1,2 = Tr_ΔO Tr_O R_ΔO R_O T_G trans(0, ±W_g/2, 0) [0,0,0,1]^T   (eq. 2)
//   conditions      0 < [0,1,0,0] P1^-1 C1,   0 < [0,1,0,0] P1^-1 C2,
//                   0 > [0,1,0,0] P2^-1 C1,   0 > [0,1,0,0] P2^-1 C2.
// P^-1 C is formed right to left as rigid inverses applied to the point:
//   trans(0, ∓W_m/2, 0)^-1 (T_ΔM^-1 ((T_O T_G)^-1 C)),
// where (T_O T_G)^-1 C is UncertainObject::possible_point_in: one flat sum per coordinate,
// q = a·Δx_o + b·Δy_o + c·Δz_o + d·cos Δθ_o + e·sin Δθ_o + f, the numbers folded soundly. R_ΔO
// enters once, through q, never as R_ΔO^T R_ΔO. Only the y row of the last two inverses is built:
//   ±W_m/2 + cos Δθ_g (q_y - Δy_g) - sin Δθ_g (q_x - Δx_g)
// (35 nodes for the paper's example, 50 for all four together; Δθ_g occurs twice, the object's
// variables once in each of q_x, q_y. In inches q_y's constant happened to cancel to an exact 0,
// 34 / 48 nodes; in metres it keeps a rounding residue of 3e-17 m, one more node each).
//
// Example:
//   ExprPool pool;
//   const UncertainManipulator gripper(pool, kTable2Gripper);  // metres, radians
//   const UncertainObject peg(pool, kTable2Object);
//   const PickupPreconditions pre = pickup_preconditions(
//       {.object_pose = t_o, .grasp = t_g, .finger_opening = 0.1016, .object_width = 0.0762},
//       gripper, peg);
//   for (const PickupCondition& c : pre.conditions) std::cout << c.name << ' ' << c.positive;
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "spar/common/units.hpp"
#include "spar/kinematics/uncertain_pose.hpp"

namespace spar::kinematics {

struct PickupGeometry {
  Transform object_pose{Transform::Identity()};  // T_O, ideal
  Transform grasp{Transform::Identity()};        // T_G, gripper frame relative to the object frame
  double finger_opening{0.0};                    // W_m, distance between the open fingers
  double object_width{0.0};                      // W_g, object width between the contact points
};

// One inequality: `expression` > 0 when `positive`, else `expression` < 0.
struct PickupCondition {
  std::string name;  // e.g. "0 < [0,1,0,0] P1^-1 C1"
  symbolic::Expr expression;
  bool positive{true};
  // Whether the inequality holds at one point (every variable of the expression needs a value).
  [[nodiscard]] bool holds_at(const std::map<std::string, double>& values) const;
};

struct PickupPreconditions {
  std::array<PickupCondition, 4> conditions;   // P1·C1, P1·C2, P2·C1, P2·C2 as in the header
  std::vector<UncertaintyVariable> variables;  // gripper's four, then the object's four
};

struct PickupOptions {
  // Run SMP (symbolic/smp.hpp) on each expression with the box widths. Off by default: on these
  // expressions it finds nothing to improve (same 35 nodes, same occurrence cost, measured): the
  // remaining repeats (q_x and q_y both hold the object's variables) are those of the function.
  bool simplify{false};
  // Box width of every variable (by name), which SMP weighs occurrences by.
  std::map<std::string, double> widths;
};

// Throws KinematicsError unless 0 < object_width and 0 < finger_opening. Both uncertainties must
// use the same pool.
[[nodiscard]] PickupPreconditions pickup_preconditions(const PickupGeometry& geometry,
                                                       const UncertainManipulator& gripper,
                                                       const UncertainObject& object,
                                                       const PickupOptions& options = {});

// The same four conditions over pose errors given as expressions (a planner's phase 2 propagates
// them through a plan): `manipulator` is T_ΔM of the pickup (eq. 1), `object` the object's error
// just before it (eq. 2 form, world displacement and rotation about world z). All expressions must
// share one pool. Throws KinematicsError like pickup_preconditions.
[[nodiscard]] std::array<PickupCondition, 4> pickup_conditions(const PickupGeometry& geometry,
                                                               const PoseError& manipulator,
                                                               const PoseError& object,
                                                               const PickupOptions& options = {});
// The same with the manipulator's error T_ΔM given as any rigid transform (e.g. one that joint
// errors make, kinematics/joint_error.hpp, tilting the fingers too): the conditions stay exact.
[[nodiscard]] std::array<PickupCondition, 4> pickup_conditions(
    const PickupGeometry& geometry, const SymbolicTransform& manipulator_error,
    const PoseError& object, const PickupOptions& options = {});

// The worked example of SPAR's paper (peg and block), used by `spar demo`, the tests and the
// benchmark, in metres and radians (the paper's inch and degree values converted exactly).
// Table 2's bounds: gripper Δx, Δy, Δz ±0.001 in and Δθ_g ±0.001 rad; object Δx, Δy, Δz ±0.11 in
// and Δθ_o ±5.5 degrees. The paper gives W_p = 3 in and W_m = 4 in but not the poses; ours: the
// peg lies at (20, 10, 0.75) in, turned 30 degrees about z, and the gripper comes from above
// (z down) 1 in along the peg from its origin, fingers across the peg's width.
inline constexpr PoseUncertainty kTable2Gripper{0.001 * units::kInch, 0.001 * units::kInch,
                                                0.001 * units::kInch, 0.001};
inline constexpr PoseUncertainty kTable2Object{0.11 * units::kInch, 0.11 * units::kInch,
                                               0.11 * units::kInch, 5.5 * units::kDegree};
[[nodiscard]] PickupGeometry peg_pickup_example();

}  // namespace spar::kinematics
