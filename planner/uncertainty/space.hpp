// UncertaintySpace: the uncertainty variables of one plan instance, each allocated once, with its
// range and its provenance (which object or the manipulator, at which step, from which source).
//
// SPAR named its variables (dxgr, dx_o); names alone let two objects share a variable by accident.
// Here every allocation makes fresh variables with unique names (a clash gets a numeric suffix),
// and the space, not the name, says what each one is:
//   initial      an object's pose error in the scenario (eq. 2): dx_<object>, ..., dtheta_<object>
//   manipulator  the arm's error at one step (eq. 1): dx_g<step>, ..., dtheta_g<step>
//   sensor       the residual of a range-scan of an object at one step: dx_<object>_s<step>, ...
// Ranges are symmetric half-widths around the nominal 0, in metres and radians. A range can be
// narrowed or replaced later (sensing, reverse analysis); ranges() produces the box.
//
// Invariants: names are unique identifiers; every range is finite with lower <= 0 <= upper... or
// narrowed to any finite [lower, upper] by set_range; symbols_ and variables_ stay parallel.
//
// Example:
//   symbolic::ExprPool pool;
//   UncertaintySpace space(pool);
//   const kinematics::PoseError peg = space.allocate({0.0028, 0.0028, 0.0028, 0.096},
//       {.source = UncertaintySource::kInitial, .object = 0, .step = -1}, "peg");
//   const std::vector<bounds::Interval> box = space.ranges(space.symbols());
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "spar/bounds/interval.hpp"
#include "spar/kinematics/uncertain_pose.hpp"
#include "spar/symbolic/expr.hpp"

namespace spar::planner {

enum class UncertaintySource { kInitial, kManipulator, kSensor };
[[nodiscard]] const char* to_string(UncertaintySource source);  // initial, manipulator, sensor

struct Provenance {
  UncertaintySource source{UncertaintySource::kInitial};
  int object{-1};  // the object's index; -1 for the manipulator
  int step{-1};    // position in the instance's execution order (1-based); -1 for initial
};

struct SpaceVariable {
  std::string name;
  char component{'x'};  // 'x', 'y', 'z' (displacement) or 't' (rotation dtheta)
  double lower{0.0};
  double upper{0.0};
  // How it is distributed in [lower, upper] (planner/uncertainty/probability.hpp; never used by
  // a verdict): 0 = uniform; > 0 = N(0, sigma^2) truncated to the range.
  double sigma{0.0};
  Provenance provenance;
};

class UncertaintySpace {
 public:
  // The pool must outlive the space.
  explicit UncertaintySpace(symbolic::ExprPool& pool) : pool_(&pool) {}

  // Four fresh variables dx, dy, dz, dtheta with ranges [-h, h] of `half_widths`, named with
  // `tag` (see the header comment), each with its `sigmas` component (0: uniform, see
  // SpaceVariable::sigma). Throws PlanError on a negative or non-finite half-width or sigma.
  [[nodiscard]] kinematics::PoseError allocate(const kinematics::PoseUncertainty& half_widths,
                                               const Provenance& provenance, std::string_view tag,
                                               const kinematics::PoseUncertainty& sigmas = {});

  [[nodiscard]] symbolic::ExprPool& pool() const { return *pool_; }
  [[nodiscard]] const std::vector<SpaceVariable>& variables() const { return variables_; }
  [[nodiscard]] const std::vector<symbolic::Expr>& symbols() const { return symbols_; }
  // Index of a variable of this space, or -1.
  [[nodiscard]] int index_of(symbolic::Expr symbol) const;
  // Replaces the range of variable `index` (narrowing, scaling); lower <= upper, both finite.
  void set_range(int index, double lower, double upper);
  // The ranges of `symbols` (each a variable of this space), in that order.
  [[nodiscard]] std::vector<bounds::Interval> ranges(std::span<const symbolic::Expr> symbols) const;

 private:
  symbolic::ExprPool* pool_;
  std::vector<SpaceVariable> variables_;
  std::vector<symbolic::Expr>
      symbols_;  // symbols_[i] is the pool variable named variables_[i].name
};

}  // namespace spar::planner
