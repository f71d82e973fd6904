#include "spar/symbolic/tape.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace spar::symbolic {
namespace {

// Compilation emits instructions over virtual registers, each written exactly once (SSA);
// registers [0, input_count) are the inputs and [input_count, input_count + constants) the
// constants. A second pass maps the remaining virtual registers to reusable slots by liveness.
class Compiler {
 public:
  // `order`: every node the outputs use, operands first (topological_order).
  Compiler(std::span<const Expr> inputs, std::span<const Expr> order)
      : input_count_(inputs.size()) {
    check_inputs(inputs);
    std::size_t capacity = 16;
    while (capacity < 2 * order.size()) capacity *= 2;
    table_.assign(capacity, {kNoNode, kNoRegister});
    for (Expr e : order) insert(e.id());
    for (std::size_t i = 0; i < inputs.size(); ++i)
      if (std::uint32_t* slot = register_slot(inputs[i].id()))
        *slot = static_cast<std::uint32_t>(i);
  }

  void compile_node(Expr e) {
    std::uint32_t result = 0;
    switch (e.op()) {
      case Op::kConstant:
        result = constant(e.constant());
        break;
      case Op::kVariable:
        throw SymbolicError("variable '" + e.name() + "' is not an input of the tape");
      case Op::kAdd:
        result = compile_sum(e);
        break;
      case Op::kMul:
        result = compile_product(e);
        break;
      case Op::kPow:
        result = emit(TapeOp::kPow, of(e.operand(0)), of(e.operand(1)));
        break;
      default:
        result = e.operand_count() == 2
                     ? emit(binary_op(e.op()), of(e.operand(0)), of(e.operand(1)))
                     : emit(unary_op(e.op()), of(e.operand(0)));
    }
    *register_slot(e.id()) = result;
  }

  bool compiled(Expr e) { return *register_slot(e.id()) != kNoRegister; }
  std::uint32_t of(Expr e) { return *register_slot(e.id()); }

  static TapeOp unary_op(Op op) {
    switch (op) {
#define SPAR_MAP(Name, ...) \
  case Op::k##Name:         \
    return TapeOp::k##Name;
      SPAR_UNARY_FUNCTIONS(SPAR_MAP)
      default:
        throw std::logic_error("tape: not a unary function");
    }
  }
  static TapeOp binary_op(Op op) {
    switch (op) {
      SPAR_BINARY_FUNCTIONS(SPAR_MAP)
#undef SPAR_MAP
      default:
        throw std::logic_error("tape: not a binary function");
    }
  }

  // Each distinct constant gets one slot, in the order first met (looked up by hash: a tape may
  // hold 100 000 constants).
  std::uint32_t constant(const Number& n) {
    if (2 * (constants_.size() + 1) > constant_table_.size()) grow_constant_table();
    const std::size_t mask = constant_table_.size() - 1;
    for (std::size_t i = n.hash() & mask;; i = (i + 1) & mask) {
      std::uint32_t& entry = constant_table_[i];
      if (entry == kNoConstant) {
        entry = static_cast<std::uint32_t>(constants_.size());
        constants_.push_back(n);
        return static_cast<std::uint32_t>(input_count_) + entry;
      }
      if (constants_[entry] == n) return static_cast<std::uint32_t>(input_count_) + entry;
    }
  }
  // Doubles the constant table (at least 16 entries) and enters the constants again.
  void grow_constant_table() {
    constant_table_.assign(std::max<std::size_t>(16, 2 * constant_table_.size()), kNoConstant);
    const std::size_t mask = constant_table_.size() - 1;
    for (std::uint32_t k = 0; k < constants_.size(); ++k) {
      std::size_t i = constants_[k].hash() & mask;
      while (constant_table_[i] != kNoConstant) i = (i + 1) & mask;
      constant_table_[i] = k;
    }
  }

  std::uint32_t emit(TapeOp op, std::uint32_t a, std::uint32_t b = 0, std::int32_t power = 0) {
    code_.push_back(Instruction{op, power, next_virtual_, a, b});
    return next_virtual_++;
  }

