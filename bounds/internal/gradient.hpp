// Reverse-mode gradients of a one-output tape in any domain with a TapeDomain (double for NLopt,
// Interval for enclosures of the gradient over a box).
//
// The forward pass records, per instruction, its operand values and result; the reverse pass walks
// the instructions backwards with one adjoint per slot. Work slots are reused by the tape's
// allocator, so an instruction's adjoint is read from its destination slot and that slot's
// adjoint is reset to zero before the operands receive their share: earlier values living in the
// same slot are different quantities.
#pragma once

#include <cmath>
#include <span>
#include <type_traits>
#include <vector>

#include "spar/bounds/internal/linear_enclosure.hpp"
#include "spar/bounds/interval.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds::internal {

// Partial derivatives of non-smooth operations: a generalized (Clarke) derivative enclosure.
inline double sign_partial(double x) { return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0); }
inline Interval sign_partial(const Interval& x) {
  if (x.lo > 0) return Interval{1.0};
  if (x.hi < 0) return Interval{-1.0};
  return Interval{-1.0, 1.0};
}
// d min(a, b) / d a: 1 where a is the minimum.
inline double min_partial(double a, double b) { return a < b ? 1.0 : 0.0; }
inline Interval min_partial(const Interval& a, const Interval& b) {
  if (a.hi < b.lo) return Interval{1.0};
  if (b.hi < a.lo) return Interval{0.0};
  return Interval{0.0, 1.0};
}

template <class T>
class GradientEvaluator {
 public:
  using D = symbolic::TapeDomain<T>;

  // The tape must have exactly one output and outlive the evaluator.
  explicit GradientEvaluator(const symbolic::Tape& tape)
      : tape_(&tape),
        slots_(tape.slot_count()),
        adjoints_(tape.slot_count()),
        first_(tape.instructions().size()),
        second_(tape.instructions().size()) {
    const auto constants = tape.constants();
    for (std::size_t i = 0; i < constants.size(); ++i) {
      slots_[tape.input_count() + i] = D::constant(constants[i]);
    }
  }

  // Enclosures of intermediate values valid on the feasible points only (sorted by instruction);
  // Interval only. Used by feasible_value(), never by value() or value_and_gradient(): a
  // gradient or a value at a centre or a face must hold at infeasible points too.
  void set_enclosures(std::vector<NodeEnclosure> enclosures) {
    static_assert(std::is_same_v<T, Interval>, "enclosures apply to interval evaluation");
    enclosures_ = std::move(enclosures);
  }
  [[nodiscard]] bool has_enclosures() const { return !enclosures_.empty(); }

  // f(x) only.
  T value(std::span<const T> x) { return forward(x, false); }

  // Encloses f over the feasible points of the box x, intersecting the enclosures into the
  // forward pass; empty if the enclosures show that x holds no feasible point.
  T feasible_value(std::span<const T> x) { return forward(x, true); }

  // f(x), and df/dx_i in gradient[i].
  T value_and_gradient(std::span<const T> x, std::span<T> gradient) {
    load(x);
    const auto instructions = tape_->instructions();
    for (std::size_t k = 0; k < instructions.size(); ++k) {
      symbolic::dispatch_instruction<D>(
          instructions[k], Forward{slots_.data(), instructions[k], &first_[k], &second_[k]});
    }
    const std::uint32_t output = tape_->output_slots()[0];
    const T result = slots_[output];
    std::fill(adjoints_.begin(), adjoints_.end(), T{0.0});
    adjoints_[output] = T{1.0};
    for (std::size_t k = instructions.size(); k-- > 0;) {
      const symbolic::Instruction& in = instructions[k];
      const T adjoint = adjoints_[in.dst];
      adjoints_[in.dst] = T{0.0};
      // Partials of exactly 1 or -1: the share is the adjoint itself, no product needed.
      if (in.op == symbolic::TapeOp::kAdd || in.op == symbolic::TapeOp::kSub) {
        adjoints_[in.a] = adjoints_[in.a] + adjoint;
        adjoints_[in.b] = adjoints_[in.b] + (in.op == symbolic::TapeOp::kAdd ? adjoint : -adjoint);
        continue;
      }
      if (in.op == symbolic::TapeOp::kNeg) {
        adjoints_[in.a] = adjoints_[in.a] - adjoint;
        continue;
      }
      T partial_a{0.0}, partial_b{0.0};
      partials(in, first_[k], second_[k], partial_a, partial_b);
      adjoints_[in.a] = adjoints_[in.a] + adjoint * partial_a;
      if (symbolic::is_binary(in.op)) adjoints_[in.b] = adjoints_[in.b] + adjoint * partial_b;
    }
    for (std::size_t i = 0; i < gradient.size(); ++i) gradient[i] = adjoints_[i];
    return result;
  }

