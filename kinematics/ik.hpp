// Closed-form inverse kinematics of Puma-type arms: all eight configurations, labelled, with
// singularities reported and joint limits checked per configuration; and SPAR's reachability test.
//
// The arm (standard DH, Paul's alpha signs alpha = +90, 0, -90, +90, -90, 0 deg; a1 = a4 = a5 = a6
// = 0, d5 = 0) has a spherical wrist, so the wrist centre p_w = p - d6 z fixes joints 1-3 and the
// orientation fixes joints 4-6 (Paul & Zhang 1986). Every solution is labelled with three letters,
// as in the corpus and Corke's toolbox:
//   l / r  shoulder left / right: in the arm plane the wrist centre lies on the negative / positive
//          x1 side (q1 = atan2(py, px) + atan2(d3, -/+ sqrt(px^2 + py^2 - d3^2)));
//   u / d  elbow up / down: the elbow is above / below the line from the shoulder to the wrist
//   centre; n / f  wrist not flipped / flipped: n has q5 <= 0; f = n with q4 + pi, -q5, q6 + pi.
// A reachable pose has exactly eight solutions (some may coincide at a singularity). Angles are
// wrapped into (-pi, pi] unless another 2 pi multiple lies within the joint's limits.
//
// Singularities never produce NaNs; they set a flag and a documented choice:
//   shoulder  wrist centre on the shoulder axis line (x1 = 0): l and r coincide;
//   elbow     arm fully stretched or folded: u and d coincide;
//   wrist     q5 = 0 (z4 parallel to z6): only q4 + q6 is determined; where q4 is numerically
//             undetermined (|sin q5| < 1e-12) q4 = 0 (n) / pi (f) is chosen.
//
// Example:
//   const PumaIk solver(puma560());
//   const IkResult result = solver.solve(puma560().forward({0, 0.7, 0.9, 0, -0.5, 0}));
//   for (const IkSolution& solution : result.solutions)        // 8 of them if reachable
//     std::cout << solution.configuration.label() << ' ' << solution.within_limits << '\n';
//   bool ok = reachable(solver, tool_pose).reachable;  // an in-limit solution, tool z down
#pragma once

#include <array>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>

#include "spar/kinematics/dh.hpp"

namespace spar::kinematics {

using JointVector = Eigen::Matrix<double, 6, 1>;

enum class Shoulder : std::uint8_t { left, right };
enum class Elbow : std::uint8_t { up, down };
enum class Wrist : std::uint8_t { no_flip, flip };

struct ArmConfiguration {
  Shoulder shoulder{Shoulder::right};
  Elbow elbow{Elbow::up};
  Wrist wrist{Wrist::no_flip};
  // Three letters, e.g. "run": l|r, u|d, n|f.
  [[nodiscard]] std::string label() const;
  // Inverse of label(); throws KinematicsError on anything but the eight labels.
  [[nodiscard]] static ArmConfiguration from_label(std::string_view label);
  friend bool operator==(const ArmConfiguration&, const ArmConfiguration&) = default;
};

// Bit flags of the singularities a pose is at (within IkOptions::singularity_tolerance).
enum Singularity : std::uint8_t {
  kNoSingularity = 0,
  kShoulderSingularity = 1,
  kElbowSingularity = 2,
  kWristSingularity = 4,
};
// "none" or e.g. "shoulder+wrist".
[[nodiscard]] std::string singularity_names(std::uint8_t flags);

struct IkSolution {
  ArmConfiguration configuration{};
  JointVector q{JointVector::Zero()};
  bool within_limits{false};
  std::uint8_t singularities{kNoSingularity};  // of this solution's sub-problems
};

enum class IkStatus : std::uint8_t {
  solved,       // eight solutions
  unreachable,  // the wrist centre is outside the arm's workspace: no solutions
};

struct IkResult {
  IkStatus status{IkStatus::unreachable};
  std::uint8_t singularities{kNoSingularity};  // union over the solutions
  // Order: lun, luf, ldn, ldf, run, ruf, rdn, rdf. Meaningful only when status == solved.
  std::array<IkSolution, 8> solutions{};
  [[nodiscard]] bool solved() const { return status == IkStatus::solved; }
  [[nodiscard]] int count_within_limits() const;
  // The first in-limit solution in the order above, if any.
  [[nodiscard]] std::optional<IkSolution> first_within_limits() const;
  [[nodiscard]] const IkSolution& solution(const ArmConfiguration& configuration) const;
};

struct IkOptions {
  // Distance (m) of the wrist centre from the shoulder axis line, |sin| of the elbow angle from
  // full stretch/fold, and |sin q5|, below which a solution is flagged singular. Flags are
  // informational: the solutions stay exact near a singularity.
  double singularity_tolerance{1e-6};
  // A joint angle this close (rad) outside its limits still counts as within them (rounding at a
  // limit must not flip the verdict).
  double limit_tolerance{1e-9};
  // How far (m^2 in the shoulder test, cos in the elbow test) a pose may lie outside the workspace
  // and still be treated as on its boundary (rounding in the caller's pose).
  double reach_tolerance{1e-12};
};

// Closed-form solver for one Puma-type chain. Keeps only the numbers it needs, not the chain.
class PumaIk {
 public:
  // Throws KinematicsError if `robot` is not a 6-joint Puma-type chain (see the header comment).
  explicit PumaIk(const DhChain& robot, IkOptions options = {});

  // All eight solutions for the flange pose `flange` (base frame, no tool). Never throws.
  [[nodiscard]] IkResult solve(const Transform& flange) const;

 private:
  // Invariants: a2 > 0, lower_arm_length = hypot(a3, d4) > 0; limits copied from the chain.
  double d1_{0.0}, a2_{0.0}, shoulder_offset_{0.0} /* d2 + d3 */, a3_{0.0}, d4_{0.0}, d6_{0.0};
  double lower_arm_length_{0.0}, lower_arm_angle_{0.0} /* atan2(d4, a3) */;
  std::array<double, 6> offsets_{};
  std::array<JointLimits, 6> limits_{};
  IkOptions options_{};
};

// SPAR's reachable(Grasp, Position): some configuration within the joint limits reaches the pose,
// and the tool z axis points down within a cone (keeps the arm off the work table).
struct ReachabilityOptions {
  // Half-angle of the cone around world -z that the tool z axis must lie in. SPAR did not publish a
  // value; 45 degrees is our default.
  double max_tool_tilt{std::numbers::pi / 4.0};
  // Tool frame relative to the flange (pose = flange * tool).
  Transform tool{Transform::Identity()};
};

struct Reachability {
  bool reachable{false};          // points_down && an in-limit configuration exists
  bool points_down{false};        // tool z within max_tool_tilt of world -z
  double tool_tilt{0.0};          // angle (rad) between tool z and world -z
  IkResult inverse_kinematics{};  // of the flange pose
};

[[nodiscard]] Reachability reachable(const PumaIk& solver, const Transform& tool_pose,
                                     const ReachabilityOptions& options = {});

}  // namespace spar::kinematics
