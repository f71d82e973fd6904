// Tape: expressions compiled to a flat instruction array, evaluated in any number domain.
//
// `Tape::compile(outputs, inputs)` turns one or many expressions (sharing subexpressions) into a
// list of three-address instructions over numbered slots, one node after another in node-id order
// (a node's operands are older, so have smaller ids):
//   slots [0, input_count)                       the inputs, in the order given to compile
//   slots [input_count, input_count + |consts|)  the constants (constants()[i] lives in slot
//                                                input_count + i); loaded once per evaluator
//   the rest                                      work slots, reused once their value is dead
// Invariants: every instruction reads only slots written earlier (or inputs/constants) and writes
// a work slot (checked by check_invariants()); an output's slot is never reused after the output
// is computed (guaranteed by the allocator, which never frees output registers).
// An n-ary sum or product becomes a chain of binary instructions; coefficients and exponents
// become constant slots, integer powers PowInt (of any size: see integer_power in tape.cpp), x^2
// Square, x^(1/2) Sqrt. A node's instructions depend on the node alone and the order on the ids
// alone, so the instructions one output needs come in the same order whatever is compiled with
// it: `slice(i)` takes output i's tape out of a shared one without compiling it again.
//
// A number domain T plugs in through `TapeDomain<T>` (specialise it): T needs + - * / and unary
// -, and TapeDomain<T> provides `constant(const Number&)` (for intervals: the enclosure
// [lower, upper]), square, pow_int(T, int), pow(T, T), sqrt, sin, cos, tan, exp, log, abs, atan,
// asin, acos, atan2, min, max. double is built in; bounds/ adds Interval.
//
// Example:
//   Expr f = parse(pool, "x*sin(y) + y^2");
//   Tape tape = Tape::compile({f}, {x, y});
//   TapeEvaluator<double> eval(tape);
//   double point[] = {0.5, 2.0}, out[1];
//   eval.evaluate(point, out);                       // out[0] = f(0.5, 2)
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "spar/symbolic/expr.hpp"

namespace spar::symbolic {

// The instruction set. It is not Op: n-ary Add/Mul with coefficients and exponents lower to
// binary Add/Sub/Mul/Div, Neg, Square and integer powers; only the functions are shared.
enum class TapeOp : std::uint8_t {
  kAdd,
  kSub,
  kMul,
  kDiv,
  kNeg,
  kSquare,
  kPowInt,
  kPow,
#define SPAR_TAPE_OP(Name, ...) k##Name,
  SPAR_UNARY_FUNCTIONS(SPAR_TAPE_OP) SPAR_BINARY_FUNCTIONS(SPAR_TAPE_OP)
#undef SPAR_TAPE_OP
};

// dst = op(a[, b]); `power` is the exponent of PowInt. Slots index the evaluator's array.
struct Instruction {
  TapeOp op;
  std::int32_t power;
  std::uint32_t dst;
  std::uint32_t a;
  std::uint32_t b;
};

// Whether an instruction of `op` reads its `b` slot: Add, Sub, Mul, Div, Pow and the binary
// functions; the others read `a` only.
[[nodiscard]] constexpr bool is_binary(TapeOp op) {
  switch (op) {
    case TapeOp::kAdd:
    case TapeOp::kSub:
    case TapeOp::kMul:
    case TapeOp::kDiv:
    case TapeOp::kPow:
#define SPAR_CASE(Name, ...) case TapeOp::k##Name:
      SPAR_BINARY_FUNCTIONS(SPAR_CASE)
#undef SPAR_CASE
      return true;
    default:
      return false;
  }
}

class Tape {
 public:
  // Throws SymbolicError if an output uses a variable that is not among `inputs`, or if an input
  // is not a Variable.
  [[nodiscard]] static Tape compile(std::span<const Expr> outputs, std::span<const Expr> inputs);
  // The instructions output `output` needs, as a one-output tape over the same inputs with the
  // constants it reads: instruction for instruction what compile({that output}, inputs) gives
  // (the same operations in the same order on the same inputs and constants; slot numbers, and
  // the number of work slots, may differ), so every evaluation of it equals that tape's bit for
  // bit. Costs three passes over this tape, no compile.
  // Throws SymbolicError for an output the tape does not have.
  [[nodiscard]] Tape slice(std::size_t output) const;

  [[nodiscard]] std::size_t input_count() const { return input_count_; }
  [[nodiscard]] std::size_t slot_count() const { return slot_count_; }
  [[nodiscard]] std::span<const Instruction> instructions() const { return instructions_; }
  [[nodiscard]] std::span<const Number> constants() const { return constants_; }
  [[nodiscard]] std::span<const std::uint32_t> output_slots() const { return output_slots_; }
  // Throws std::logic_error naming the first broken invariant (see the header comment).
  void check_invariants() const;

