#include "spar/kinematics/pickup_template.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "spar/bounds/condition_set.hpp"
#include "spar/kinematics/internal/pickup_shared.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::kinematics {

using bounds::Interval;
using symbolic::Expr;
using symbolic::ExprPool;

namespace {

// Parameter slots. q = a·Δx_o + b·Δy_o + c·Δz_o + d·cos Δθ_o + e·sin Δθ_o + f for coordinate
// `row` (0 = x, 1 = y) of contact `contact` (0 = C1 at +W_g/2, 1 = C2 at -W_g/2): a, b, c are
// column `row` of R_F = R_O R_G, the same for both contacts; d, e, f depend on the contact.
constexpr int kVariableCount = 8;  // dx_g dy_g dz_g dtheta_g dx_o dy_o dz_o dtheta_o
constexpr int kParameterCount = 19;
constexpr int kHalfOpening = 18;
constexpr int rotation_parameter(int row, int k) { return row * 3 + k; }  // a, b, c
constexpr int contact_parameter(int row, int contact, int j) {            // d, e, f
  return 6 + (contact * 2 + row) * 3 + j;
}

std::array<Expr, kParameterCount> make_parameters(ExprPool& pool) {
  std::array<Expr, kParameterCount> parameters;
  const char* const rows[2] = {"x", "y"};
  for (int row = 0; row < 2; ++row) {
    for (int k = 0; k < 3; ++k) {
      parameters[rotation_parameter(row, k)] =
          pool.variable(std::string("pickup_") + "abc"[k] + "_" + rows[row]);
    }
    for (int contact = 0; contact < 2; ++contact) {
      for (int j = 0; j < 3; ++j) {
        parameters[contact_parameter(row, contact, j)] = pool.variable(
            std::string("pickup_") + "def"[j] + "_" + rows[row] + std::to_string(contact + 1));
      }
    }
  }
  parameters[kHalfOpening] = pool.variable("pickup_half_opening");
  return parameters;
}

// pickup_conditions' four conditions with the parameters in place of the folded numbers: the
// same transforms applied the same way, so the same occurrence structure.
std::array<PickupCondition, 4> parametric_conditions(const UncertainManipulator& gripper,
                                                     const UncertainObject& object,
                                                     const std::array<Expr, kParameterCount>& p) {
  ExprPool& pool = gripper.dx().pool();
  const Expr zero = pool.integer(0);
  const Expr atoms[5] = {object.dx(), object.dy(), object.dz(), cos(object.dtheta()),
                         sin(object.dtheta())};
  std::array<SymbolicPoint, 2> in_ideal;  // (T_O T_G)^-1 C: z is not needed (T_ΔM^-1 rows 0, 1)
  for (int contact = 0; contact < 2; ++contact) {
    for (int row = 0; row < 2; ++row) {
      const Expr terms[6] = {p[contact_parameter(row, contact, 2)],
                             p[rotation_parameter(row, 0)] * atoms[0],
                             p[rotation_parameter(row, 1)] * atoms[1],
                             p[rotation_parameter(row, 2)] * atoms[2],
                             p[contact_parameter(row, contact, 0)] * atoms[3],
                             p[contact_parameter(row, contact, 1)] * atoms[4]};
      in_ideal[contact][row] = pool.sum(terms);
    }
    in_ideal[contact][2] = zero;
  }
  const Expr half_opening = p[kHalfOpening];
  return internal::conditions_from_contacts(
      in_ideal, gripper.error(),
      {trans(zero, -half_opening, zero), trans(zero, half_opening, zero)});
}

// Enclosures of the exact parameters of `geometry` (its doubles taken as exact reals, as
// pickup_conditions takes them), mirroring possible_object_point_in's folding:
//   R_F = R_O R_G (columns x and y only), local contact = R_G (0, ±W_g/2, 0) + t_G,
//   p = R_O local, offset = t_O - t_F = -R_O t_G (t_F = R_O t_G + t_O: the same real, fewer
//   roundings); for coordinate `row` with (a0, a1, a2) column `row` of R_F:
//   d = a0 p0 + a1 p1, e = a1 p0 - a0 p1, f = a0 offset0 + a1 offset1 + a2 (offset2 + p2).
void enclose_parameters(const PickupGeometry& geometry, std::span<Interval> parameters) {
  const auto& r_o = geometry.object_pose.linear();
  const auto& r_g = geometry.grasp.linear();
  const auto& t_g = geometry.grasp.translation();
  // R_O times a vector of intervals.
  const auto rotate = [&](const Interval(&v)[3], Interval(&result)[3]) {
    for (int i = 0; i < 3; ++i) {
      result[i] =
          Interval(r_o(i, 0)) * v[0] + Interval(r_o(i, 1)) * v[1] + Interval(r_o(i, 2)) * v[2];
    }
  };
  Interval r_f[2][3], offset[3];  // r_f[row] = column `row` of R_F
  for (int row = 0; row < 2; ++row) {
    const Interval column[3] = {r_g(0, row), r_g(1, row), r_g(2, row)};
    rotate(column, r_f[row]);
  }
  const Interval grasp_origin[3] = {t_g(0), t_g(1), t_g(2)};
  rotate(grasp_origin, offset);
  for (Interval& o : offset) o = -o;
  for (int row = 0; row < 2; ++row) {
    for (int k = 0; k < 3; ++k) parameters[rotation_parameter(row, k)] = r_f[row][k];
  }
  const double half_width = geometry.object_width / 2;  // as pickup_conditions rounds it
  for (int contact = 0; contact < 2; ++contact) {
    const double y = contact == 0 ? half_width : -half_width;
    Interval local[3], p[3];
    for (int k = 0; k < 3; ++k) local[k] = Interval(r_g(k, 1)) * y + t_g(k);
    rotate(local, p);
    for (int row = 0; row < 2; ++row) {
      const auto& [a0, a1, a2] = r_f[row];
      parameters[contact_parameter(row, contact, 0)] = a0 * p[0] + a1 * p[1];
      parameters[contact_parameter(row, contact, 1)] = a1 * p[0] - a0 * p[1];
      parameters[contact_parameter(row, contact, 2)] =
          a0 * offset[0] + a1 * offset[1] + a2 * (offset[2] + p[2]);
    }
  }
  parameters[kHalfOpening] = Interval(geometry.finger_opening / 2);  // as pickup_conditions
}

}  // namespace