  // c0 + Σ ci·ti as a chain of Add/Sub, scaling by |ci| where it is not one.
  std::uint32_t compile_sum(Expr e) {
    std::int64_t accumulator = -1;
    auto add = [&](std::uint32_t value, bool negative) {
      if (accumulator < 0) {
        accumulator = negative ? emit(TapeOp::kNeg, value) : value;
      } else {
        accumulator = emit(negative ? TapeOp::kSub : TapeOp::kAdd,
                           static_cast<std::uint32_t>(accumulator), value);
      }
    };
    for (std::size_t i = 0; i < e.operand_count(); ++i) {
      const Number& c = e.factor(i);
      const Number magnitude = c.is_negative() ? -c : c;
      std::uint32_t term = of(e.operand(i));
      if (!magnitude.is_one()) term = emit(TapeOp::kMul, term, constant(magnitude));
      add(term, c.is_negative());
    }
    const Number& c0 = e.constant();
    if (!c0.is_zero()) add(constant(c0.is_negative() ? -c0 : c0), c0.is_negative());
    return static_cast<std::uint32_t>(accumulator);
  }

  // base^n for an integer n >= 3 of any size, as PowInt instructions (whose power is 32-bit): with
  // n = n0 + 2^30 n1 + 2^60 n2 (each digit < 2^30), base^n0 · (base^2^30)^n1 · (base^2^60)^n2.
  // Every factor is an exact integer power, so the parity of n (the sign of a negative base) is
  // kept whatever its size: never exp(n log x), which is undefined for x < 0.
  std::uint32_t integer_power(std::uint32_t base, std::int64_t n) {
    constexpr int kDigitBits = 30;
    constexpr std::int64_t kDigit = std::int64_t{1} << kDigitBits;
    std::int64_t chain = -1;
    std::uint32_t power_of_base = base;  // base^(2^(30 k)) for the k-th digit
    for (std::int64_t rest = n; rest > 0; rest >>= kDigitBits) {
      const auto digit = static_cast<std::int32_t>(rest % kDigit);
      if (digit > 0) {
        const std::uint32_t factor =
            digit == 1 ? power_of_base : emit(TapeOp::kPowInt, power_of_base, 0, digit);
        chain = chain < 0 ? factor : emit(TapeOp::kMul, static_cast<std::uint32_t>(chain), factor);
      }
      if (rest >= kDigit) {
        power_of_base = emit(TapeOp::kPowInt, power_of_base, 0, static_cast<std::int32_t>(kDigit));
      }
    }
    return static_cast<std::uint32_t>(chain);
  }

  // c · Π bi^ei as numerator / denominator chains; negative exponents go to the denominator.
  std::uint32_t compile_product(Expr e) {
    std::int64_t numerator = -1, denominator = -1;
    auto multiply_into = [&](std::int64_t& chain, std::uint32_t value) {
      chain = chain < 0 ? value : emit(TapeOp::kMul, static_cast<std::uint32_t>(chain), value);
    };
    for (std::size_t i = 0; i < e.operand_count(); ++i) {
      const Number& exponent = e.factor(i);
      const std::uint32_t base = of(e.operand(i));
      const bool inverse = exponent.is_negative();
      const Number magnitude = inverse ? -exponent : exponent;
      std::uint32_t power;
      if (magnitude.is_one()) {
        power = base;
      } else if (magnitude == Number::integer(2)) {
        power = emit(TapeOp::kSquare, base);
      } else if (magnitude.is_integer()) {
        power = integer_power(base, magnitude.numerator());
      } else if (magnitude == Number::rational(1, 2)) {
        power = emit(TapeOp::kSqrt, base);
      } else {
        power = emit(TapeOp::kPow, base, constant(magnitude));
      }
      multiply_into(inverse ? denominator : numerator, power);
    }
    const Number& c = e.constant();
    const Number magnitude = c.is_negative() ? -c : c;
    std::uint32_t result;
    if (denominator >= 0) {
      const std::uint32_t top =
          numerator >= 0 ? static_cast<std::uint32_t>(numerator) : constant(Number::integer(1));
      result = emit(TapeOp::kDiv, top, static_cast<std::uint32_t>(denominator));
    } else {
      result = static_cast<std::uint32_t>(numerator);
    }
    if (!magnitude.is_one()) result = emit(TapeOp::kMul, result, constant(magnitude));
    if (c.is_negative()) result = emit(TapeOp::kNeg, result);
    return result;
  }