 private:
  std::size_t input_count_{0};
  std::size_t slot_count_{0};
  std::vector<Instruction> instructions_;
  std::vector<Number> constants_;
  std::vector<std::uint32_t> output_slots_;
};

template <class T>
struct TapeDomain;

template <>
struct TapeDomain<double> {
  static double constant(const Number& n) { return n.value(); }
  static double square(double x) { return x * x; }
  static double pow_int(double x, int n) {
    double result = 1.0, base = n < 0 ? 1.0 / x : x;
    for (unsigned k = n < 0 ? -static_cast<unsigned>(n) : n; k; k >>= 1, base *= base) {
      if (k & 1) result *= base;
    }
    return result;
  }
  static double pow(double x, double y) { return std::pow(x, y); }
#define SPAR_DOUBLE_UNARY(Name, name, libm, ...) \
  static double name(double x) { return std::libm(x); }
#define SPAR_DOUBLE_BINARY(Name, name, libm, ...) \
  static double name(double a, double b) { return std::libm(a, b); }
  SPAR_UNARY_FUNCTIONS(SPAR_DOUBLE_UNARY)
  SPAR_BINARY_FUNCTIONS(SPAR_DOUBLE_BINARY)
#undef SPAR_DOUBLE_UNARY
#undef SPAR_DOUBLE_BINARY
};

// Calls visitor.unary(f) or visitor.binary(f) with the instruction's operation as a generic
// callable over domain values. The one place that maps TapeOp to arithmetic, shared by every
// evaluator (scalar, batch, and bounds/'s interval and gradient evaluators).
template <class D, class Visitor>
inline void dispatch_instruction(const Instruction& in, Visitor&& visitor) {
  switch (in.op) {
    case TapeOp::kAdd:
      visitor.binary([](const auto& a, const auto& b) { return a + b; });
      break;
    case TapeOp::kSub:
      visitor.binary([](const auto& a, const auto& b) { return a - b; });
      break;
    case TapeOp::kMul:
      visitor.binary([](const auto& a, const auto& b) { return a * b; });
      break;
    case TapeOp::kDiv:
      visitor.binary([](const auto& a, const auto& b) { return a / b; });
      break;
    case TapeOp::kNeg:
      visitor.unary([](const auto& a) { return -a; });
      break;
    case TapeOp::kSquare:
      visitor.unary([](const auto& a) { return D::square(a); });
      break;
    case TapeOp::kPowInt:
      visitor.unary([n = in.power](const auto& a) { return D::pow_int(a, n); });
      break;
    case TapeOp::kPow:
      visitor.binary([](const auto& a, const auto& b) { return D::pow(a, b); });
      break;
#define SPAR_DISPATCH_UNARY(Name, name, ...)                 \
  case TapeOp::k##Name:                                      \
    visitor.unary([](const auto& a) { return D::name(a); }); \
    break;
#define SPAR_DISPATCH_BINARY(Name, name, ...)                                   \
  case TapeOp::k##Name:                                                         \
    visitor.binary([](const auto& a, const auto& b) { return D::name(a, b); }); \
    break;
      SPAR_UNARY_FUNCTIONS(SPAR_DISPATCH_UNARY)
      SPAR_BINARY_FUNCTIONS(SPAR_DISPATCH_BINARY)
#undef SPAR_DISPATCH_UNARY
#undef SPAR_DISPATCH_BINARY
  }
}

// Evaluates a tape at single points in domain T. Holds the slot array, with the constants loaded
// once at construction. The tape must outlive the evaluator.
template <class T, class D = TapeDomain<T>>
class TapeEvaluator {
 public:
  explicit TapeEvaluator(const Tape& tape) : tape_(&tape), slots_(tape.slot_count()) {
    const auto constants = tape.constants();
    for (std::size_t i = 0; i < constants.size(); ++i) {
      slots_[tape.input_count() + i] = D::constant(constants[i]);
    }
  }

  // inputs.size() == input_count(); outputs.size() == output_slots().size().
  void evaluate(std::span<const T> inputs, std::span<T> outputs) {
    for (std::size_t i = 0; i < tape_->input_count(); ++i) slots_[i] = inputs[i];
    for (const Instruction& in : tape_->instructions()) {
      dispatch_instruction<D>(in, SlotVisitor{slots_.data(), in});
    }
    const auto out = tape_->output_slots();
    for (std::size_t i = 0; i < out.size(); ++i) outputs[i] = slots_[out[i]];
  }

  // The slot array after the last evaluate(): intermediate values, for reverse-mode passes.
  [[nodiscard]] std::span<const T> slots() const { return slots_; }

 private:
  struct SlotVisitor {
    T* s;
    const Instruction& in;
    template <class F>
    void unary(F f) {
      s[in.dst] = f(s[in.a]);
    }
    template <class F>
    void binary(F f) {
      s[in.dst] = f(s[in.a], s[in.b]);
    }
  };

  const Tape* tape_;
  std::vector<T> slots_;
};

// Evaluates a tape in double at `points` points at once. inputs[i * points + p] is input i at
// point p; outputs[o * points + p] receives output o. Instructions run in the outer loop over
// blocks of points, so the inner loop is a tight, vectorisable loop over points.
void evaluate_batch(const Tape& tape, std::span<const double> inputs, std::span<double> outputs,
                    std::size_t points);

}  // namespace spar::symbolic