// Member order is construction order: the pool first, everything after refers to it.
struct PickupTemplate::Impl {
  Impl(const PoseUncertainty& gripper_bounds, const PoseUncertainty& object_bounds)
      : gripper(pool, gripper_bounds),
        object(pool, object_bounds),
        parameters(make_parameters(pool)),
        conditions(parametric_conditions(gripper, object, parameters)),
        inputs(make_inputs()),
        set(make_set()),
        tape(symbolic::Tape::compile(expressions(), inputs)),
        evaluator(tape) {
    for (const auto* uncertainty : {&gripper.variables(), &object.variables()}) {
      variables.insert(variables.end(), uncertainty->begin(), uncertainty->end());
    }
  }

  std::vector<Expr> make_inputs() const {
    std::vector<Expr> result = {gripper.dx(), gripper.dy(), gripper.dz(), gripper.dtheta(),
                                object.dx(),  object.dy(),  object.dz(),  object.dtheta()};
    result.insert(result.end(), parameters.begin(), parameters.end());
    return result;
  }
  bounds::ConditionSet make_set() const {
    std::vector<bounds::Inequality> inequalities;
    for (const PickupCondition& condition : conditions) {
      inequalities.push_back(as_inequality(condition));
    }
    return bounds::ConditionSet(std::move(inequalities), inputs);
  }
  std::vector<Expr> expressions() const {
    std::vector<Expr> result;
    for (const PickupCondition& condition : conditions) result.push_back(condition.expression);
    return result;
  }

  // The four conditions' enclosures at the uncertainty coordinates of `point` with the
  // parameters' enclosures (ranges[kVariableCount..]); the last point's values are kept, as the
  // natural pass gives every condition the same witness (the box centre).
  const std::array<Interval, 4>& values_at(std::span<const double> point) {
    if (!cached ||
        !std::equal(point.begin(), point.begin() + kVariableCount, cached_point.begin())) {
      std::copy(point.begin(), point.begin() + kVariableCount, cached_point.begin());
      for (int i = 0; i < kVariableCount; ++i) witness_inputs[i] = Interval(point[i]);
      std::copy(ranges.begin() + kVariableCount, ranges.end(),
                witness_inputs.begin() + kVariableCount);
      evaluator.evaluate(witness_inputs, cached_values);
      cached = true;
    }
    return cached_values;
  }

