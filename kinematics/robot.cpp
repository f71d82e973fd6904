#include "spar/kinematics/robot.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "spar/kinematics/internal/chain.hpp"
#include "spar/kinematics/internal/ik_solver.hpp"

namespace spar::kinematics {
namespace {

[[noreturn]] void fail(const std::string& robot, const std::string& what) {
  throw KinematicsError("robot '" + robot + "': " + what);
}

void require_rigid(const std::string& robot, const RobotJoint& joint) {
  const Eigen::Matrix3d& rotation = joint.origin.linear();
  const bool finite = joint.origin.matrix().allFinite();
  if (!finite ||
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
          1e-6 ||
      rotation.determinant() < 0.0)
    fail(robot, "joint '" + joint.name + "' has an origin that is not a rigid transform");
}

}  // namespace

std::string_view to_string(JointType type) {
  switch (type) {
    case JointType::kRevolute:
      return "revolute";
    case JointType::kPrismatic:
      return "prismatic";
    case JointType::kFixed:
      return "fixed";
  }
  return "?";
}

std::string_view to_string(IkMethod method) {
  switch (method) {
    case IkMethod::kPumaClosedForm:
      return "closed form (Puma)";
    case IkMethod::kUrClosedForm:
      return "closed form (UR)";
    case IkMethod::kRedundantClosedForm:
      return "closed form over q7 (7 joints)";
    case IkMethod::kNumeric:
      return "numeric (Levenberg-Marquardt, random restarts)";
  }
  return "?";
}

Transform joint_motion(const MovingJoint& joint, double q) {
  Transform motion = Transform::Identity();
  if (joint.type == JointType::kPrismatic) {
    motion.translation() = q * joint.axis;
  } else {
    motion.linear() = Eigen::AngleAxisd(q, joint.axis).toRotationMatrix();
  }
  return motion;
}

RobotModel::RobotModel(RobotDescription description)
    : name_(std::move(description.name)),
      source_(std::move(description.source)),
      base_link_(std::move(description.base_link)),
      tip_link_(std::move(description.tip_link)) {
  // Where each link sits: its body and its frame in the body's frame.
  struct Placement {
    int body;
    Transform offset;
  };
  std::map<std::string, Placement> placement;
  std::vector<std::string> order;  // links of the arm, base first
  const auto place = [&](const std::string& link, Placement where) {
    if (!placement.emplace(link, where).second) fail(name_, "link '" + link + "' appears twice");
    order.push_back(link);
  };
  place(base_link_, {0, Transform::Identity()});
  std::string previous = base_link_;
  Transform pending = Transform::Identity();  // fixed joints since the last moving one
  for (const RobotJoint& joint : description.chain) {
    if (joint.parent_link != previous)
      fail(name_, "joint '" + joint.name + "' hangs from '" + joint.parent_link + "', not from '" +
                      previous + "': the joints do not form one chain from '" + base_link_ + "'");
    require_rigid(name_, joint);
    if (joint.type == JointType::kFixed) {
      pending = pending * joint.origin;
    } else {
      const double length = joint.axis.norm();
      if (!std::isfinite(length) || length < 1e-12)
        fail(name_, "joint '" + joint.name + "' has no axis direction");
      if (!(joint.limits.lower <= joint.limits.upper))
        fail(name_, "joint '" + joint.name + "' has its lower limit " +
                        std::to_string(joint.limits.lower) + " above its upper limit " +
                        std::to_string(joint.limits.upper));
      joints_.push_back({.name = joint.name,
                         .type = joint.type,
                         .origin = pending * joint.origin,
                         .axis = joint.axis / length,
                         .limits = joint.limits});
      pending = Transform::Identity();
    }
    place(joint.child_link, {static_cast<int>(joints_.size()), pending});
    previous = joint.child_link;
  }
  if (previous != tip_link_)
    fail(name_, "the chain from '" + base_link_ + "' ends at '" + previous + "', not at the tip '" +
                    tip_link_ + "'");
  if (joints_.empty())
    fail(name_, "no joint moves between '" + base_link_ + "' and '" + tip_link_ + "'");
  tip_offset_ = pending;
  for (const RobotJoint& joint : description.attachments) {
    const auto parent = placement.find(joint.parent_link);
    if (joint.type != JointType::kFixed || parent == placement.end())
      fail(name_, "joint '" + joint.name + "' is not a fixed joint on a link of the arm");
    require_rigid(name_, joint);
    place(joint.child_link, {parent->second.body, parent->second.offset * joint.origin});
  }
  std::map<std::string, std::vector<LinkShape>> geometry;
  for (RobotLink& link : description.links) {
    if (!placement.contains(link.name))
      fail(name_, "link '" + link.name + "' has geometry but is not part of the arm");
    geometry[link.name] = std::move(link.collision);
  }
  for (const std::string& link : order) {
    const Placement& where = placement.at(link);
    links_.push_back({.name = link,
                      .body = where.body,
                      .offset = where.offset,
                      .collision = std::move(geometry[link])});
  }
  internal::ChosenSolver chosen =
      internal::choose_ik_solver(joints_, tip_offset_, description.dh.get());
  ik_ = std::move(chosen.solver);
  ik_method_ = chosen.method;
}

RobotModel RobotModel::from_dh(const DhChain& chain) {
  RobotDescription description{.name = chain.name(),
                               .source = chain.source(),
                               .base_link = "link0",
                               .tip_link = "flange",
                               .chain = {},
                               .attachments = {},
                               .links = {},
                               .dh = std::make_shared<const DhChain>(chain)};
  // A_i = Rz(q_i + offset_i) F_i with F_i = Tz(d_i) Tx(a_i) Rx(alpha_i): joint i's origin is
  // F_(i-1) Rz(offset_i), the flange hangs off the last link by F_n.
  Transform previous = Transform::Identity();
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const DhJoint& joint = chain.joint(i);
    const std::string index = std::to_string(i + 1);
    description.chain.push_back(
        {.name = "joint" + index,
         .type = JointType::kRevolute,
         .parent_link = "link" + std::to_string(i),
         .child_link = "link" + index,
         .origin = previous * Eigen::AngleAxisd(joint.offset, Eigen::Vector3d::UnitZ()),
         .axis = Eigen::Vector3d::UnitZ(),
         .limits = joint.limits});
    previous = dh_link_transform(0.0, joint.d, joint.a, joint.alpha);
  }
  description.chain.push_back({.name = "flange_joint",
                               .type = JointType::kFixed,
                               .parent_link = "link" + std::to_string(chain.size()),
                               .child_link = "flange",
                               .origin = previous,
                               .axis = Eigen::Vector3d::UnitZ(),
                               .limits = {}});
  return RobotModel(std::move(description));
}

