// Which inverse kinematics a chain gets (robot.hpp): Puma-type DH tables keep kinematics/ik.hpp's
// solver, then the closed forms by geometry, then the numeric solver.
#include "spar/kinematics/internal/ik_solver.hpp"

namespace spar::kinematics::internal {
namespace {

// kinematics/ik.hpp's answer as JointSolutions, in its order (lun ... rdf), all eight.
class PumaSolver final : public IkSolver {
 public:
  explicit PumaSolver(const DhChain& chain) : solver_(chain) {}

  [[nodiscard]] std::vector<JointSolution> solve(const Transform& tip_pose,
                                                 const InverseOptions&) const override {
    const IkResult result = solver_.solve(tip_pose);
    std::vector<JointSolution> solutions;
    if (!result.solved()) return solutions;
    for (const IkSolution& solution : result.solutions)
      solutions.push_back({.q = std::vector<double>(solution.q.data(), solution.q.data() + 6),
                           .configuration = solution.configuration.label(),
                           .within_limits = solution.within_limits,
                           .singularities = solution.singularities});
    return solutions;
  }

 private:
  PumaIk solver_;
};

}  // namespace

ChosenSolver choose_ik_solver(std::span<const MovingJoint> joints, const Transform& tip,
                              const DhChain* puma) {
  if (puma != nullptr) {
    try {
      return {std::make_shared<const PumaSolver>(*puma), IkMethod::kPumaClosedForm};
    } catch (const KinematicsError&) {
      // Not a Puma-type table: its geometry decides below.
    }
  }
  if (auto ur = make_ur_solver(joints, tip)) return {std::move(ur), IkMethod::kUrClosedForm};
  if (auto redundant = make_redundant_solver(joints, tip))
    return {std::move(redundant), IkMethod::kRedundantClosedForm};
  return {make_numeric_solver(joints, tip), IkMethod::kNumeric};
}

}  // namespace spar::kinematics::internal