  // The witnesses of a check's bound (points over the uncertainty variables AND the parameters,
  // the parameters at some point of their enclosures, not necessarily the exact geometry's) made
  // rigorous for the exact geometry: values re-enclosed with the parameters' enclosures, inner
  // bounds ordered as BoundResult documents, the points cut to the uncertainty coordinates.
  void rewitness(int condition, bounds::BoundResult& bound) {
    if (!bound.argmin_value.is_empty()) {
      bound.argmin_value = values_at(bound.argmin)[condition];
      bound.argmin.resize(kVariableCount);
    }
    if (!bound.argmax_value.is_empty()) {
      bound.argmax_value = values_at(bound.argmax)[condition];
      bound.argmax.resize(kVariableCount);
    }
    bounds::order_inner_bounds(bound);
  }

  std::array<PickupCheck, 4> check(const PickupGeometry& geometry,
                                   std::span<const UncertaintyVariable> given,
                                   const bounds::BoundOptions& full) {
    internal::check_pickup_geometry(geometry);
    if (!geometry.object_pose.matrix().allFinite() || !geometry.grasp.matrix().allFinite() ||
        !std::isfinite(geometry.finger_opening) || !std::isfinite(geometry.object_width)) {
      throw KinematicsError("pickup template: the geometry's poses and widths must be finite");
    }
    internal::pickup_ranges(variables, given, std::span(ranges).first(kVariableCount));
    enclose_parameters(geometry, std::span(ranges).subspan(kVariableCount));
    cached = false;
    const std::vector<bounds::ConditionCheck> decided =
        set.check(ranges, full, bounds::Escalation::kNotSatisfied);
    std::array<PickupCheck, 4> checks;
    for (int k = 0; k < 4; ++k) {
      bounds::BoundResult bound = decided[k].bound;
      rewitness(k, bound);
      const Verdict verdict = bounds::decide(set.inequalities()[k], bound);
      checks[k] = {conditions[k], std::move(bound), verdict};
    }
    return checks;
  }

  ExprPool pool;
  UncertainManipulator gripper;
  UncertainObject object;
  std::array<Expr, kParameterCount> parameters;  // see rotation_parameter, contact_parameter
  std::array<PickupCondition, 4> conditions;     // parametric, in pickup_conditions' order
  std::vector<Expr> inputs;                      // the 8 uncertainty variables, then parameters
  bounds::ConditionSet set;                      // the conditions over `inputs`
  symbolic::Tape tape;                           // the conditions over `inputs`, for witnesses
  symbolic::TapeEvaluator<Interval> evaluator;   // of `tape`
  std::vector<UncertaintyVariable> variables;    // inputs[0..8) with the construction's bounds
  // Per check: uncertainty ranges, then parameter enclosures (the order of `inputs`).
  std::vector<Interval> ranges = std::vector<Interval>(kVariableCount + kParameterCount);
  std::vector<Interval> witness_inputs = std::vector<Interval>(kVariableCount + kParameterCount);
  std::array<double, kVariableCount> cached_point{};  // values_at's last point, valid if `cached`
  std::array<Interval, 4> cached_values;
  bool cached{false};
};

PickupTemplate::PickupTemplate(const PoseUncertainty& gripper, const PoseUncertainty& object)
    : impl_(std::make_unique<Impl>(gripper, object)) {}
PickupTemplate::PickupTemplate(PickupTemplate&&) noexcept = default;
PickupTemplate& PickupTemplate::operator=(PickupTemplate&&) noexcept = default;
PickupTemplate::~PickupTemplate() = default;

std::span<const UncertaintyVariable> PickupTemplate::variables() const { return impl_->variables; }

std::array<PickupCheck, 4> PickupTemplate::check(const PickupGeometry& geometry,
                                                 const bounds::BoundOptions& full) {
  return impl_->check(geometry, impl_->variables, full);
}

std::array<PickupCheck, 4> PickupTemplate::check(const PickupGeometry& geometry,
                                                 std::span<const UncertaintyVariable> variables,
                                                 const bounds::BoundOptions& full) {
  return impl_->check(geometry, variables, full);
}

}  // namespace spar::kinematics
