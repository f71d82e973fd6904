#include "spar/kinematics/symbolic_dh.hpp"

#include <cmath>
#include <numbers>

namespace spar::kinematics {

using symbolic::Expr;
using symbolic::ExprPool;

namespace {

// rotx(alpha) with exact entries when alpha is a multiple of 90 degrees (to double precision).
SymbolicTransform twist(ExprPool& pool, double alpha) {
  const double quarter_turns = alpha / (std::numbers::pi / 2);
  const double nearest = std::round(quarter_turns);
  if (std::abs(quarter_turns - nearest) > 1e-12) return rotx(pool.constant(alpha));
  const int turn = ((static_cast<int>(nearest) % 4) + 4) % 4;
  const int cosine[] = {1, 0, -1, 0}, sine[] = {0, 1, 0, -1};
  const Expr zero = pool.integer(0), one = pool.integer(1);
  const Expr c = pool.integer(cosine[turn]), s = pool.integer(sine[turn]);
  return SymbolicTransform(pool, {one, zero, zero, zero, c, -s, zero, s, c}, {zero, zero, zero});
}

}  // namespace

SymbolicTransform symbolic_forward(const DhChain& chain, std::span<const Expr> joints) {
  if (joints.size() != chain.size()) {
    throw KinematicsError("symbolic_forward: " + chain.name() + " has " +
                          std::to_string(chain.size()) + " joints, got " +
                          std::to_string(joints.size()) + " joint values");
  }
  ExprPool& pool = joints.front().pool();
  SymbolicTransform pose(pool);
  for (std::size_t i = 0; i < joints.size(); ++i) {
    if (&joints[i].pool() != &pool) {
      throw KinematicsError("symbolic_forward: joint values from different pools");
    }
    const DhJoint& joint = chain.joint(i);
    pose = pose * rotz(joints[i] + joint.offset) * trans(pool, joint.a, 0, joint.d) *
           twist(pool, joint.alpha);
  }
  return pose;
}

UncertainChainPose uncertain_forward(ExprPool& pool, const DhChain& chain,
                                     std::span<const double> q,
                                     std::span<const double> offset_half_widths) {
  if (q.size() != chain.size() || offset_half_widths.size() != chain.size()) {
    throw KinematicsError("uncertain_forward: " + chain.name() + " has " +
                          std::to_string(chain.size()) + " joints, got " +
                          std::to_string(q.size()) + " joint values and " +
                          std::to_string(offset_half_widths.size()) + " offset bounds");
  }
  std::vector<UncertaintyVariable> variables;
  std::vector<Expr> joints;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const std::string name = "dq" + std::to_string(i + 1);
    if (!(offset_half_widths[i] >= 0.0)) {
      throw KinematicsError("uncertain_forward: bound of " + name + " must be >= 0");
    }
    variables.push_back({name, -offset_half_widths[i], offset_half_widths[i]});
    joints.push_back(pool.variable(name) + q[i]);
  }
  return {symbolic_forward(chain, joints), std::move(variables)};
}

}  // namespace spar::kinematics
