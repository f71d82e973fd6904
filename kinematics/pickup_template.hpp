// PickupTemplate: SPAR's four pickup preconditions compiled once per pair of uncertainty models,
// with the GEOMETRY as parameters, so a fresh instance (new poses, grasp, widths) only computes a
// few numbers and evaluates a tape.
//
// pickup_preconditions (kinematics/pickup.hpp) builds, per instance, the closed form
//   q = a·Δx_o + b·Δy_o + c·Δz_o + d·cos Δθ_o + e·sin Δθ_o + f    (per coordinate x, y of C1, C2)
//   condition = ±W_m/2 + cos Δθ_g (q_y - Δy_g) - sin Δθ_g (q_x - Δx_g)
// with the numbers a..f folded from the geometry. Here the same expressions are built ONCE with
// those numbers as parameter variables (19 of them, named pickup_*: a, b, c per coordinate, shared
// by both contacts; d, e, f per coordinate and contact; W_m/2), compiled into one
// bounds::ConditionSet over the eight uncertainty variables followed by the parameters.
// check(geometry) computes enclosures of the exact real parameters from the geometry's doubles
// with outward-rounded interval arithmetic (a few ulps wide) and checks the box
// (uncertainty ranges, parameter enclosures): the natural interval and the centre, bound() only
// for conditions not proved satisfied, exactly as PickupChecker does.
//
// Invariants:
//   - Sound: [lo, hi] encloses the condition over the uncertainty box for the exact geometry (the
//     exact parameters lie in their enclosures), so "satisfied" is as rigorous as the per-instance
//     path. Witness values (argmin_value, argmax_value, hence inner bounds and "violated") are
//     re-evaluated with the parameters' enclosures, so they hold for the exact geometry too;
//     argmin and argmax hold the eight uncertainty coordinates only.
//   - Same occurrence structure as pickup_preconditions (every uncertainty variable of the object
//     once per coordinate, Δθ_g twice), so bounds agree with it up to rounding (~1e-15 relative).
//   - PickupCheck::condition holds the PARAMETRIC expression of the template's own pool (variables:
//     the uncertainty variables and the pickup_* parameters); the template must outlive it.
// Not thread-safe (one template per thread); movable, not copyable.
//
// Example:
//   PickupTemplate pickup(kTable2Gripper, kTable2Object);        // once: build + compile
//   for (const PickupGeometry& geometry : instances)              // per instance: numbers + tape
//     for (const PickupCheck& check : pickup.check(geometry))
//       std::cout << check.condition.name << ' ' << to_string(check.verdict) << '\n';
#pragma once

#include <array>
#include <memory>
#include <span>

#include "spar/bounds/bound.hpp"
#include "spar/kinematics/pickup.hpp"
#include "spar/kinematics/pickup_check.hpp"

namespace spar::kinematics {

class PickupTemplate {
 public:
  // The uncertainty variables are dx_g, dy_g, dz_g, dtheta_g, dx_o, dy_o, dz_o, dtheta_o (the
  // default tags of UncertainManipulator and UncertainObject) with these half-widths. Throws
  // KinematicsError on a negative half-width.
  PickupTemplate(const PoseUncertainty& gripper, const PoseUncertainty& object);
  PickupTemplate(PickupTemplate&&) noexcept;
  PickupTemplate& operator=(PickupTemplate&&) noexcept;
  ~PickupTemplate();

  // The eight uncertainty variables with the construction's bounds, in the order check() takes.
  [[nodiscard]] std::span<const UncertaintyVariable> variables() const;

  // The four checks of `geometry` over variables(). Throws KinematicsError unless
  // 0 < finger_opening and 0 < object_width (as pickup_preconditions) and every number of the
  // geometry is finite.
  [[nodiscard]] std::array<PickupCheck, 4> check(const PickupGeometry& geometry,
                                                 const bounds::BoundOptions& full = {});
  // The same over other bounds: `variables` must name variables() in the same order; throws
  // KinematicsError otherwise or for an empty range (as PickupChecker::check).
  [[nodiscard]] std::array<PickupCheck, 4> check(const PickupGeometry& geometry,
                                                 std::span<const UncertaintyVariable> variables,
                                                 const bounds::BoundOptions& full = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spar::kinematics
