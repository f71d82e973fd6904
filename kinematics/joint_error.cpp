#include "spar/kinematics/joint_error.hpp"

#include <string>

namespace spar::kinematics {
namespace {

// A rotation whose z axis is `axis` (a unit vector): the identity for +z, exact quarter or half
// turns for the other coordinate axes, otherwise the shortest rotation taking z to `axis`.
Eigen::Matrix3d frame_along(const Eigen::Vector3d& axis) {
  Eigen::Matrix3d frame;
  if (axis == Eigen::Vector3d::UnitZ()) return Eigen::Matrix3d::Identity();
  if (axis == -Eigen::Vector3d::UnitZ()) return Eigen::Vector3d(1, -1, -1).asDiagonal();
  if (axis.cwiseAbs() == Eigen::Vector3d::UnitX() || axis.cwiseAbs() == Eigen::Vector3d::UnitY()) {
    // Columns: x' = the coordinate axis after z (cyclic), y' = z' × x', z' = axis.
    const Eigen::Vector3d x = axis.cwiseAbs() == Eigen::Vector3d::UnitX()
                                  ? Eigen::Vector3d::UnitY()
                                  : Eigen::Vector3d::UnitZ();
    frame << x, axis.cross(x), axis;
    return frame;
  }
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix();
}

Transform rotation_only(const Eigen::Matrix3d& rotation) {
  Transform pose = Transform::Identity();
  pose.linear() = rotation;
  return pose;
}

}  // namespace

SymbolicTransform joint_error_transform(const RobotModel& robot, std::span<const double> q,
                                        const Transform& tool, std::span<const symbolic::Expr> dq) {
  if (dq.size() != robot.dof())
    throw KinematicsError("joint_error_transform: " + robot.name() + " has " +
                          std::to_string(robot.dof()) + " moving joints, got " +
                          std::to_string(dq.size()) + " joint errors");
  const Transform gripper = robot.forward(q) * tool;  // checks q
  symbolic::ExprPool& pool = dq.front().pool();
  const symbolic::Expr zero = pool.integer(0);
  // `folded` collects the numbers between two symbolic factors.
  Transform folded = gripper.inverse(Eigen::Isometry);
  SymbolicTransform error(pool);
  for (std::size_t i = 0; i < dq.size(); ++i) {
    if (&dq[i].pool() != &pool)
      throw KinematicsError("joint_error_transform: joint errors from different pools");
    const MovingJoint& joint = robot.joints()[i];
    const Transform along = rotation_only(frame_along(joint.axis));
    folded = folded * joint.origin * joint_motion(joint, q[i]) * along;
    const SymbolicTransform motion =
        joint.type == JointType::kPrismatic ? trans(zero, zero, dq[i]) : rotz(dq[i]);
    error = error * SymbolicTransform::from_numeric(pool, folded) * motion;
    folded = along.inverse(Eigen::Isometry);
  }
  return error * SymbolicTransform::from_numeric(pool, folded * robot.tip_offset() * tool);
}

}  // namespace spar::kinematics