void RobotModel::require_joint_values(std::span<const double> q) const {
  if (q.size() != joints_.size())
    throw KinematicsError("robot '" + name_ + "' has " + std::to_string(joints_.size()) +
                          " joints but " + std::to_string(q.size()) + " joint values were given");
  for (std::size_t i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i]))
      throw KinematicsError("robot '" + name_ + "': the value of joint " + std::to_string(i + 1) +
                            " ('" + joints_[i].name + "') is not a finite number");
}

Transform RobotModel::forward(std::span<const double> q) const {
  require_joint_values(q);
  return internal::chain_forward(joints_, tip_offset_, q);
}

std::vector<Transform> RobotModel::body_poses(std::span<const double> q) const {
  require_joint_values(q);
  std::vector<Transform> bodies{Transform::Identity()};
  for (std::size_t i = 0; i < joints_.size(); ++i)
    bodies.push_back(bodies.back() * joints_[i].origin * joint_motion(joints_[i], q[i]));
  return bodies;
}

std::vector<Transform> RobotModel::link_poses(std::span<const double> q) const {
  const std::vector<Transform> bodies = body_poses(q);
  std::vector<Transform> poses;
  for (const RobotLinkInfo& link : links_)
    poses.push_back(bodies[static_cast<std::size_t>(link.body)] * link.offset);
  return poses;
}

std::vector<int> RobotModel::joints_out_of_limits(std::span<const double> q,
                                                  double tolerance) const {
  require_joint_values(q);
  std::vector<int> out;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const JointLimits& limits = joints_[i].limits;
    if (q[i] < limits.lower - tolerance || q[i] > limits.upper + tolerance)
      out.push_back(static_cast<int>(i) + 1);
  }
  return out;
}

bool RobotModel::within_limits(std::span<const double> q, double tolerance) const {
  return joints_out_of_limits(q, tolerance).empty();
}

std::vector<JointSolution> RobotModel::inverse(const Transform& tip_pose,
                                               const InverseOptions& options) const {
  if (!tip_pose.matrix().allFinite()) return {};
  return ik_->solve(tip_pose, options);
}

std::vector<JointSolution> RobotModel::inverse_numeric(const Transform& tip_pose,
                                                       const InverseOptions& options) const {
  if (!tip_pose.matrix().allFinite()) return {};
  return internal::solve_numerically(joints_, tip_offset_, tip_pose, options);
}

}  // namespace spar::kinematics
