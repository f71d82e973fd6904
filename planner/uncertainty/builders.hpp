// Builders: the uncertainty preconditions of a step (seed 001, "Constraints at the
// Uncertainty-Reduction Level"), as inequalities over the instance's uncertainty variables, from
// the propagated state just before the step. The domain names which builders a step calls
// (planner/uncertainty/effects.hpp); planner/uncertainty/propagation.hpp calls them.
//
// The records propagation keeps per object (every error an expression over the space):
//   TableState  on the table: SPAR's eq. 2, actual pose = trans(d) T_O' with T_O' = rotz(θ) about
//               the ideal pose's origin, d = (dx, dy, dz) in world coordinates;
//   HeldState   held: actual pose = M T_ΔM H T_G^-1 (ideal gripper pose M of the current step,
//               the arm's error T_ΔM of that step (eq. 1), the grip H, the grasp T_G).
// Builders:
//   pickup, squeeze  SPAR's four: 0 < [0,1,0,0] P1^-1 C1, ... (kinematics/pickup.hpp), with W_m
//                    the gripper's maximum opening and W_g the grasp's width, over the object's
//                    table state and the step's arm error;
//   assemble         the held object's mating point p (area centroid of its mating faces) must
//                    reach its place in the fixed object within the goal's clearance c measured
//                    perpendicular to the mating vector v: with δ = W_f^-1 W_h p - Ta p (fixed
//                    frame) and u1, u2 an orthonormal pair perpendicular to v:
//                    -c <= δ·u1 <= c and -c <= δ·u2 <= c (four inequalities); and, if the goal
//                    gives an angular clearance α > 0, the held mating axis turned by the actual
//                    relative rotation stays within α of v: (R_f^T R_h R_a^T v)·v >= cos α.
// Invariant: every expression is built from the state's shared DAG nodes (no copies), so a later
// precondition's node count grows linearly with the number of steps that touched its objects.
// Cost: a pickup builds 4 expressions of ~50 nodes; an insertion 4-5 of a few hundred.
//
// Example:
//   const TableState& peg = *propagation.on_table(0);
//   const std::vector<Precondition> four =
//       pickup_preconditions(world, step, peg, arm, Builder::kPickup);
//   for (const Precondition& p : four) std::cout << p.inequality.name << '\n';
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "spar/bounds/inequality.hpp"
#include "spar/kinematics/symbolic_transform.hpp"
#include "spar/planner/uncertainty/effects.hpp"
#include "spar/planner/world.hpp"

namespace spar::planner {

// One step as phase 2 sees it: an instance step or a range-scan / squeeze phase 2 inserted.
struct Phase2Step {
  int action{0};                 // index into Domain::actions
  Effect effect{Effect::kNone};  // == Domain::actions[action].effect
  int object{-1};                // the handled (held) object
  int grasp{-1};                 // grasp label of `object` (grasp, release, squeeze, insert)
  int position{-1};              // position label of `object` where it is (grasp, squeeze) or goes
                                 // (release); -1 for insertions and inserted range-scans
  int fixed_object{-1};          // insertions
  int camera{-1};  // a camera verification (sense, `sensor: camera`): index into Scenario::cameras
  // Ideal: where the object is (grasp, squeeze, scan) or goes (release; insert: T_f Ta).
  kinematics::Transform object_pose{kinematics::Transform::Identity()};
  kinematics::Transform fixed_pose{kinematics::Transform::Identity()};
  // The IK branch the step's collisions were checked at (InstanceStep::reach; a squeeze's:
  // RepairCandidate::arm). Joint uncertainty acts there and refuses a step without one.
  std::optional<kinematics::JointSolution> arm{};
  int instance_step{-1};  // index into PlanInstance::steps; -1 when inserted by phase 2
  int repair{-1};         // inserted by phase 2's repair: index into InstanceAnalysis::repairs
  // The number phase 2 names the step's variables after while it searches (dx_g<label>, ...):
  // instance_step + 1 for an instance step (phase2_steps); for a step the repair search splices
  // in, a number past every instance step's, fixed by the failing step it serves and its
  // candidate index (splice). Unlike the execution position it does not move when a step is
  // spliced in before it, so a replay rebuilds the same expressions and hits the decisions cached
  // for them (DecisionCache); the analysis renumbers the chosen plan's variables by execution
  // position at the end. -1: not numbered (callers of Propagation::step number steps themselves).
  int label{-1};
};

struct TableState {
  kinematics::Transform ideal;
  kinematics::PoseError error;
};

struct HeldState {
  int grasp{-1};
  kinematics::SymbolicTransform grip;  // H: the grasp frame relative to the actual gripper
};

// The arm's error at one step, in the ideal gripper's frame: the actual gripper is M T_ΔM with
//   T_ΔM = ΔT(δq) trans(Δx_g, Δy_g, Δz_g) rotz(Δθ_g),
// SPAR's eq. 1 after the joints' ΔT (kinematics/joint_error.hpp) when the robot has joint
// uncertainty; eq. 1 alone otherwise.
struct ArmError {
  kinematics::PoseError pose;
  std::optional<kinematics::SymbolicTransform> joints;  // ΔT(δq); nullopt: no joint model
  // T_ΔM as one transform.
  [[nodiscard]] kinematics::SymbolicTransform transform() const;
  // The rotation about the gripper's approach (z) axis: Δθ_g, or with joints the z-y-x yaw of
  // T_ΔM, atan2(R_10, R_00) (its tilt about x and y is not part of it).
  [[nodiscard]] symbolic::Expr yaw() const;
};

struct Precondition {
  Builder kind{Builder::kPickup};  // the builder that made it
  bounds::Inequality inequality;
  bool length{true};  // the expression is a length in metres (else dimensionless, e.g. a cosine)
};

// The world position of `local` (object frame) of the object held with `grip` at `step` (ideal
// gripper at step.object_pose T_G, arm error `arm`): M T_ΔM H T_G^-1 local, applied right to left.
[[nodiscard]] kinematics::SymbolicPoint held_point(const WorldModel& world, const Phase2Step& step,
                                                   const ArmError& arm,
                                                   const kinematics::SymbolicTransform& grip,
                                                   const Eigen::Vector3d& local);

// SPAR's four pickup inequalities of step.object (on the table in `state`) with grasp step.grasp;
// `kind` is kPickup or kSqueeze (the name the report gives them).
[[nodiscard]] std::vector<Precondition> pickup_preconditions(const WorldModel& world,
                                                             const Phase2Step& step,
                                                             const TableState& state,
                                                             const ArmError& arm, Builder kind);

// The insertion's clearance inequalities of step.object (held as `held`) into step.fixed_object
// (on the table in `fixed`). Throws PlanError if no goal joins the two.
[[nodiscard]] std::vector<Precondition> assemble_preconditions(const WorldModel& world,
                                                               const Phase2Step& step,
                                                               const HeldState& held,
                                                               const TableState& fixed,
                                                               const ArmError& arm);

}  // namespace spar::planner
