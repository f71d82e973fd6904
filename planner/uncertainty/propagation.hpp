// Propagation of uncertain poses through a plan instance, symbolically (seed 001, "The Propagation
// of Uncertainty by Actions"): for each step, in execution order, the preconditions its domain
// builders make from the state just before it, then its effect on the state.
//
// State: every object is on the table (TableState, SPAR's eq. 2), held (HeldState) or inserted
// (no longer tracked); see planner/uncertainty/builders.hpp. What a step does is its domain
// effect (planner/uncertainty/effects.hpp), nothing else:
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
//   sense   the object's d and θ are corrected by the sensor's reading: the range scanner's, or
//           for a camera verification (Phase2Step::camera) that camera's. Per component (dx, dy,
//           dz, dθ), the executor uses the measurement only where it knows more than it did: a
//           component whose error is already enclosed in the residual's box [-r, r]
//           (natural_enclosures of deciding.hpp, over the current ranges) keeps its error
//           expression, and the executor its belief there; every other component is replaced by
//           the residual (a fresh variable). SPAR replaced all four, which let a scan loosen a
//           component (the residual's 1.1° is worse than a putdown's 0.063°) and made the repair
//           search non-monotone in the parts' uncertainty. A kept component's values lie inside
//           [-r, r], so keeping it never widens what any precondition can take. Scanned again
//           before it moved (all four components still the last scan's residual), the two readings
//           are fused (planner/uncertainty/fusion.hpp): the worst-case box is their intersection,
//           and a Gaussian residual gets the information-form sigma (CHOLMOD), e.g. sigma / sqrt(2)
//           for two equal readings; a uniform one stays uniform over the intersection. The
//           verdicts see only the box. For the reverse analysis of the sensor (set_sensor_scale)
//           the range scanner's residual is s·u in every component (a scale variable times one
//           over the scenario's residual), so that a new scale is new ranges, not new
//           expressions: SPAR's replace-all, whose answer is conservative for the rule above (a
//           sensor of scale s corrects at least as well when it keeps what it does not beat).
//   reduce  a grasp and a release in place with the same arm error (squeeze: no motion between).
//   insert  the held object joins the fixed one (it is no longer tracked).
//   none    nothing changes.
// A step whose effect moves the arm, or that has builders, gets a fresh arm error (arm_error:
// the one place the arm's uncertainty enters): eq. 1's four variables and, when the robot has
// joint uncertainty (RobotSpec::joint_uncertainty), one variable δq_i per moving joint, through
// the exact kinematics of the chain at the step's IK solution (Phase2Step::arm, the branch its
// collisions were checked at; else WorldModel::reach of the ideal gripper M = object_pose T_G):
// T_ΔM = ΔT(δq) trans(Δx_g, Δy_g, Δz_g) rotz(Δθ_g) (builders.hpp's ArmError). The rules above then
// read, for a T_ΔM with rotation R_Δ and translation t:
//   grasp   H = R_Δ^T trans(q_x - t_x, 0, q_z - t_z) (the fingers centre the object along their
//           axis and square it with the actual gripper, tilt included; R_Δ = rotz(Δθ_g) gives
//           SPAR's rule above exactly);
//   release d as above (exact for any T_ΔM); θ the z-y-x yaw of T_ΔM about the approach axis
//           (the tilt about the gripper's x and y is taken to settle on the table, like a tilted
//           approach's).
// Pickup and insertion preconditions use T_ΔM whole (exact for any rigid error).
//
// Invariants: an object is in at most one of table_ and held_; every error is an expression over
// space_'s variables. A copy is a snapshot (state and space). The world and domain must outlive
// it; the pool too.
// Cost: a step costs its builders' expressions (DAG nodes shared with earlier steps) plus, for a
// release, one held-point transform; no bounding happens here.
//
// Example:
//   Propagation propagation(world, domain, pool);         // initial errors of every object
//   for (std::size_t k = 0; k < steps.size(); ++k)
//     for (const Precondition& p : propagation.step(steps[k], k + 1)) check(p);
#pragma once

#include <array>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "spar/planner/domain.hpp"
#include "spar/planner/uncertainty/builders.hpp"
#include "spar/planner/uncertainty/space.hpp"
#include "spar/planner/world.hpp"

namespace spar::planner {

// A range-scan's residual: half-widths and sigmas (0: uniform).
struct ScanReading {
  kinematics::PoseUncertainty half_widths, sigmas;
};

class DeferredStep;

class Propagation {
 public:
  // Allocates every object's initial error (the scenario's half-widths) in a new space over
  // `pool`.
  Propagation(const WorldModel& world, const Domain& domain, symbolic::ExprPool& pool);

  // Allocates the arm's error for step `index` if the step needs one, builds its preconditions
  // from the current state (the builders its action lists, in order), then applies its effect.
  // `index` numbers the step: it names the step's variables (dx_g<index>, <object>_s<index>,
  // dq<i>_g<index>), is their Provenance::step and names the step in errors; its 1-based position
  // in execution order, or while phase 2 searches its Phase2Step::label. Throws PlanError when the
  // step does not fit the state (e.g. grasping a held object).
  [[nodiscard]] std::vector<Precondition> step(const Phase2Step& step, int index);
  // step() with the building of its preconditions left for later: the arm's error allocated and
  // the effect applied as step() does; the result's build() gives step()'s preconditions (it
  // keeps the state before the effect). Phase 2's repair search decides the failing step first
  // and may not need the steps' before it.
  [[nodiscard]] DeferredStep step_deferred(const Phase2Step& step, int index);