  // The first input that is not a variable, or repeats an earlier one, throws.
  static void check_inputs(std::span<const Expr> inputs) {
    std::size_t first_not_variable = inputs.size();
    for (std::size_t i = 0; i < inputs.size() && first_not_variable == inputs.size(); ++i)
      if (!inputs[i].is_variable()) first_not_variable = i;
    // (node id, position) of the variables before it: the earliest second occurrence repeats.
    std::vector<std::pair<std::uint32_t, std::size_t>> by_id;
    for (std::size_t i = 0; i < first_not_variable; ++i) by_id.emplace_back(inputs[i].id(), i);
    std::sort(by_id.begin(), by_id.end());
    std::size_t first_repeat = inputs.size();
    for (std::size_t k = 1; k < by_id.size(); ++k)
      if (by_id[k].first == by_id[k - 1].first)
        first_repeat = std::min(first_repeat, by_id[k].second);
    if (first_repeat < first_not_variable)
      throw SymbolicError("tape input '" + inputs[first_repeat].name() + "' listed twice");
    if (first_not_variable < inputs.size()) throw SymbolicError("tape input is not a variable");
  }

  // Where node `id` is or belongs in table_: linear probing from a multiplicative hash.
  std::size_t probe(std::uint32_t id) const {
    const std::size_t mask = table_.size() - 1;
    std::size_t i = (id * std::uint64_t{0x9E3779B97F4A7C15u} >> 32) & mask;
    while (table_[i].first != id && table_[i].first != kNoNode) i = (i + 1) & mask;
    return i;
  }
  void insert(std::uint32_t id) { table_[probe(id)].first = id; }
  // The register of node `id` (kNoRegister until compiled), or nullptr for a node not in the
  // order.
  std::uint32_t* register_slot(std::uint32_t id) {
    auto& entry = table_[probe(id)];
    return entry.first == id ? &entry.second : nullptr;
  }

  static constexpr std::uint32_t kNoRegister = 0xFFFFFFFFu;
  static constexpr std::uint32_t kNoNode = 0xFFFFFFFFu;  // an empty entry (ids are below 2^32 - 1)
  std::size_t input_count_;
  std::uint32_t next_virtual_ = 0x80000000u;  // virtual registers of instructions start here
  // (node id, register) of every node of the order, open addressing at most half full: a tape's
  // DAG may hold 10^5 nodes, and a node-based map allocated once per node.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> table_;
  std::vector<Instruction> code_;
  std::vector<Number> constants_;
  // Indices into constants_ by Number::hash, open addressing at most half full (a node-based map
  // allocated once per constant).
  static constexpr std::uint32_t kNoConstant = 0xFFFFFFFFu;
  std::vector<std::uint32_t> constant_table_;
};

}  // namespace

