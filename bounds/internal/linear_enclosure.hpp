// Linear constraints tighten the tape's affine intermediate values (a one-multiplier Lagrangian
// bound, the dual of the LP "range of L over box ∩ {C <= 0}" restricted to one constraint).
//
// If L(x) = c·x + c0 is an affine tape value and C(x) = a·x + a0 <= 0 holds on the feasible set,
// then for every multiplier λ >= 0 and every feasible x in the box X
//   L(x) <= (L - λ·C)(X).hi   and   L(x) >= (L + λ·C)(X).lo,
// because λ·C(x) <= 0. λ is chosen once (from the root box) to cancel the coefficients best; the
// forms are evaluated with outward-rounded interval arithmetic, so the enclosure is sound for any
// λ. Heron's formula under triangle inequalities is the motivating case: s - c = (a + b - c) / 2 is
// bounded below by the constraint a + b - c >= 0.01 although the box alone allows negative values.
//
// Example:
//   auto forms = affine_forms(tape);                 // per instruction, nullopt if not affine
//   auto encl = linear_enclosures(forms, {constraint}, root_box);
//   evaluator.set_enclosures(std::move(encl));       // GradientEvaluator<Interval> applies them
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "spar/bounds/interval.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds::internal {

// constant + Σ coefficients[i]·x_i, coefficients enclosing the exact real ones.
struct LinearForm {
  std::vector<Interval> coefficients;  // one per tape input, in input order
  Interval constant;

  // Outward-rounded enclosure of the form over a box (the first coefficients.size() entries).
  [[nodiscard]] Interval over(std::span<const Interval> box) const {
    Interval sum = constant;
    for (std::size_t i = 0; i < coefficients.size(); ++i) {
      const Interval& c = coefficients[i];
      if (c.lo != 0 || c.hi != 0) sum = sum + c * box[i];
    }
    return sum;
  }
  [[nodiscard]] std::size_t variable_count() const {
    std::size_t count = 0;
    for (const Interval& c : coefficients) count += (c.lo != 0 || c.hi != 0) ? 1 : 0;
    return count;
  }
};

// lower.over(X).lo <= value of `instruction` <= upper.over(X).hi for feasible points of X.
struct NodeEnclosure {
  std::size_t instruction;
  LinearForm lower, upper;
};

// The affine form of every instruction's result, or nullopt where it is not affine in the inputs.
[[nodiscard]] inline std::vector<std::optional<LinearForm>> affine_forms(
    const symbolic::Tape& tape) {
  using symbolic::TapeOp;
  const std::size_t n = tape.input_count();
  std::vector<std::optional<LinearForm>> slot(tape.slot_count());
  for (std::size_t i = 0; i < n; ++i) {
    slot[i] = LinearForm{std::vector<Interval>(n, Interval{0.0}), Interval{0.0}};
    slot[i]->coefficients[i] = Interval{1.0};
  }
  const auto constants = tape.constants();
  for (std::size_t i = 0; i < constants.size(); ++i) {
    slot[n + i] = LinearForm{std::vector<Interval>(n, Interval{0.0}), enclose(constants[i])};
  }
  const auto is_constant = [](const std::optional<LinearForm>& f) {
    return f && f->variable_count() == 0;
  };
  const auto scaled = [](LinearForm f, const Interval& factor) {
    for (Interval& c : f.coefficients) c = c * factor;
    f.constant = f.constant * factor;
    return f;
  };
  const auto combined = [](LinearForm f, const LinearForm& g, double sign) {
    for (std::size_t i = 0; i < f.coefficients.size(); ++i) {
      f.coefficients[i] = f.coefficients[i] + Interval{sign} * g.coefficients[i];
    }
    f.constant = f.constant + Interval{sign} * g.constant;
    return f;
  };
  std::vector<std::optional<LinearForm>> result;
  for (const symbolic::Instruction& in : tape.instructions()) {
    const std::optional<LinearForm> a = slot[in.a];
    const std::optional<LinearForm> b = slot[in.b];
    std::optional<LinearForm> out;
    switch (in.op) {
      case TapeOp::kAdd:
      case TapeOp::kSub:
        if (a && b) out = combined(*a, *b, in.op == TapeOp::kAdd ? 1.0 : -1.0);
        break;
      case TapeOp::kNeg:
        if (a) out = scaled(*a, Interval{-1.0});
        break;
      case TapeOp::kMul:
        if (a && is_constant(b)) out = scaled(*a, b->constant);
        if (b && is_constant(a)) out = scaled(*b, a->constant);
        break;
      case TapeOp::kDiv:
        if (a && is_constant(b) && (b->constant.lo > 0 || b->constant.hi < 0)) {
          out = scaled(*a, Interval{1.0} / b->constant);
        }
        break;
      default:
        break;
    }
    const bool bounded = out && out->constant.is_bounded() &&
                         std::all_of(out->coefficients.begin(), out->coefficients.end(),
                                     [](const Interval& c) { return c.is_bounded(); });
    if (!bounded) out.reset();
    slot[in.dst] = out;
    result.push_back(out);
  }
  return result;
}

// Enclosures for the affine instructions that involve at least two variables, one per linear
// constraint `form <= 0`. Multipliers come from the coefficient ratios, chosen to minimise the
// width of the combined form over `root`.
[[nodiscard]] inline std::vector<NodeEnclosure> linear_enclosures(
    std::span<const std::optional<LinearForm>> forms, std::span<const LinearForm> constraints,
    std::span<const Interval> root) {
  std::vector<NodeEnclosure> result;
  // L + t·C with t of either sign (t = -λ for the upper form, +λ for the lower one).
  const auto combine = [](const LinearForm& l, const LinearForm& c, double t) {
    LinearForm out = l;
    for (std::size_t i = 0; i < out.coefficients.size(); ++i) {
      out.coefficients[i] = out.coefficients[i] + Interval{t} * c.coefficients[i];
    }
    out.constant = out.constant + Interval{t} * c.constant;
    return out;
  };
  const auto width_over_root = [&](const LinearForm& f) {
    double width = 0;
    for (std::size_t i = 0; i < f.coefficients.size(); ++i) {
      width += std::max(std::fabs(f.coefficients[i].lo), std::fabs(f.coefficients[i].hi)) *
               root[i].width();
    }
    return width;
  };
  for (std::size_t k = 0; k < forms.size(); ++k) {
    if (!forms[k] || forms[k]->variable_count() < 2) continue;
    const LinearForm& l = *forms[k];
    for (const LinearForm& c : constraints) {
      // Best multiplier per side among the ratios c_i / a_i of the right sign (λ = 0: no gain).
      double best_upper = 0, best_lower = 0;
      double upper_width = width_over_root(l), lower_width = upper_width;
      for (std::size_t i = 0; i < l.coefficients.size(); ++i) {
        const double a = c.coefficients[i].mid(), coefficient = l.coefficients[i].mid();
        if (a == 0 || coefficient == 0) continue;
        const double lambda = coefficient / a;  // cancels x_i in L - λ·C
        if (!std::isfinite(lambda)) continue;
        if (lambda > 0) {
          const double w = width_over_root(combine(l, c, -lambda));
          if (w < upper_width) upper_width = w, best_upper = lambda;
        } else {
          const double w = width_over_root(combine(l, c, -lambda));
          if (w < lower_width) lower_width = w, best_lower = -lambda;
        }
      }
      if (best_upper == 0 && best_lower == 0) continue;
      result.push_back({k, combine(l, c, best_lower), combine(l, c, -best_upper)});
    }
  }
  return result;
}

}  // namespace spar::bounds::internal
