// The numeric inverse kinematics of any chain: Levenberg-Marquardt on the 6-D pose error from
// random starts within the joint limits (robot.hpp, kNumeric).
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "spar/kinematics/internal/chain.hpp"
#include "spar/kinematics/internal/ik_solver.hpp"

namespace spar::kinematics::internal {
namespace {

// A solution reproduces the pose when the position and rotation errors are below this (m, rad).
constexpr double kConverged = 1e-12;
constexpr int kMaxIterations = 100;
// Two solutions closer than this (rad or m, per joint) are the same.
constexpr double kSameSolution = 1e-6;

// The range a random start is drawn from: the limits, or one turn / +-1 m where they are open.
JointLimits start_range(const MovingJoint& joint) {
  const double open = joint.type == JointType::kRevolute ? std::numbers::pi : 1.0;
  return {std::isfinite(joint.limits.lower) ? joint.limits.lower : -open,
          std::isfinite(joint.limits.upper) ? joint.limits.upper : open};
}

// The damped step `damped` * step = `gradient`, solved again without the joints that sit at a
// limit and would step beyond it (an active set, at most one pass per joint): clamping such a
// joint's step alone would leave the others' steps computed for a motion it cannot make, and
// the descent stalls at the limit although the other joints could reach the pose.
Eigen::VectorXd step_within_limits(std::span<const MovingJoint> joints, std::span<const double> q,
                                   Eigen::MatrixXd damped, Eigen::VectorXd gradient) {
  Eigen::VectorXd step = damped.ldlt().solve(gradient);
  // A held joint's step is 0 from then on, so each pass holds a new joint: at most n passes.
  for (bool held_one = true; held_one;) {
    held_one = false;
    for (Eigen::Index i = 0; i < step.size(); ++i) {
      const std::size_t j = static_cast<std::size_t>(i);
      const bool pushes_out = (q[j] <= joints[j].limits.lower && step[i] < 0.0) ||
                              (q[j] >= joints[j].limits.upper && step[i] > 0.0);
      if (!pushes_out) continue;
      damped.row(i).setZero();
      damped.col(i).setZero();
      damped(i, i) = 1.0;
      gradient[i] = 0.0;
      held_one = true;
    }
    if (held_one) step = damped.ldlt().solve(gradient);
  }
  return step;
}

// Levenberg-Marquardt from q (within limits, each step clamped to them). True when it reaches the
// pose to kConverged.
bool descend(std::span<const MovingJoint> joints, const Transform& tip, const Transform& target,
             std::vector<double>& q) {
  const Eigen::Index n = static_cast<Eigen::Index>(q.size());
  PoseError error = pose_error(target, chain_forward(joints, tip, q));
  double cost = error.squaredNorm();
  double damping = 1e-3;
  std::vector<double> candidate(q.size());
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    if (error.head<3>().norm() < kConverged && error.tail<3>().norm() < kConverged) return true;
    const Jacobian jacobian = chain_jacobian(joints, tip, q);
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    const Eigen::VectorXd gradient = jacobian.transpose() * error;
    bool improved = false;
    while (!improved && damping < 1e10) {
      Eigen::MatrixXd damped = normal;
      damped.diagonal().array() += damping * (1.0 + normal.diagonal().array());
      const Eigen::VectorXd step = step_within_limits(joints, q, damped, gradient);
      for (Eigen::Index i = 0; i < n; ++i) {
        const std::size_t j = static_cast<std::size_t>(i);
        candidate[j] = std::clamp(q[j] + step[i], joints[j].limits.lower, joints[j].limits.upper);
      }
      const PoseError candidate_error = pose_error(target, chain_forward(joints, tip, candidate));
      const double candidate_cost = candidate_error.squaredNorm();
      if (candidate_cost < cost) {
        q = candidate;
        error = candidate_error;
        cost = candidate_cost;
        damping = std::max(damping / 10.0, 1e-12);
        improved = true;
      } else {
        damping *= 10.0;
      }
    }
    if (!improved) return false;  // stuck in a local minimum or at a limit
  }
  return error.head<3>().norm() < kConverged && error.tail<3>().norm() < kConverged;
}

class NumericIk final : public IkSolver {
 public:
  NumericIk(std::span<const MovingJoint> joints, const Transform& tip)
      : joints_(joints.begin(), joints.end()), tip_(tip) {}

  [[nodiscard]] std::vector<JointSolution> solve(const Transform& tip_pose,
                                                 const InverseOptions& options) const override {
    return solve_numerically(joints_, tip_, tip_pose, options);
  }

 private:
  std::vector<MovingJoint> joints_;
  Transform tip_;
};

}  // namespace

std::vector<JointSolution> solve_numerically(std::span<const MovingJoint> joints,
                                             const Transform& tip, const Transform& tip_pose,
                                             const InverseOptions& options) {
  std::mt19937_64 random(options.random_seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<JointSolution> solutions;
  std::vector<double> q(joints.size());
  for (int attempt = 0;
       attempt < options.numeric_attempts && solutions.size() < options.numeric_solutions;
       ++attempt) {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      const JointLimits range = start_range(joints[i]);
      q[i] = range.lower + (range.upper - range.lower) * unit(random);
    }
    if (!descend(joints, tip, tip_pose, q)) continue;
    JointSolution solution{.q = q, .configuration = {}, .within_limits = false, .singularities = 0};
    solution.within_limits = choose_representatives(joints, solution.q, 1e-9);
    if (!solution.within_limits) continue;
    const bool known = std::any_of(solutions.begin(), solutions.end(), [&](const JointSolution& s) {
      return same_configuration(joints, s.q, solution.q, kSameSolution);
    });
    if (!known) solutions.push_back(std::move(solution));
  }
  std::stable_sort(solutions.begin(), solutions.end(),
                   [&](const JointSolution& a, const JointSolution& b) {
                     return limit_margin(joints, a.q) > limit_margin(joints, b.q);
                   });
  for (std::size_t i = 0; i < solutions.size(); ++i)
    solutions[i].configuration =
        std::string(1, 'n').append(std::to_string(i + 1));  // GCC 12 warns on "n" + s
  return solutions;
}

std::shared_ptr<const IkSolver> make_numeric_solver(std::span<const MovingJoint> joints,
                                                    const Transform& tip) {
  return std::make_shared<const NumericIk>(joints, tip);
}

}  // namespace spar::kinematics::internal
