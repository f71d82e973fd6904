// Closed-form inverse kinematics from the chain's zero-configuration geometry (robot.hpp:
// kUrClosedForm and kRedundantClosedForm), by Paden-Kahan subproblems in the product-of-
// exponentials form of chain.hpp: with R_0i = rot(h1, q1) ... rot(hi, qi), the tip is at
//   p_0T = p1 + R_01 p_12 + R_02 p_23 + ... + R_0n p_nT,   R_0T = R_0n R_home,
// where p_ij runs from the chosen point on axis i to the one on axis j at q = 0. Choosing the
// points where axes meet makes terms vanish; that is what each family's geometry buys.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

#include "spar/kinematics/internal/chain.hpp"
#include "spar/kinematics/internal/ik_solver.hpp"
#include "spar/kinematics/internal/subproblems.hpp"

namespace spar::kinematics::internal {
namespace {

// Axes closer to parallel than this (|a x b|) are parallel; lines closer than this (m) meet. The
// solutions are polished on the exact chain afterwards, so a URDF's rounded pi/2 does no harm.
constexpr double kGeometryTolerance = 1e-7;
// A sub-problem whose two solutions are closer than this (rad) is at a singularity.
constexpr double kSingular = 1e-6;
// Closed-form solutions that miss the pose by more than this are polished on the exact chain.
constexpr double kPolishAbove = 1e-12;

bool all_revolute(std::span<const MovingJoint> joints) {
  return std::all_of(joints.begin(), joints.end(),
                     [](const MovingJoint& joint) { return joint.type == JointType::kRevolute; });
}

// A unit vector perpendicular to `axis`.
Eigen::Vector3d perpendicular(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d trial =
      std::abs(axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  return axis.cross(trial).normalized();
}

// The angle of the rotation `rotation` = rot(axis, angle) about `axis`.
double angle_about(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& axis) {
  const Eigen::Vector3d probe = perpendicular(axis);
  return angle_between_about(probe, rotation * probe, axis).value;
}

// Whether a sub-problem's two solutions (nearly) coincide: a singular configuration.
bool singular(const Angles& angles) {
  if (angles.tangent || angles.degenerate) return true;
  return angles.count == 2 && std::abs(std::remainder(angles.values[0] - angles.values[1],
                                                      2 * std::numbers::pi)) < 2 * kSingular;
}

// A closed-form answer on the exact chain: polished if it misses the pose, representatives chosen.
JointSolution finish(std::span<const MovingJoint> joints, const Transform& tip,
                     const Transform& target, std::vector<double> q, std::string label,
                     std::uint8_t singularities) {
  const PoseError error = pose_error(target, chain_forward(joints, tip, q));
  if (error.norm() > kPolishAbove) polish(joints, tip, target, q);
  JointSolution solution{.q = std::move(q),
                         .configuration = std::move(label),
                         .within_limits = false,
                         .singularities = singularities};
  solution.within_limits = choose_representatives(joints, solution.q, 1e-9);
  return solution;
}

// ---- UR type: axes 2, 3, 4 parallel, axes 5 and 6 meet (robot.hpp, kUrClosedForm) ----

class UrIk final : public IkSolver {
 public:
  static std::shared_ptr<const UrIk> recognise(std::span<const MovingJoint> joints,
                                               const Transform& tip) {
    if (joints.size() != 6 || !all_revolute(joints)) return nullptr;
    const ZeroGeometry zero = zero_geometry(joints, tip);
    const auto& h = zero.axis;
    const auto& p = zero.point;
    if (!parallel(h[1], h[2], kGeometryTolerance) || !parallel(h[1], h[3], kGeometryTolerance))
      return nullptr;
    if (parallel(h[0], h[1], kGeometryTolerance) || parallel(h[4], h[1], kGeometryTolerance))
      return nullptr;
    const std::optional<Eigen::Vector3d> wrist =
        line_intersection(p[4], h[4], p[5], h[5], kGeometryTolerance);
    if (!wrist) return nullptr;
    auto solver = std::make_shared<UrIk>();
    solver->joints_.assign(joints.begin(), joints.end());
    solver->tip_ = tip;
    for (std::size_t i = 0; i < 6; ++i) solver->h_[i] = h[i];
    // Parallel axes as one direction (an opposite axis turns the other way: rot(-h, q) =
    // rot(h, -q), which the sub-problems below handle by using each joint's own axis).
    solver->p1_ = p[0];
    solver->p12_ = p[1] - p[0];
    solver->p23_ = p[2] - p[1];
    solver->p34_ = p[3] - p[2];
    solver->p45_ = *wrist - p[3];
    solver->p6t_ = zero.home.translation() - *wrist;
    solver->home_rotation_ = zero.home.linear();
    // 'r': the wrist point on the side the arm reaches to at q = 0 (in the plane of axis 1 and
    // the arm, perpendicular to axis 2).
    Eigen::Vector3d side = h[1].cross(h[0]).normalized();
    if ((*wrist - p[0]).dot(side) < 0.0) side = -side;
    solver->reach_side_ = side;
    return solver;
  }

  [[nodiscard]] std::vector<JointSolution> solve(const Transform& target,
                                                 const InverseOptions&) const override {
    const auto& h = h_;
    const Eigen::Matrix3d r06 = target.linear() * home_rotation_.transpose();
    const Eigen::Vector3d p16 = target.translation() - r06 * p6t_ - p1_;
    // q1: h2 . R_01^T p_16 = h2 . (p_12 + p_23 + p_34 + p_45) (rotations about the parallel axes
    // keep h2, and p_56 = 0).
    Angles shoulder = solve_projection(h[1], p16, -h[0], h[1].dot(p12_ + p23_ + p34_ + p45_));
    if (shoulder.count == 0) return {};
    const bool shoulder_singular = singular(shoulder);
    if (shoulder.count == 1) shoulder.add(shoulder.values[0]);
    // 'l' first: the wrist point on the negative side.
    const auto side_of = [&](double q1) {
      return (rotation_about(h[0], q1).transpose() * p16).dot(reach_side_);
    };
    if (side_of(shoulder.values[0]) > side_of(shoulder.values[1]))
      std::swap(shoulder.values[0], shoulder.values[1]);

    std::array<std::optional<JointSolution>, 8> found;  // index 4 s + 2 e + w
    for (std::size_t s = 0; s < 2; ++s) {
      const double q1 = shoulder.values[s];
      const Eigen::Matrix3d r01 = rotation_about(h[0], q1);
      // q5: h2 . rot(h5, q5) h6 = h2 . R_01^T R_06 h6.
      Angles wrist = solve_projection(h[1], h[5], h[4], h[1].dot(r01.transpose() * r06 * h[5]));
      if (wrist.count == 0) continue;
      const bool wrist_singular = singular(wrist);
      if (wrist.count == 1) wrist.add(wrist.values[0]);
      for (std::size_t w = 0; w < 2; ++w) {
        const double q5 = wrist.values[w];
        const Eigen::Matrix3d r45 = rotation_about(h[4], q5);
        // q6: rot(h6, q6) R_06^T R_01 h2 = R_45^T h2.
        const Angle sixth =
            angle_between_about(r06.transpose() * r01 * h[1], r45.transpose() * h[1], h[5]);
        const double q6 = sixth.value;
        const Eigen::Matrix3d r14 =
            r01.transpose() * r06 * rotation_about(h[5], q6).transpose() * r45.transpose();
        // The planar arm: rot(h2, q2) (p_23 + rot(h3, q3) p_34) = d.
        const Eigen::Vector3d d = r01.transpose() * p16 - p12_ - r14 * p45_;
        Angles elbow = solve_distance(p34_, -p23_, h[2], d.norm());
        if (elbow.count == 0) continue;
        const bool elbow_singular = singular(elbow);
        if (elbow.count == 1) elbow.add(elbow.values[0]);
        std::array<std::array<double, 3>, 2> arms{};  // q2, q3, q4 per elbow root
        std::array<double, 2> height{};               // of the elbow above the shoulder-wrist line
        for (std::size_t e = 0; e < 2; ++e) {
          const double q3 = elbow.values[e];
          const Eigen::Matrix3d r23 = rotation_about(h[2], q3);
          const Eigen::Vector3d reach = p23_ + r23 * p34_;
          const double q2 = angle_between_about(reach, d, h[1]).value;
          const Eigen::Matrix3d r13 = rotation_about(h[1], q2) * r23;
          const double q4 = angle_about(r13.transpose() * r14, h[3]);
          arms[e] = {q2, q3, q4};
          const Eigen::Vector3d to_elbow = rotation_about(h[1], q2) * p23_;
          const Eigen::Vector3d to_wrist = to_elbow + r13 * p34_;
          const Eigen::Vector3d line = to_wrist.normalized();
          height[e] = (to_elbow - to_elbow.dot(line) * line).dot(h[0]);
        }
        if (height[0] < height[1]) std::swap(arms[0], arms[1]);  // 'u' first
        const std::uint8_t flags = (shoulder_singular ? kShoulderSingularity : 0) |
                                   (elbow_singular ? kElbowSingularity : 0) |
                                   (wrist_singular || sixth.degenerate ? kWristSingularity : 0);
        for (std::size_t e = 0; e < 2; ++e) {
          const std::string label{"lr"[s], "ud"[e], "nf"[w]};
          found[4 * s + 2 * e + w] =
              finish(joints_, tip_, target, {q1, arms[e][0], arms[e][1], arms[e][2], q5, q6}, label,
                     flags);
        }
      }
    }
    std::vector<JointSolution> solutions;
    for (std::optional<JointSolution>& solution : found)
      if (solution) solutions.push_back(std::move(*solution));
    return solutions;
  }

 private:
  std::vector<MovingJoint> joints_;
  Transform tip_{Transform::Identity()};
  std::array<Eigen::Vector3d, 6> h_{};
  Eigen::Vector3d p1_, p12_, p23_, p34_, p45_, p6t_;  // p45 ends, p6t starts where 5 and 6 meet
  Eigen::Matrix3d home_rotation_{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d reach_side_{Eigen::Vector3d::UnitX()};
};

// ---- Six joints with a spherical shoulder (axes 1, 2, 3 meet at S) and axes 5, 6 meeting at W.
// The home pose is an argument: the redundant solver moves it with q7. ----

// At the shoulder singularity axes 1 and 3 are aligned (axis 3 turned by q2 is `sign` times axis
// 1): R_03 fixes only q1 + sign q3, and solve_two_rotations reports q1 = 0. Where that leaves q3
// with no representative within joint 3's limits, the split moves by d (q1 + d, q3 - sign d) to
// the middle of the shifts that keep both within their limits; where none does, it is left as it
// is (the branch is then dropped). A split within limits is never moved: only branches that
// would be dropped change.
void resplit_at_shoulder_singularity(double& q1, double& q3, double sign, const JointLimits& first,
                                     const JointLimits& third) {
  double representative = q3;
  if (choose_representative(representative, third, 1e-9)) return;
  for (int turns = -1; turns <= 1; ++turns) {
    const double q3k = q3 + 2 * std::numbers::pi * turns;
    // q1 + d within the first joint's limits; q3k - sign d within the third's.
    double low = first.lower - q1, high = first.upper - q1;
    const double a = q3k - third.upper, b = q3k - third.lower;
    low = std::max(low, sign > 0 ? a : -b);
    high = std::min(high, sign > 0 ? b : -a);
    if (!(low <= high)) continue;
    const double d = (low + high) / 2;
    q1 += d;
    q3 = q3k - sign * d;
    return;
  }
}

struct Branch {
  std::array<double, 6> q{};
  std::array<char, 3> label{};
  std::uint8_t singularities{kNoSingularity};
};

class SphericalShoulder {
 public:
  static std::optional<SphericalShoulder> recognise(const ZeroGeometry& zero) {
    const auto& h = zero.axis;
    const auto& p = zero.point;
    if (parallel(h[0], h[1], kGeometryTolerance) || parallel(h[1], h[2], kGeometryTolerance))
      return std::nullopt;
    const std::optional<Eigen::Vector3d> shoulder =
        line_intersection(p[0], h[0], p[1], h[1], kGeometryTolerance);
    if (!shoulder) return std::nullopt;
    const Eigen::Vector3d off_axis3 = (*shoulder - p[2]) - (*shoulder - p[2]).dot(h[2]) * h[2];
    if (off_axis3.norm() > kGeometryTolerance) return std::nullopt;
    const std::optional<Eigen::Vector3d> wrist =
        line_intersection(p[4], h[4], p[5], h[5], kGeometryTolerance);
    if (!wrist) return std::nullopt;
    SphericalShoulder solver;
    for (std::size_t i = 0; i < 6; ++i) solver.h_[i] = h[i];
    solver.shoulder_ = *shoulder;
    solver.wrist_ = *wrist;
    solver.p34_ = p[3] - *shoulder;
    solver.p45_ = *wrist - p[3];
    // |p34 + rot(h4, q4) p45| over q4: the components along h4 add, the perpendicular ones
    // turn against each other.
    const auto across = [&](const Eigen::Vector3d& v) { return (v - v.dot(h[3]) * h[3]).norm(); };
    const double along = (solver.p34_ + solver.p45_).dot(h[3]);
    const double a = across(solver.p34_), b = across(solver.p45_);
    solver.reach_ = {std::hypot(along, a - b), std::hypot(along, a + b)};
    // q4 must change the shoulder-wrist distance.
    if (parallel(solver.p34_, h[3], kGeometryTolerance * std::max(1.0, solver.p34_.norm())) ||
        parallel(solver.p45_, h[3], kGeometryTolerance * std::max(1.0, solver.p45_.norm())))
      return std::nullopt;
    return solver;
  }

  // The wrist point (axes 5 and 6 meet there) with every joint at 0.
  [[nodiscard]] const Eigen::Vector3d& wrist() const { return wrist_; }
  // The shortest and the longest shoulder-wrist distance q4 can give.
  [[nodiscard]] const std::array<double, 2>& reach() const { return reach_; }

  // S W, the wrist point seen from the shoulder, with the tip at `target` (at `home` when
  // q1..q6 = 0).
  [[nodiscard]] Eigen::Vector3d to_wrist(const Transform& target, const Transform& home) const {
    return to_wrist(target, home, target.linear() * home.linear().transpose());
  }

  // Up to eight branches reaching `target` with the tip at `home` when q1..q6 = 0; a branch is
  // dropped as soon as one of its angles has no representative within the limits of `joints`.
  // `within_reach` is set when the wrist point is within the arm's reach (limits aside).
  [[nodiscard]] std::vector<Branch> solve(const Transform& target, const Transform& home,
                                          std::span<const MovingJoint> joints,
                                          bool& within_reach) const {
    const auto admissible = [&](std::size_t joint, double angle) {
      return choose_representative(angle, joints[joint].limits, 1e-9);
    };
    const auto& h = h_;
    std::vector<Branch> branches;
    const Eigen::Matrix3d r06 = target.linear() * home.linear().transpose();
    const Eigen::Vector3d to_wrist = this->to_wrist(target, home, r06);
    const Eigen::Vector3d h6 = r06 * h[5];
    // q4: |p_34 + rot(h4, q4) p_45| = |S W|.
    const Angles elbow = solve_distance(p45_, -p34_, h[3], to_wrist.norm());
    within_reach |= elbow.count > 0;
    for (std::size_t e = 0; e < elbow.count; ++e) {
      if (!admissible(3, elbow.values[e])) continue;
      const Eigen::Matrix3d r34 = rotation_about(h[3], elbow.values[e]);
      const Eigen::Vector3d u1 = p34_ + r34 * p45_;  // R_03^T (S W)
      // q5: R_03 keeps the angle between S W and axis 6.
      const Angles wrist_angles =
          solve_projection(r34.transpose() * u1, h[5], h[4], to_wrist.dot(h6));
      for (std::size_t w = 0; w < wrist_angles.count; ++w) {
        if (!admissible(4, wrist_angles.values[w])) continue;
        const Eigen::Matrix3d r35 = r34 * rotation_about(h[4], wrist_angles.values[w]);
        const Eigen::Vector3d u2 = r35 * h[5];  // R_03^T h6
        const std::optional<Eigen::Matrix3d> r03 = rotation_taking(u1, u2, to_wrist, h6);
        if (!r03) continue;  // S W along axis 6: R_03 is not fixed by these two directions
        // q1, q2: rot(h1, q1) rot(h2, q2) h3 = R_03 h3; then q3 and q6 by one rotation each.
        const AnglePairs arm = solve_two_rotations(*r03 * h[2], -h[0], h[2], h[1]);
        for (std::size_t s = 0; s < arm.count; ++s) {
          double q1 = arm.values[s][0];
          const double q2 = arm.values[s][1];
          if (!admissible(0, q1) || !admissible(1, q2)) continue;
          const Eigen::Matrix3d r02 = rotation_about(h[0], q1) * rotation_about(h[1], q2);
          double q3 = angle_about(r02.transpose() * *r03, h[2]);
          if (arm.degenerate) {
            const double sign = h[0].dot(rotation_about(h[1], q2) * h[2]) < 0 ? -1.0 : 1.0;
            resplit_at_shoulder_singularity(q1, q3, sign, joints[0].limits, joints[2].limits);
          }
          const double q6 = angle_about((*r03 * r35).transpose() * r06, h[5]);
          const std::uint8_t flags = (arm.tangent || arm.degenerate ? kShoulderSingularity : 0) |
                                     (singular(elbow) ? kElbowSingularity : 0) |
                                     (singular(wrist_angles) ? kWristSingularity : 0);
          branches.push_back({.q = {q1, q2, q3, elbow.values[e], wrist_angles.values[w], q6},
                              .label = {"lr"[s], "ud"[e], "nf"[w]},
                              .singularities = flags});
        }
      }
    }
    return branches;
  }

 private:
  // to_wrist with r06 = R_target R_home^T given.
  [[nodiscard]] Eigen::Vector3d to_wrist(const Transform& target, const Transform& home,
                                         const Eigen::Matrix3d& r06) const {
    return target.translation() - r06 * (home.translation() - wrist_) - shoulder_;
  }

  // The rotation R with R a1 = b1 and R a2 = b2 (|a1| = |b1| and a1 . a2 = b1 . b2 given), or
  // nullopt when a2 is (nearly) parallel to a1.
  static std::optional<Eigen::Matrix3d> rotation_taking(const Eigen::Vector3d& a1,
                                                        const Eigen::Vector3d& a2,
                                                        const Eigen::Vector3d& b1,
                                                        const Eigen::Vector3d& b2) {
    const auto frame = [](const Eigen::Vector3d& first,
                          const Eigen::Vector3d& second) -> std::optional<Eigen::Matrix3d> {
      const Eigen::Vector3d x = first.normalized();
      const Eigen::Vector3d rest = second - second.dot(x) * x;
      if (rest.norm() < 1e-9 * std::max(1.0, second.norm())) return std::nullopt;
      Eigen::Matrix3d axes;
      axes.col(0) = x;
      axes.col(1) = rest.normalized();
      axes.col(2) = axes.col(0).cross(axes.col(1));
      return axes;
    };
    const std::optional<Eigen::Matrix3d> from = frame(a1, a2), to = frame(b1, b2);
    if (!from || !to) return std::nullopt;
    return *to * from->transpose();
  }

  std::array<Eigen::Vector3d, 6> h_{};
  Eigen::Vector3d shoulder_, wrist_, p34_, p45_;
  std::array<double, 2> reach_{};
};

// ---- Seven joints: q7 sampled, the first six in closed form (robot.hpp, kRedundantClosedForm).

class RedundantIk final : public IkSolver {
 public:
  RedundantIk(std::span<const MovingJoint> joints, const Transform& tip, const ZeroGeometry& zero,
              SphericalShoulder six)
      : joints_(joints.begin(), joints.end()),
        tip_(tip),
        home_(zero.home),
        axis7_(zero.axis[6]),
        point7_(zero.point[6]),
        six_(std::move(six)) {}

  [[nodiscard]] std::vector<JointSolution> solve(const Transform& target,
                                                 const InverseOptions& options) const override {
    if (!(options.redundancy_step > 0.0) || !std::isfinite(options.redundancy_step))
      throw KinematicsError("the redundancy step must be a positive angle");
    const JointLimits& limits = joints_[6].limits;
    const double lower = std::isfinite(limits.lower) ? limits.lower : -std::numbers::pi;
    const double upper = std::isfinite(limits.upper) ? limits.upper : std::numbers::pi;
    std::vector<double> samples;
    if (options.redundancy_at) {
      samples.push_back(*options.redundancy_at);
    } else {
      const long first = static_cast<long>(std::ceil(lower / options.redundancy_step - 1e-9));
      const long last = static_cast<long>(std::floor(upper / options.redundancy_step + 1e-9));
      for (long k = first; k <= last; ++k)
        samples.push_back(static_cast<double>(k) * options.redundancy_step);
      add_samples_within_reach(target, lower, upper, samples);
    }
    struct Ranked {
      JointSolution solution;
      double margin;
      double q7;
    };
    std::vector<Ranked> ranked;
    bool within_reach = false;
    for (const double q7 : samples) {
      for (const Branch& branch : six_.solve(target, home_at(q7), joints_, within_reach)) {
        std::vector<double> q(branch.q.begin(), branch.q.end());
        q.push_back(q7);
        // Most branches leave the limits: drop them before verifying the pose.
        if (!choose_representatives(joints_, q, 1e-9)) continue;
        char suffix[48];
        std::snprintf(suffix, sizeof suffix, "@q7=%gdeg", q7 * 180.0 / std::numbers::pi);
        JointSolution solution = finish(
            joints_, tip_, target, std::move(q),
            std::string(branch.label.begin(), branch.label.end()) + suffix, branch.singularities);
        if (!solution.within_limits) continue;
        const double margin = limit_margin(joints_, solution.q);
        ranked.push_back({std::move(solution), margin, q7});
      }
    }
    std::stable_sort(ranked.begin(), ranked.end(), [](const Ranked& a, const Ranked& b) {
      if (a.margin != b.margin) return a.margin > b.margin;
      return std::abs(a.q7) < std::abs(b.q7);
    });
    std::vector<JointSolution> solutions;
    for (Ranked& entry : ranked) solutions.push_back(std::move(entry.solution));
    // Within reach but no sample within limits: the limits may still allow q7 between samples.
    if (solutions.empty() && within_reach && !options.redundancy_at)
      return solve_numerically(joints_, tip_, target, options);
    return solutions;
  }

 private:
  // The tip at q1..q6 = 0 with joint 7 at q7: turned about axis 7.
  [[nodiscard]] Transform home_at(double q7) const {
    Transform turn = Transform::Identity();
    turn.linear() = rotation_about(axis7_, q7);
    turn.translation() = point7_ - turn.linear() * point7_;
    return turn * home_;
  }

  // The wrist point is fixed in link 6, so with the tip at `target` it turns with q7 on a circle
  // about axis 7: |S W|^2 = A + B cos q7 + C sin q7 exactly (three values fix A, B, C). Where the
  // arcs of q7 in [lower, upper] that keep |S W| within the shoulder's reach hold no sample (a
  // band narrower than the step, near the reach's ends), their middles are added: else no
  // sample reaches a pose the arm reaches.
  void add_samples_within_reach(const Transform& target, double lower, double upper,
                                std::vector<double>& samples) const {
    const auto squared = [&](double q7) {
      return six_.to_wrist(target, home_at(q7)).squaredNorm();
    };
    const double at_0 = squared(0.0), at_half = squared(std::numbers::pi / 2),
                 at_pi = squared(std::numbers::pi);
    const double a = (at_0 + at_pi) / 2, b = (at_0 - at_pi) / 2, c = at_half - a;
    const double amplitude = std::hypot(b, c);
    if (!(amplitude > 1e-12 * std::max(1.0, a))) return;  // |S W| does not change with q7
    const double phase = std::atan2(c, b);                // |S W|^2 = a + amplitude cos(q7 - phase)
    const std::array<double, 2>& reach = six_.reach();
    const double cos_lo = std::max(-1.0, (reach[0] * reach[0] - a) / amplitude);
    const double cos_hi = std::min(1.0, (reach[1] * reach[1] - a) / amplitude);
    if (cos_lo > cos_hi) return;
    const double near = std::acos(cos_hi), far = std::acos(cos_lo);  // 0 <= near <= far <= pi
    for (const auto& [from, to] : {std::pair{near, far}, std::pair{-far, -near}}) {
      for (int turns = -1; turns <= 1; ++turns) {
        const double shift = phase + 2 * std::numbers::pi * turns;
        const double x = std::max(lower, from + shift), y = std::min(upper, to + shift);
        if (x > y) continue;
        const bool sampled = std::any_of(samples.begin(), samples.end(),
                                         [&](double q7) { return x <= q7 && q7 <= y; });
        if (!sampled) samples.push_back((x + y) / 2);
      }
    }
  }

  std::vector<MovingJoint> joints_;
  Transform tip_;
  Transform home_;
  Eigen::Vector3d axis7_, point7_;
  SphericalShoulder six_;
};

}  // namespace

std::shared_ptr<const IkSolver> make_ur_solver(std::span<const MovingJoint> joints,
                                               const Transform& tip) {
  return UrIk::recognise(joints, tip);
}

std::shared_ptr<const IkSolver> make_redundant_solver(std::span<const MovingJoint> joints,
                                                      const Transform& tip) {
  if (joints.size() != 7 || !all_revolute(joints)) return nullptr;
  const ZeroGeometry zero = zero_geometry(joints, tip);
  std::optional<SphericalShoulder> six = SphericalShoulder::recognise(zero);
  if (!six) return nullptr;
  return std::make_shared<const RedundantIk>(joints, tip, zero, std::move(*six));
}

}  // namespace spar::kinematics::internal