Tape Tape::compile(std::span<const Expr> outputs, std::span<const Expr> inputs) {
  // Node-id order (a node's operands exist before it, so have smaller ids): the order of the
  // nodes one output needs is the same whichever outputs are compiled with it (see slice()).
  std::vector<Expr> order = topological_order(outputs);
  std::sort(order.begin(), order.end(), [](Expr a, Expr b) { return a.id() < b.id(); });
  Compiler compiler(inputs, order);
  for (Expr e : order) {
    if (!compiler.compiled(e)) compiler.compile_node(e);
  }

  // Register allocation. Virtual registers >= 0x80000000 are instruction results; everything
  // below is a fixed input or constant slot. A result's slot is freed after its last read,
  // unless it is an output (outputs must survive to the end).
  constexpr std::uint32_t kFirstVirtual = 0x80000000u;
  const std::uint32_t fixed =
      static_cast<std::uint32_t>(inputs.size() + compiler.constants_.size());
  std::vector<Instruction>& code = compiler.code_;
  std::vector<std::size_t> last_read(code.size(), 0);
  auto index_of = [&](std::uint32_t reg) { return reg - kFirstVirtual; };
  for (std::size_t k = 0; k < code.size(); ++k) {
    if (code[k].a >= kFirstVirtual) last_read[index_of(code[k].a)] = k;
    if (is_binary(code[k].op) && code[k].b >= kFirstVirtual) last_read[index_of(code[k].b)] = k;
  }
  std::vector<bool> is_output(code.size(), false);
  for (Expr e : outputs) {
    const std::uint32_t reg = compiler.of(e);
    if (reg >= kFirstVirtual) is_output[index_of(reg)] = true;
  }
  std::vector<std::uint32_t> slot_of(code.size());
  std::vector<std::uint32_t> free_slots;
  std::uint32_t next_slot = fixed;
  auto physical = [&](std::uint32_t reg) {
    return reg >= kFirstVirtual ? slot_of[index_of(reg)] : reg;
  };
  for (std::size_t k = 0; k < code.size(); ++k) {
    Instruction& in = code[k];
    const std::uint32_t a = in.a, b = in.b;
    in.a = physical(a);
    if (is_binary(in.op)) in.b = physical(b);
    // Operands whose last read is this instruction are dead: their slots may take the result.
    for (std::uint32_t reg : {a, is_binary(in.op) ? b : a}) {
      if (reg >= kFirstVirtual && last_read[index_of(reg)] == k && !is_output[index_of(reg)]) {
        free_slots.push_back(slot_of[index_of(reg)]);
        last_read[index_of(reg)] = code.size();  // freed once even if read twice (a == b)
      }
    }
    std::uint32_t slot;
    if (free_slots.empty()) {
      slot = next_slot++;
    } else {
      slot = free_slots.back();
      free_slots.pop_back();
    }
    slot_of[k] = slot;
    in.dst = slot;
    // A result nobody reads (possible only for outputs) keeps its slot; others are freed above.
  }

  Tape tape;
  tape.input_count_ = inputs.size();
  tape.slot_count_ = next_slot;
  tape.constants_ = std::move(compiler.constants_);
  tape.instructions_ = std::move(code);
  for (Expr e : outputs) tape.output_slots_.push_back(physical(compiler.of(e)));
  return tape;
}

Tape Tape::slice(std::size_t output) const {
  if (output >= output_slots_.size())
    throw SymbolicError("tape has no output " + std::to_string(output) + " (it has " +
                        std::to_string(output_slots_.size()) + ")");
  const std::size_t fixed = input_count_ + constants_.size();
  // Backwards from the output: an instruction is kept if a kept one (or the output) reads the
  // value it writes; `wanted` marks the slots whose next write is read.
  std::vector<std::uint8_t> wanted(slot_count_, 0), kept(instructions_.size(), 0);
  wanted[output_slots_[output]] = 1;
  for (std::size_t k = instructions_.size(); k-- > 0;) {
    const Instruction& in = instructions_[k];
    if (!wanted[in.dst]) continue;
    kept[k] = 1;
    wanted[in.dst] = 0;
    wanted[in.a] = 1;
    if (is_binary(in.op)) wanted[in.b] = 1;
  }
  // The constants read (by a kept instruction or as the output), renumbered in the order first
  // read; work slots keep their numbers, moved down by the constants left out (live ranges do not
  // change: a slot a kept instruction reads was last written by a kept one).
  Tape sliced;
  sliced.input_count_ = input_count_;
  constexpr std::uint32_t kNotRead = 0xFFFFFFFFu;
  std::vector<std::uint32_t> constant_slot(constants_.size(), kNotRead);
  const auto read = [&](std::uint32_t slot) {
    if (slot < input_count_ || slot >= fixed) return;
    std::uint32_t& renumbered = constant_slot[slot - input_count_];
    if (renumbered != kNotRead) return;
    renumbered = static_cast<std::uint32_t>(input_count_ + sliced.constants_.size());
    sliced.constants_.push_back(constants_[slot - input_count_]);
  };
  for (std::size_t k = 0; k < instructions_.size(); ++k) {
    if (!kept[k]) continue;
    read(instructions_[k].a);
    if (is_binary(instructions_[k].op)) read(instructions_[k].b);
  }
  read(output_slots_[output]);
  const std::size_t shift = constants_.size() - sliced.constants_.size();
  const auto renumbered = [&](std::uint32_t slot) {
    if (slot < input_count_) return slot;
    if (slot < fixed) return constant_slot[slot - input_count_];
    return static_cast<std::uint32_t>(slot - shift);
  };
  for (std::size_t k = 0; k < instructions_.size(); ++k) {
    if (!kept[k]) continue;
    Instruction in = instructions_[k];
    in.dst = renumbered(in.dst);
    in.a = renumbered(in.a);
    if (is_binary(in.op)) in.b = renumbered(in.b);
    sliced.instructions_.push_back(in);
  }
  sliced.output_slots_ = {renumbered(output_slots_[output])};
  sliced.slot_count_ = slot_count_ - shift;
  return sliced;
}

