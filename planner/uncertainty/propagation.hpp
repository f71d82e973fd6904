// Propagation of uncertain poses through a plan instance, symbolically (seed 001, "The Propagation
// of Uncertainty by Actions"), and the uncertainty preconditions of each step.
//
// State of an object (every error an expression over the instance's UncertaintySpace):
//   on the table  SPAR's eq. 2: actual pose = trans(d) Tr_O rotz(θ) R_O for its ideal pose T_O,
//                 d = (dx, dy, dz) in world coordinates, θ about world z through its origin;
//   held          actual pose = M T_ΔM H T_G^-1: the ideal gripper pose M of the current step, the
//                 arm's error T_ΔM of that step (eq. 1), the grip H (the grasp frame relative to
//                 the actual gripper, fixed from pickup to release) and the grasp T_G.
// Effects (what a step does is read off its template: adding holding(o, g) grasps, deleting it
// and adding at(o, p) releases, adding assembled(...) inserts; `sensing` and `reduction` kinds):
//   grasp (pickup at ideal gripper M = T_O T_G, arm error T_ΔM = trans(Δx_g, Δy_g, Δz_g)
//         rotz(Δθ_g)): SPAR's rule applied to the grasp centre c = T_G 0: its offset from the
//         ideal gripper, q = M^-1 (actual object pose) c, keeps its x and z, its y (the finger
//         axis) becomes the arm's Δy_g (the fingers centre it) and the object's rotation relative
//         to the ideal gripper becomes the arm's rotz(Δθ_g). So H = T_ΔM^-1 trans(q_x, Δy_g, q_z)
//         rotz(Δθ_g).
//   release (putdown to ideal pose T_P, M = T_P T_G, arm error of that step): the actual pose is
//         M T_ΔM H T_G^-1; back in eq. 2 form, d is its origin's displacement from T_P and θ the
//         angle of its rotation error about the gripper's approach axis a = R_M z, counted about
//         world z (sign of a_z): exact for a vertical approach; for a tilted one the object is
//         taken to settle on the table turned by that angle (a modelling choice).
//   range-scan  the object's d and θ are replaced by the sensor's residual (fresh variables).
//               Scanned again before it moved (its error is still the last scan's residual),
//               the two readings are fused (planner/uncertainty/probability.hpp): the worst-case
//               box is their intersection, and a Gaussian residual gets the information-form
//               sigma (CHOLMOD), e.g. sigma / sqrt(2) for two equal readings; a uniform one stays
//               uniform over the intersection. The verdicts see only the box.
//   squeeze     a grasp and a release in place with the same arm error (no motion in between).
//   insertion   the held object joins the fixed one (it is no longer tracked).
// Every step's preconditions are built from the state just before it, with the arm error
// allocated for that step. Expressions are shared DAG nodes: the node count of a later
// precondition grows linearly with the number of steps that touched the object.
//
// Preconditions (builders named in the domain):
//   pickup, squeeze  SPAR's four: 0 < [0,1,0,0] P1^-1 C1, ... (kinematics/pickup.hpp), with W_m
//                    the gripper's maximum opening and W_g the grasp's width;
//   assemble         the held object's mating point p (area centroid of its mating faces) must
//                    reach its place in the fixed object within the goal's clearance c measured
//                    perpendicular to the mating vector v: with δ = W_f^-1 W_h p - Ta p (fixed
//                    frame) and u1, u2 an orthonormal pair perpendicular to v:
//                    -c <= δ·u1 <= c and -c <= δ·u2 <= c (four inequalities); and, if the goal
//                    gives an angular clearance α > 0, the held mating axis turned by the actual
//                    relative rotation stays within α of v: (R_f^T R_h R_a^T v)·v >= cos α.
//
// Example:
//   Propagation propagation(world, pool);               // initial errors of every object
//   for (std::size_t k = 0; k < steps.size(); ++k)
//     for (const Precondition& p : propagation.step(steps[k], k + 1)) check(p);
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "spar/bounds/inequality.hpp"
#include "spar/kinematics/symbolic_transform.hpp"
#include "spar/planner/domain.hpp"
#include "spar/planner/uncertainty/space.hpp"
#include "spar/planner/world.hpp"

