#include "spar/kinematics/ik.hpp"

#include <algorithm>
#include <cmath>

#include "spar/kinematics/internal/chain.hpp"

namespace spar::kinematics {
namespace {

constexpr double kPi = std::numbers::pi;
// |sin q5| below which q4 is pure rounding noise (the q4 = 0 choice then moves the pose < 1e-12).
constexpr double kUndeterminedWrist = 1e-12;

// Index of a configuration in IkResult::solutions: shoulder (l, r) x elbow (u, d) x wrist (n, f).
constexpr std::size_t solution_index(Shoulder shoulder, Elbow elbow, Wrist wrist) {
  return 4 * static_cast<std::size_t>(shoulder) + 2 * static_cast<std::size_t>(elbow) +
         static_cast<std::size_t>(wrist);
}

// A direction in the plane as (cos, sin); composing adds the angles (complex multiplication).
// Lets the solver carry joint angles' cosines and sines without calling sin/cos.
struct PlaneDirection {
  double c{1.0};
  double s{0.0};
};
PlaneDirection compose(PlaneDirection a, PlaneDirection b) {
  return {a.c * b.c - a.s * b.s, a.s * b.c + a.c * b.s};
}
PlaneDirection inverse(PlaneDirection a) { return {a.c, -a.s}; }
// Direction of (x, y); (1, 0) for the zero vector (the angle is then undetermined).
PlaneDirection direction_of(double x, double y) {
  const double norm = std::sqrt(x * x + y * y);
  if (!(norm > 0.0)) return {};
  return {x / norm, y / norm};
}

// The wrist's q4, q5, q6 for the arm's q1 and q2 + q3 (as directions) and the flange rotation,
// with |sin q5| (small near the wrist singularity).
struct WristAngles {
  double theta4{0}, theta5{0}, theta6{0}, sin_q5_magnitude{0};
};
WristAngles wrist_joint_angles(PlaneDirection joint1, PlaneDirection joint23,
                               const Eigen::Matrix3d& rotation) {
  const double c1 = joint1.c, s1 = joint1.s, c23 = joint23.c, s23 = joint23.s;
  // Axes of frame 3 in the base frame; M = R03^T R is the wrist rotation
  // Rz(q4) Ry(-q5) Rz(q6) (ZYZ Euler angles with the middle one negated).
  const Eigen::Vector3d x3(c1 * c23, s1 * c23, s23);
  const Eigen::Vector3d y3(-s1, c1, 0.0);
  const Eigen::Vector3d z3(-c1 * s23, -s1 * s23, c23);
  const Eigen::Vector3d r0 = rotation.col(0), r1 = rotation.col(1), r2 = rotation.col(2);
  const double m00 = x3.dot(r0), m01 = x3.dot(r1), m02 = x3.dot(r2);
  const double m10 = y3.dot(r0), m11 = y3.dot(r1), m12 = y3.dot(r2);
  const double m22 = z3.dot(r2);
  WristAngles out;
  out.sin_q5_magnitude = std::sqrt(m02 * m02 + m12 * m12);
  // Where q4 is numerically undetermined, the documented choice q4 = 0.
  const PlaneDirection joint4 =
      out.sin_q5_magnitude < kUndeterminedWrist
          ? PlaneDirection{1.0, 0.0}
          : PlaneDirection{m02 / out.sin_q5_magnitude, m12 / out.sin_q5_magnitude};
  out.theta4 = std::atan2(joint4.s, joint4.c);
  // q5 and q6 given q4 (well conditioned even near the singularity):
  // Rz(-q4) M = Ry(-q5) Rz(q6).
  const double c4 = joint4.c, s4 = joint4.s;
  out.theta5 = -std::atan2(c4 * m02 + s4 * m12, m22);
  out.theta6 = std::atan2(c4 * m10 - s4 * m00, c4 * m11 - s4 * m01);
  return out;
}

void require(bool condition, const std::string& robot, const std::string& what) {
  if (!condition) {
    throw KinematicsError("robot '" + robot +
                          "' is not a Puma-type arm, the closed-form solver needs " + what);
  }
}

}  // namespace

std::string ArmConfiguration::label() const {
  std::string text(3, ' ');
  text[0] = shoulder == Shoulder::left ? 'l' : 'r';
  text[1] = elbow == Elbow::up ? 'u' : 'd';
  text[2] = wrist == Wrist::no_flip ? 'n' : 'f';
  return text;
}

ArmConfiguration ArmConfiguration::from_label(std::string_view label) {
  const auto bad = [&] {
    return KinematicsError("bad configuration label '" + std::string(label) +
                           "': expected three letters l|r, u|d, n|f such as 'run'");
  };
  if (label.size() != 3) throw bad();
  ArmConfiguration configuration;
  if (label[0] == 'l')
    configuration.shoulder = Shoulder::left;
  else if (label[0] == 'r')
    configuration.shoulder = Shoulder::right;
  else
    throw bad();
  if (label[1] == 'u')
    configuration.elbow = Elbow::up;
  else if (label[1] == 'd')
    configuration.elbow = Elbow::down;
  else
    throw bad();
  if (label[2] == 'n')
    configuration.wrist = Wrist::no_flip;
  else if (label[2] == 'f')
    configuration.wrist = Wrist::flip;
  else
    throw bad();
  return configuration;
}

std::string singularity_names(std::uint8_t flags) {
  if (flags == kNoSingularity) return "none";
  std::string names;
  const auto add = [&](std::uint8_t flag, const char* name) {
    if ((flags & flag) == 0) return;
    if (!names.empty()) names += '+';
    names += name;
  };
  add(kShoulderSingularity, "shoulder");
  add(kElbowSingularity, "elbow");
  add(kWristSingularity, "wrist");
  return names;
}

int IkResult::count_within_limits() const {
  if (!solved()) return 0;
  int count = 0;
  for (const IkSolution& solution : solutions) count += solution.within_limits ? 1 : 0;
  return count;
}

std::optional<IkSolution> IkResult::first_within_limits() const {
  if (!solved()) return std::nullopt;
  for (const IkSolution& solution : solutions) {
    if (solution.within_limits) return solution;
  }
  return std::nullopt;
}

const IkSolution& IkResult::solution(const ArmConfiguration& configuration) const {
  return solutions[solution_index(configuration.shoulder, configuration.elbow,
                                  configuration.wrist)];
}

PumaIk::PumaIk(const DhChain& robot, IkOptions options) : options_(options) {
  const std::string& name = robot.name();
  require(robot.size() == 6, name, "6 joints");
  constexpr double kExact = 1e-12;
  const double expected_alpha[6] = {kPi / 2, 0.0, -kPi / 2, kPi / 2, -kPi / 2, 0.0};
  for (std::size_t i = 0; i < 6; ++i) {
    const DhJoint& joint = robot.joint(i);
    require(std::abs(joint.alpha - expected_alpha[i]) < 1e-9, name,
            "alpha = +90, 0, -90, +90, -90, 0 degrees (Paul's signs); joint " +
                std::to_string(i + 1) + " differs");
    offsets_[i] = joint.offset;
    limits_[i] = joint.limits;
  }
  require(std::abs(robot.joint(0).a) < kExact && std::abs(robot.joint(3).a) < kExact &&
              std::abs(robot.joint(4).a) < kExact && std::abs(robot.joint(5).a) < kExact,
          name, "a1 = a4 = a5 = a6 = 0 (a spherical wrist)");
  require(std::abs(robot.joint(4).d) < kExact, name, "d5 = 0 (a spherical wrist)");
  d1_ = robot.joint(0).d;
  a2_ = robot.joint(1).a;
  shoulder_offset_ = robot.joint(1).d + robot.joint(2).d;
  a3_ = robot.joint(2).a;
  d4_ = robot.joint(3).d;
  d6_ = robot.joint(5).d;
  lower_arm_length_ = std::hypot(a3_, d4_);
  lower_arm_angle_ = std::atan2(d4_, a3_);
  require(a2_ > 0.0 && lower_arm_length_ > 0.0, name, "a2 > 0 and hypot(a3, d4) > 0");
}

IkResult PumaIk::solve(const Transform& flange) const {
  IkResult result;
  const Eigen::Matrix3d& rotation = flange.linear();
  const Eigen::Vector3d wrist_centre = flange.translation() - d6_ * rotation.col(2);
  const double px = wrist_centre.x(), py = wrist_centre.y();
  const double height = wrist_centre.z() - d1_;  // y coordinate in the arm plane (frame 1)

  // Shoulder: px s1 - py c1 = d (the shoulder offset), so the arm-plane coordinate of the wrist
  // centre is x = px c1 + py s1 = +-sqrt(px^2 + py^2 - d^2).
  const double d = shoulder_offset_;
  const double reach_squared = px * px + py * py - d * d;
  if (reach_squared < -options_.reach_tolerance || !std::isfinite(reach_squared)) return result;
  const double reach = std::sqrt(std::max(reach_squared, 0.0));
  std::uint8_t arm_flags = reach < options_.singularity_tolerance ? kShoulderSingularity : 0;

  // Elbow: planar two-link arm (a2, then lower_arm_length at angle q2 + q3 + lower_arm_angle)
  // reaching (x, height); cos_elbow = cos(q3 + lower_arm_angle).
  const double length = lower_arm_length_;
  const double cos_elbow =
      (reach * reach + height * height - a2_ * a2_ - length * length) / (2.0 * a2_ * length);
  if (std::abs(cos_elbow) > 1.0 + options_.reach_tolerance) return result;
  const double c = std::clamp(cos_elbow, -1.0, 1.0);
  const double sin_elbow_magnitude = std::sqrt((1.0 - c) * (1.0 + c));
  if (sin_elbow_magnitude < options_.singularity_tolerance) arm_flags |= kElbowSingularity;

  result.status = IkStatus::solved;
  result.singularities = arm_flags;
  const PlaneDirection elbow_offset{a3_ / length, d4_ / length};  // lower_arm_angle
  for (const Shoulder shoulder : {Shoulder::left, Shoulder::right}) {
    const double side = shoulder == Shoulder::right ? 1.0 : -1.0;
    const double x = side * reach;
    // (c1, s1) solves px c1 + py s1 = x, px s1 - py c1 = d.
    const PlaneDirection joint1 = direction_of(px * x - py * d, py * x + px * d);
    const double theta1 = std::atan2(joint1.s, joint1.c);
    const PlaneDirection wrist_direction = direction_of(x, height);
    for (const Elbow elbow : {Elbow::up, Elbow::down}) {
      // The elbow is above the shoulder-wrist line when sin(q3 + lower_arm_angle) has the sign
      // opposite to x (cross product of wrist and elbow vectors).
      const PlaneDirection elbow_angle{c,
                                       (elbow == Elbow::up ? -side : side) * sin_elbow_magnitude};
      const double theta3 = std::atan2(elbow_angle.s, elbow_angle.c) - lower_arm_angle_;
      // q2 = direction of the wrist centre minus the angle the lower arm adds at the shoulder.
      const PlaneDirection joint2 =
          compose(wrist_direction,
                  inverse(direction_of(a2_ + length * elbow_angle.c, length * elbow_angle.s)));
      const double theta2 = std::atan2(joint2.s, joint2.c);
      const PlaneDirection joint23 = compose(joint2, compose(elbow_angle, inverse(elbow_offset)));
      const WristAngles angles = wrist_joint_angles(joint1, joint23, rotation);
      std::uint8_t flags = arm_flags;
      if (angles.sin_q5_magnitude < options_.singularity_tolerance) flags |= kWristSingularity;
      result.singularities |= flags;

      const double no_flip[6] = {theta1,        theta2,        theta3,
                                 angles.theta4, angles.theta5, angles.theta6};
      const double flip[6] = {
          theta1, theta2, theta3, angles.theta4 + kPi, -angles.theta5, angles.theta6 + kPi};
      for (const Wrist wrist : {Wrist::no_flip, Wrist::flip}) {
        IkSolution& solution = result.solutions[solution_index(shoulder, elbow, wrist)];
        solution.configuration = {shoulder, elbow, wrist};
        solution.singularities = flags;
        solution.within_limits = true;
        const double* theta = wrist == Wrist::no_flip ? no_flip : flip;
        for (std::size_t i = 0; i < 6; ++i) {
          double angle = theta[i] - offsets_[i];
          solution.within_limits &=
              internal::choose_representative(angle, limits_[i], options_.limit_tolerance);
          solution.q[static_cast<Eigen::Index>(i)] = angle;
        }
      }
    }
  }
  return result;
}

Reachability reachable(const PumaIk& solver, const Transform& tool_pose,
                       const ReachabilityOptions& options) {
  Reachability reachability;
  const Eigen::Vector3d tool_z = tool_pose.linear().col(2);
  reachability.tool_tilt = std::atan2(std::hypot(tool_z.x(), tool_z.y()), -tool_z.z());
  reachability.points_down = reachability.tool_tilt <= options.max_tool_tilt;
  reachability.inverse_kinematics = solver.solve(tool_pose * options.tool.inverse());
  reachability.reachable =
      reachability.points_down && reachability.inverse_kinematics.count_within_limits() > 0;
  return reachability;
}

}  // namespace spar::kinematics