void Tape::check_invariants() const {
  const std::size_t fixed = input_count_ + constants_.size();
  std::vector<bool> written(slot_count_, false);
  for (std::size_t i = 0; i < fixed; ++i) written[i] = true;
  for (std::size_t k = 0; k < instructions_.size(); ++k) {
    const Instruction& in = instructions_[k];
    const auto where = " (instruction " + std::to_string(k) + ")";
    if (in.dst < fixed || in.dst >= slot_count_) throw std::logic_error("bad destination" + where);
    if (in.a >= slot_count_ || !written[in.a] ||
        (is_binary(in.op) && (in.b >= slot_count_ || !written[in.b]))) {
      throw std::logic_error("reads a slot before it is written" + where);
    }
    written[in.dst] = true;
  }
  for (std::uint32_t s : output_slots_) {
    if (s >= slot_count_ || !written[s]) throw std::logic_error("output slot never written");
  }
}

namespace {
// Applies one instruction to a block of n points: the loop the compiler vectorises.
struct BlockVisitor {
  double* dst;
  const double* a;
  const double* b;
  std::size_t n;
  template <class F>
  void unary(F f) {
    for (std::size_t p = 0; p < n; ++p) dst[p] = f(a[p]);
  }
  template <class F>
  void binary(F f) {
    for (std::size_t p = 0; p < n; ++p) dst[p] = f(a[p], b[p]);
  }
};
}  // namespace

void evaluate_batch(const Tape& tape, std::span<const double> inputs, std::span<double> outputs,
                    std::size_t points) {
  // Points per block: up to 256, but few enough that the whole slot array (slots x block
  // doubles) stays within about 256 KiB, so a tape with many live slots still runs from cache.
  constexpr std::size_t kSlotArrayBudget = 32768;
  const std::size_t block = std::clamp<std::size_t>(
      kSlotArrayBudget / std::max<std::size_t>(tape.slot_count(), 1), 8, 256);
  using D = TapeDomain<double>;
  if (inputs.size() < tape.input_count() * points ||
      outputs.size() < tape.output_slots().size() * points) {
    throw SymbolicError("evaluate_batch: input or output array too small");
  }
  std::vector<double> slots(tape.slot_count() * block);
  const auto constants = tape.constants();
  for (std::size_t i = 0; i < constants.size(); ++i) {
    std::fill_n(&slots[(tape.input_count() + i) * block], block, D::constant(constants[i]));
  }
  for (std::size_t start = 0; start < points; start += block) {
    const std::size_t n = std::min(block, points - start);
    for (std::size_t i = 0; i < tape.input_count(); ++i) {
      std::copy_n(&inputs[i * points + start], n, &slots[i * block]);
    }
    double* s = slots.data();
    for (const Instruction& in : tape.instructions()) {
      dispatch_instruction<D>(
          in, BlockVisitor{s + in.dst * block, s + in.a * block, s + in.b * block, n});
    }
    const auto out = tape.output_slots();
    for (std::size_t o = 0; o < out.size(); ++o) {
      std::copy_n(&slots[out[o] * block], n, &outputs[o * points + start]);
    }
  }
}

}  // namespace spar::symbolic