namespace spar::planner {

enum class StepEffect { kGrasp, kRelease, kInsert, kRangeScan, kSqueeze, kNone };
// What a template does to uncertainty, read off its kind and its add/delete lists.
[[nodiscard]] StepEffect step_effect(const ActionTemplate& action);

// One step as phase 2 sees it: an instance step or a range-scan / squeeze phase 2 inserted.
struct Phase2Step {
  int action{0};  // index into Domain::actions
  StepEffect effect{StepEffect::kNone};
  int object{-1};        // the handled (held) object
  int grasp{-1};         // grasp label of `object` (grasp, release, squeeze, insert)
  int position{-1};      // position label of `object` where it is (grasp, squeeze) or goes
                         // (release); -1 for insertions and inserted range-scans
  int fixed_object{-1};  // insertions
  kinematics::Transform object_pose{
      kinematics::Transform::Identity()};  // ideal: where it is
                                           // (grasp, squeeze, scan) or goes (release, insert: T_f
                                           // Ta)
  kinematics::Transform fixed_pose{kinematics::Transform::Identity()};
  int instance_step{-1};  // index into PlanInstance::steps; -1 when inserted by phase 2
};

struct Precondition {
  std::string kind;  // pickup, squeeze, assemble
  bounds::Inequality inequality;
  bool length{true};  // the expression is a length in metres (else dimensionless, e.g. a cosine)
};

class Propagation {
 public:
  // Allocates every object's initial error (the scenario's half-widths) in a new space over
  // `pool`. The world and the pool must outlive this. A copy is a snapshot (state and space).
  Propagation(const WorldModel& world, symbolic::ExprPool& pool);

  // Allocates the arm's error for step `index` (1-based position in execution order) if the step
  // moves the arm, builds its preconditions from the current state, then applies its effect.
  // Throws PlanError when the step does not fit the state (e.g. grasping a held object).
  [[nodiscard]] std::vector<Precondition> step(const Phase2Step& step, int index);

  // The table state of an object (nullopt while held or once inserted).
  struct TableState {
    kinematics::Transform ideal;
    kinematics::PoseError error;
  };
  [[nodiscard]] const std::optional<TableState>& on_table(int object) const {
    return table_.at(object);
  }
  [[nodiscard]] bool held(int object) const { return held_.at(object).has_value(); }
  // Range-scans from now on leave `scale` times the scenario's residual (reverse analysis of the
  // sensor); 1 by default.
  void set_sensor_scale(double scale) { sensor_scale_ = scale; }
  [[nodiscard]] const UncertaintySpace& space() const { return space_; }
  [[nodiscard]] UncertaintySpace& space() { return space_; }

 private:
  struct HeldState {
    int grasp{-1};
    kinematics::SymbolicTransform grip;  // H: the grasp frame relative to the actual gripper
  };
  [[nodiscard]] kinematics::PoseError allocate_arm(int index);
  // A range-scan's residual: half-widths and sigmas (0: uniform).
  struct Reading {
    kinematics::PoseUncertainty half_widths, sigmas;
  };
  // The residual of the last scan of `object` if it has not moved since, else nullopt.
  [[nodiscard]] std::optional<Reading> unmoved_scan(int object) const;
  // Two readings of one object fused (see the header comment).
  [[nodiscard]] Reading fused(const Reading& earlier, const Reading& latest, int object) const;
  [[nodiscard]] kinematics::SymbolicTransform grip_after_grasp(const Phase2Step& step,
                                                               const kinematics::PoseError& arm);
  // The actual world position of `local` (object frame) of the held object at `step`.
  [[nodiscard]] kinematics::SymbolicPoint held_point(const Phase2Step& step,
                                                     const kinematics::PoseError& arm,
                                                     const kinematics::SymbolicTransform& grip,
                                                     const Eigen::Vector3d& local) const;
  [[nodiscard]] TableState released(const Phase2Step& step, const kinematics::PoseError& arm,
                                    const kinematics::SymbolicTransform& grip) const;
  [[nodiscard]] std::vector<Precondition> pickup_preconditions(const Phase2Step& step,
                                                               const kinematics::PoseError& arm,
                                                               const std::string& kind) const;
  [[nodiscard]] std::vector<Precondition> assemble_preconditions(
      const Phase2Step& step, const kinematics::PoseError& arm) const;

  const WorldModel* world_;
  UncertaintySpace space_;
  std::vector<std::optional<TableState>> table_;  // per object
  std::vector<std::optional<HeldState>> held_;    // per object
  double sensor_scale_{1.0};
};

}  // namespace spar::planner