  // The table state of an object (nullopt while held or once inserted).
  [[nodiscard]] const std::optional<TableState>& on_table(int object) const {
    return table_.at(object);
  }
  [[nodiscard]] bool held(int object) const { return held_.at(object).has_value(); }
  // Reverse analysis of the sensor: range-scans from now on leave `scale` times the scenario's
  // residual, each component as a product s·u of a variable u over the scenario's residual and a
  // scale variable s whose range is the one value `scale` (an unmoved earlier reading's share at
  // most, as fusion keeps). Called again, it re-scales every such residual already allocated by
  // setting the ranges of their s, so the same expressions are decided at another scale without
  // propagating or compiling again. Without a call, scans leave the scenario's residual as plain
  // variables.
  void set_sensor_scale(double scale);
  [[nodiscard]] const UncertaintySpace& space() const { return space_; }
  [[nodiscard]] UncertaintySpace& space() { return space_; }
  [[nodiscard]] const Domain& domain() const { return *domain_; }

 private:
  // The arm's error at step `index`: four fresh manipulator variables (eq. 1) and, with joint
  // uncertainty, one per joint at the step's IK solution. Throws PlanError when the joints are
  // modelled and the robot does not reach the step's gripper pose.
  [[nodiscard]] ArmError arm_error(const Phase2Step& step, int index);
  // ΔT(δq) of the step's IK solution over fresh joint variables dq<i>_g<index>.
  [[nodiscard]] kinematics::SymbolicTransform joint_error(const Phase2Step& step, int index);
  // The residual of the last scan of `object` if it has not moved since, else nullopt.
  [[nodiscard]] std::optional<ScanReading> unmoved_scan(int object) const;
  // Per component of `object`'s error, whether a reading with these half-widths corrects it:
  // false where the error is already enclosed in [-half_width, half_width].
  [[nodiscard]] std::array<bool, 4> corrected_by(int object,
                                                 const kinematics::PoseUncertainty& reading) const;
  [[nodiscard]] kinematics::SymbolicTransform grip_after_grasp(const Phase2Step& step,
                                                               const ArmError& arm);
  [[nodiscard]] TableState released(const Phase2Step& step, const ArmError& arm,
                                    const kinematics::SymbolicTransform& grip) const;
  // The arm's error of a step that needs one (it moves the arm or has builders).
  [[nodiscard]] std::optional<ArmError> arm_for(const Phase2Step& step, int index);
  [[nodiscard]] std::vector<Precondition> build(const Phase2Step& step, int index,
                                                const std::optional<ArmError>& arm) const;
  void apply(const Phase2Step& step, int index, const std::optional<ArmError>& arm);
  // A range-scan (camera -1) or the verification of camera `camera` (its residual; not scaled).
  void sense(int object, int index, int camera);
  // Throws PlanError naming the step, its action and effect unless `object` is on the table /
  // held: a domain whose `effect:` does not fit what phase 1 does with the action ends here.
  void require_on_table(const Phase2Step& step, int object, int index) const;
  void require_held(const Phase2Step& step, int index, const char* doing) const;
  // "step 2 (putdown, effect grasp)".
  [[nodiscard]] std::string step_name(const Phase2Step& step, int index) const;

  // sense() in set_sensor_scale's form.
  void sense_scaled(int object, int index);

  const WorldModel* world_;
  const Domain* domain_;
  UncertaintySpace space_;
  std::vector<std::optional<TableState>> table_;  // per object
  std::vector<std::optional<HeldState>> held_;    // per object
  // set_sensor_scale: the scale (nullopt: not called), every scale variable with the largest value
  // it may take (an earlier reading's share, else infinity), and per object the error its last
  // scaled scan left with those caps (still its error while it has not moved).
  std::optional<double> sensor_scale_;
  struct ScaleVariable {
    VariableId id;
    double cap;
  };
  std::vector<ScaleVariable> scale_variables_;
  struct ScaledScan {
    kinematics::PoseError error;
    std::array<double, 4> caps;
  };
  std::map<int, ScaledScan> scaled_scans_;
  friend class DeferredStep;
};

// A step whose preconditions Propagation::step_deferred left unbuilt.
class DeferredStep {
 public:
  [[nodiscard]] std::vector<Precondition> build() const {
    return before_.build(step_, index_, arm_);
  }

 private:
  friend class Propagation;
  DeferredStep(Propagation before, Phase2Step step, int index, std::optional<ArmError> arm)
      : before_(std::move(before)), step_(std::move(step)), index_(index), arm_(std::move(arm)) {}
  Propagation before_;  // the state the preconditions are built from
  Phase2Step step_;
  int index_;
  std::optional<ArmError> arm_;
};

}  // namespace spar::planner
