// UncertaintySpace: the uncertainty variables of one plan instance, each allocated once, with its
// range, its distribution and its provenance (which object or the manipulator, at which step,
// from which source), addressed by a VariableId.
//
// SPAR named its variables (dxgr, dx_o); names alone let two objects share a variable by accident.
// Here every allocation makes a fresh variable; its identity is its VariableId (its index in
// allocation order), and the space, not the name, says what it is. Names are for people: unique
// in the space (a clash gets a numeric suffix), built from the source:
//   initial      an object's pose error in the scenario (eq. 2): dx_<object>, ..., dtheta_<object>
//   manipulator  the arm's error at one step (eq. 1): dx_g<step>, ..., dtheta_g<step>
//   sensor       the residual of a range-scan of an object at one step: dx_<object>_s<step>, ...
//   joint        the error δq_i of the arm's moving joint i (1-based) at one step: dq<i>_g<step>,
//                an angle (revolute) or a length (prismatic); see RobotSpec::joint_uncertainty
// Ranges are symmetric half-widths around the nominal 0, in metres and radians (is_angle of the
// component). A range can be narrowed or replaced later (sensing, reverse analysis); ranges()
// produces the box of a list of ids.
//
// A new source of uncertainty (e.g. per-joint encoder errors) adds an UncertaintySource
// enumerator and allocates its variables with allocate(VariableSpec); everything downstream
// (deciding, repair, margins, probability, reports) reads ranges and provenance from the space, so
// it needs nothing else. Tolerance allocation groups variables by (source, object, component).
//
// Invariants: variables_[i] and symbols_[i] describe VariableId{i}; names are unique (the pool
// holds one variable per name, so a name is taken exactly when its pool variable is one of
// symbols_); every range is finite with lower <= upper; by_symbol_ holds each symbol's expression
// id with its VariableId, sorted by expression id.
// A copy is a snapshot: later allocations in either copy do not show in the other, and ids
// allocated before the copy mean the same variable in both. Copies are cheap (three vectors, no
// node containers): phase 2 copies the space with every propagation state it keeps.
// Cost: allocate is O(log n), O(n) moves where a symbol older than the newest is allocated again
// (a replay's), id_of O(log n), ranges O(ids).
//
// Example:
//   symbolic::ExprPool pool;
//   UncertaintySpace space(pool);
//   const kinematics::PoseError peg = space.allocate_pose({0.0028, 0.0028, 0.0028, 0.096},
//       {.source = UncertaintySource::kInitial, .object = 0, .step = -1}, "peg");
//   const VariableId dx = *space.id_of(peg.dx);                 // VariableId{0}
//   const std::vector<bounds::Interval> box = space.ranges(std::vector{dx});
#pragma once

#include <compare>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "spar/bounds/interval.hpp"
#include "spar/common/pose_component.hpp"
#include "spar/kinematics/uncertain_pose.hpp"
#include "spar/symbolic/expr.hpp"

namespace spar::planner {

// A variable of an UncertaintySpace: its index in allocation order.
struct VariableId {
  std::uint32_t index{0};
  friend auto operator<=>(VariableId, VariableId) = default;
};

enum class UncertaintySource { kInitial, kManipulator, kSensor, kJoint };
// initial, manipulator, sensor, joint
[[nodiscard]] const char* to_string(UncertaintySource source);
// The arm's own error (eq. 1's four or a joint's): reverse analysis scales it only when asked.
[[nodiscard]] inline bool of_the_arm(UncertaintySource source) {
  return source == UncertaintySource::kManipulator || source == UncertaintySource::kJoint;
}

struct Provenance {
  UncertaintySource source{UncertaintySource::kInitial};
  int object{-1};  // the object's index; -1 for the manipulator
  int step{-1};    // the step's number (Propagation::step's index): its position in execution
                   // order (1-based) in an analysis' result; -1 for initial
  int camera{-1};  // kSensor: the camera whose verification left it; -1: the range scanner
};

struct SpaceVariable {
  std::string name;
  PoseComponent component{PoseComponent::kDx};
  double lower{0.0};
  double upper{0.0};
  // How it is distributed in [lower, upper] (planner/uncertainty/probability.hpp; never used by
  // a verdict): 0 = uniform; > 0 = N(0, sigma^2) truncated to the range.
  double sigma{0.0};
  Provenance provenance;
  [[nodiscard]] bool angle() const { return is_angle(component); }
  [[nodiscard]] double half_width() const { return upper > -lower ? upper : -lower; }
};

// One variable to allocate: named `<component>_<tag>` (or `name` when given), ranging over
// [-half_width, half_width]. `component` says its unit: kDtheta an angle, the others a length.
struct VariableSpec {
  PoseComponent component{PoseComponent::kDx};
  double half_width{0.0};
  double sigma{0.0};
  Provenance provenance;
  std::string_view tag;
  std::string_view name{};
};

class UncertaintySpace {
 public:
  // The pool must outlive the space.
  explicit UncertaintySpace(symbolic::ExprPool& pool) : pool_(&pool) {}

  // A fresh variable. Throws PlanError on a negative or non-finite half-width or sigma.
  VariableId allocate(const VariableSpec& spec);
  // Four fresh variables dx, dy, dz, dtheta with ranges [-h, h] of `half_widths`, named with
  // `tag`, each with its `sigmas` component (0: uniform). Throws PlanError as allocate() does;
  // a refused allocation adds nothing.
  [[nodiscard]] kinematics::PoseError allocate_pose(const kinematics::PoseUncertainty& half_widths,
                                                    const Provenance& provenance,
                                                    std::string_view tag,
                                                    const kinematics::PoseUncertainty& sigmas = {});

  [[nodiscard]] symbolic::ExprPool& pool() const { return *pool_; }
  [[nodiscard]] std::size_t size() const { return variables_.size(); }
  [[nodiscard]] const std::vector<SpaceVariable>& variables() const { return variables_; }
  [[nodiscard]] const SpaceVariable& variable(VariableId id) const {
    return variables_.at(id.index);
  }
  [[nodiscard]] const std::vector<symbolic::Expr>& symbols() const { return symbols_; }
  [[nodiscard]] symbolic::Expr symbol(VariableId id) const { return symbols_.at(id.index); }
  // The id of a variable of this space, or nullopt (any other expression).
  [[nodiscard]] std::optional<VariableId> id_of(symbolic::Expr symbol) const;
  // Replaces the range of a variable (narrowing, scaling); lower <= upper, both finite.
  void set_range(VariableId id, double lower, double upper);
  [[nodiscard]] bounds::Interval range(VariableId id) const;
  // The ranges of `ids`, in that order.
  [[nodiscard]] std::vector<bounds::Interval> ranges(std::span<const VariableId> ids) const;

 private:
  symbolic::ExprPool* pool_;
  std::vector<SpaceVariable> variables_;
  std::vector<symbolic::Expr>
      symbols_;  // symbols_[i] is the pool variable named variables_[i].name
  std::vector<std::pair<std::uint32_t, VariableId>> by_symbol_;  // (expression id, variable)
};

}  // namespace spar::planner
