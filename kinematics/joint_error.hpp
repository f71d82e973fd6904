// The arm's pose error from per-joint errors: how much the gripper frame moves when every joint
// of a RobotModel is off by a small δq_i (an encoder or calibration error), as a symbolic rigid
// transform over the δq_i (beyond SPAR, whose arm error is dx, dy, dz, dθ at the gripper).
//
// At the joint vector q (the IK solution of a step), the actual gripper pose is
//     G(q + δq) = G(q) ΔT(δq),   G(q) = FK(q) tool,
// so ΔT = G(q)^-1 G(q + δq), in the gripper's own frame like SPAR's T_ΔM (eq. 1). It is built as
//     ΔT = C_0 J_1(δq_1) C_1 J_2(δq_2) ... J_n(δq_n) C_n,
// with J_i = rotz(δq_i) (revolute) or trans(0, 0, δq_i) (prismatic) in a frame whose z axis is
// joint i's axis, and the C_k numeric: the folded numbers of the chain at q (joint origins, the
// motions by q_i, the tool), so each factor adds one symbolic rotation or translation.
//
// Invariants: ΔT evaluates to the identity at δq = 0 up to the rounding of the folded numbers
// (~1e-16), and to G(q)^-1 G(q + δq) at any δq (exact kinematics, no small-angle step); its
// rotation is orthonormal for every δq (built from rotz, translations and numeric rigid poses).
// Cost: n symbolic products of 3x4 entries; O(n) DAG nodes per entry, shared across entries.
//
// Example:
//   symbolic::ExprPool pool;
//   const RobotModel ur5 = builtin_robot_model("ur5");
//   std::vector<symbolic::Expr> dq;
//   for (int i = 1; i <= 6; ++i) dq.push_back(pool.variable("dq" + std::to_string(i)));
//   const SymbolicTransform error = joint_error_transform(ur5, q, Transform::Identity(), dq);
#pragma once

#include <span>

#include "spar/kinematics/robot.hpp"
#include "spar/kinematics/symbolic_transform.hpp"

namespace spar::kinematics {

// ΔT(δq) above for the gripper frame G = FK(q) tool. Throws KinematicsError unless q and dq both
// have robot.dof() entries (q finite) and the dq share one pool.
[[nodiscard]] SymbolicTransform joint_error_transform(const RobotModel& robot,
                                                      std::span<const double> q,
                                                      const Transform& tool,
                                                      std::span<const symbolic::Expr> dq);

}  // namespace spar::kinematics
