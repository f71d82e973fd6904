// The inverse kinematics solvers behind RobotModel::inverse (robot.hpp documents each one's
// answers, order and labels). A solver is immutable after construction and keeps copies of the
// numbers it needs, never a pointer to the model. Not public API.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "spar/kinematics/robot.hpp"

namespace spar::kinematics::internal {

class IkSolver {
 public:
  virtual ~IkSolver() = default;
  [[nodiscard]] virtual std::vector<JointSolution> solve(const Transform& tip_pose,
                                                         const InverseOptions& options) const = 0;
};

struct ChosenSolver {
  std::shared_ptr<const IkSolver> solver;
  IkMethod method{IkMethod::kNumeric};
};

// The closed form the chain's geometry allows (Puma when `puma` is a Puma-type table, else UR or
// the 7-joint redundant form), else the numeric solver. (ik_choice.cpp)
[[nodiscard]] ChosenSolver choose_ik_solver(std::span<const MovingJoint> joints,
                                            const Transform& tip, const DhChain* puma);

// Each closed form: the solver if the chain has its geometry, else nullptr. (closed_form_ik.cpp)
[[nodiscard]] std::shared_ptr<const IkSolver> make_ur_solver(std::span<const MovingJoint> joints,
                                                             const Transform& tip);
[[nodiscard]] std::shared_ptr<const IkSolver> make_redundant_solver(
    std::span<const MovingJoint> joints, const Transform& tip);
// The numeric solver works for any chain. (numeric_ik.cpp)
[[nodiscard]] std::shared_ptr<const IkSolver> make_numeric_solver(
    std::span<const MovingJoint> joints, const Transform& tip);

// Solutions within limits found by the numeric solver, labelled "n1", "n2", ... by decreasing
// limit margin. (numeric_ik.cpp)
[[nodiscard]] std::vector<JointSolution> solve_numerically(std::span<const MovingJoint> joints,
                                                           const Transform& tip,
                                                           const Transform& tip_pose,
                                                           const InverseOptions& options);

}  // namespace spar::kinematics::internal