 private:
  struct Forward {
    T* s;
    const symbolic::Instruction& in;
    T* first;
    T* second;
    template <class F>
    void unary(F f) {
      if (first) *first = s[in.a];
      s[in.dst] = f(s[in.a]);
    }
    template <class F>
    void binary(F f) {
      if (first) {
        *first = s[in.a];
        *second = s[in.b];
      }
      s[in.dst] = f(s[in.a], s[in.b]);
    }
  };

  // The function set the table's derivative formulas (symbolic/functions.hpp) are written over.
  struct F {
    static T one() { return T{1.0}; }
    static T square(const T& x) { return D::square(x); }
    static T sin(const T& x) { return D::sin(x); }
    static T cos(const T& x) { return D::cos(x); }
    static T tan(const T& x) { return D::tan(x); }
    static T exp(const T& x) { return D::exp(x); }
    static T sqrt(const T& x) { return D::sqrt(x); }
    static T sign(const T& x) { return sign_partial(x); }
    static T min_partial(const T& a, const T& b) { return internal::min_partial(a, b); }
  };

  static void partials(const symbolic::Instruction& in, const T& a, const T& b, T& da, T& db) {
    using symbolic::TapeOp;
    const T one{1.0};
    switch (in.op) {
      case TapeOp::kAdd:
        da = one;
        db = one;
        break;
      case TapeOp::kSub:
        da = one;
        db = T{-1.0};
        break;
      case TapeOp::kMul:
        da = b;
        db = a;
        break;
      case TapeOp::kDiv:
        da = one / b;
        db = -(a / D::square(b));
        break;
      case TapeOp::kNeg:
        da = T{-1.0};
        break;
      case TapeOp::kSquare:
        da = T{2.0} * a;
        break;
      case TapeOp::kPowInt:
        da = T{static_cast<double>(in.power)} * D::pow_int(a, in.power - 1);
        break;
      case TapeOp::kPow:
        da = b * D::pow(a, b - one);
        db = D::pow(a, b) * D::log(a);
        break;
#define SPAR_PARTIAL_UNARY(Name, name, libm, derivative) \
  case TapeOp::k##Name:                                  \
    da = derivative;                                     \
    break;
#define SPAR_PARTIAL_BINARY(Name, name, libm, by_a, by_b) \
  case TapeOp::k##Name:                                   \
    da = by_a;                                            \
    db = by_b;                                            \
    break;
        SPAR_UNARY_FUNCTIONS(SPAR_PARTIAL_UNARY)
        SPAR_BINARY_FUNCTIONS(SPAR_PARTIAL_BINARY)
#undef SPAR_PARTIAL_UNARY
#undef SPAR_PARTIAL_BINARY
    }
    if constexpr (std::is_same_v<T, Interval>) {
      // atan2(a, b) jumps by 2π where b < 0 and a crosses 0 (the branch cut): no derivative
      // bounds the change there, so monotonicity and the centred form must not be used.
      if (in.op == TapeOp::kAtan2 && b.lo < 0 && a.lo <= 0 && a.hi >= 0) {
        da = db = Interval::entire();
      }
    }
  }

  T forward(std::span<const T> x, bool refine) {
    load(x);
    const auto instructions = tape_->instructions();
    std::size_t next = 0;  // walks enclosures_ in step with k
    for (std::size_t k = 0; k < instructions.size(); ++k) {
      const symbolic::Instruction& in = instructions[k];
      symbolic::dispatch_instruction<D>(in, Forward{slots_.data(), in, nullptr, nullptr});
      if constexpr (std::is_same_v<T, Interval>) {
        for (; refine && next < enclosures_.size() && enclosures_[next].instruction == k; ++next) {
          const NodeEnclosure& e = enclosures_[next];
          slots_[in.dst] =
              intersect(slots_[in.dst], Interval{e.lower.over(x).lo, e.upper.over(x).hi});
        }
      }
    }
    return slots_[tape_->output_slots()[0]];
  }

  void load(std::span<const T> x) {
    for (std::size_t i = 0; i < tape_->input_count(); ++i) slots_[i] = x[i];
  }

  const symbolic::Tape* tape_;
  std::vector<T> slots_;
  std::vector<T> adjoints_;
  std::vector<T> first_;   // operand a of instruction k during the last value_and_gradient
  std::vector<T> second_;  // operand b (binary instructions)
  std::vector<NodeEnclosure> enclosures_;  // sorted by instruction; empty unless set
};

}  // namespace spar::bounds::internal
