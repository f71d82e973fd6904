// Symbolic forward kinematics of a DH chain, with joint-offset uncertainty variables.
//
// The link transform of kinematics/dh.hpp, over expressions:
//     A_i = rotz(theta_i) trans(a_i, 0, d_i) rotx(alpha_i),   theta_i = joint_i + offset_i,
// and T = A_1 ... A_n composed structurally (see symbolic_transform.hpp). A twist alpha that is a
// multiple of 90 degrees (as in the Puma tables) is taken as the exact quarter turn, so its zero
// entries are exact and skipped; any other alpha enters as cos/sin of the constant.
//
// uncertain_forward() uses joint_i = q_i + δq_i with one bounded variable δq_i per joint (an
// encoder / calibration offset), so the end-effector pose error can be bounded over the box.
//
// Example:
//   ExprPool pool;
//   const UncertainChainPose flange = uncertain_forward(pool, puma560(), q, {1e-3, 1e-3, 1e-3,
//                                                                             1e-3, 1e-3, 1e-3});
//   Expr x = flange.pose.translation()[0];                  // x of the flange, in q + δq
//   Transform at_q = flange.pose.evaluate({{"dq1", 0}, ...});  // == puma560().forward(q)
#pragma once

#include <span>
#include <string>
#include <vector>

#include "spar/kinematics/uncertain_pose.hpp"

namespace spar::kinematics {

// T(joints) for symbolic joint values. Throws KinematicsError if joints.size() != chain.size() or
// the joints belong to different pools.
[[nodiscard]] SymbolicTransform symbolic_forward(const DhChain& chain,
                                                 std::span<const symbolic::Expr> joints);

struct UncertainChainPose {
  SymbolicTransform pose;                      // T(q + δq)
  std::vector<UncertaintyVariable> variables;  // dq1 .. dqn, δq_i in [-half_width_i, half_width_i]
};

// Throws KinematicsError on a count mismatch or a negative half-width.
[[nodiscard]] UncertainChainPose uncertain_forward(symbolic::ExprPool& pool, const DhChain& chain,
                                                   std::span<const double> q,
                                                   std::span<const double> offset_half_widths);

}  // namespace spar::kinematics
