// Expr: hash-consed symbolic expressions over named real variables.
//
// An expression is a node in a DAG owned by an ExprPool. An `Expr` is a non-owning handle (the
// pool's address plus a 32-bit node id); it stays valid as long as its pool lives. Nodes are
// **hash-consed at construction**: building a structurally equal expression twice returns the same
// id, so equality and hashing of Expr are O(1) and shared subexpressions are stored once. A chain
// of n uncertain transforms, exponential as a tree, stays linear as a DAG.
//
// Grammar of nodes (Op) and the canonical form every node is built in:
//   Constant  a Number (exact rational or sound real enclosure; never NaN)
//   Variable  a name; one node per name in a pool
//   Add       c0 + Σ ci·ti   (constant(), then operands ti with factor() ci)
//   Mul       c · Π bi^ei    (constant() c, then operands bi with factor() ei, a Number exponent)
//   Pow       a^b with a non-constant or a real (not rational) exponent b (rational exponents
//             are Mul factors): x^pi, 2^pi, x^1.2345678901234567 are real powers; a negative
//             real exponent is the product -1·|r|, as the parser reads "x^(-r)"
//   Sin Cos Tan Sqrt Exp Log Abs Atan Asin Acos   unary functions
//   Atan2(y, x) Min(a, b) Max(a, b)                binary functions
//
// Automatic simplifications at construction (everything else is the simplifier's, see smp.hpp):
//   * Add: nested sums flattened; constants folded into c0; like terms collected (x + 2x -> 3x);
//     terms with coefficient 0 dropped (x - x -> 0) unless partial (see Domains); c0 + 1·t with
//     c0 = 0 is t; a lone scaled
//     term c·t is the Mul c·t. Each term ti is neither a rational Constant, an Add, nor a Mul
//     whose coefficient is not 1 (that coefficient moves into ci).
//   * Mul: nested products flattened (for integer outer exponents); numeric factors folded into c;
//     equal bases merged by adding exponents (x·x -> x^2, x^2/x -> x); exponent 0 dropped (x^0 ->
//     1); c = 0 gives 0; 1·b^1 is b; a constant coefficient times a sum is distributed (2·(x + y)
//     -> 2x + 2y). A base is a rational Constant only under a non-integer exponent (2^(1/2));
//     real Constants may be bases with any exponent.
//   * Flattening stops at 16 operands: a larger sum or product stays one operand of its parent
//     (and a coefficient is not distributed into such a sum: c·s stays a product),
//     so deep chains build in linear time (canonical forms above hold below that size).
//   * Operands of Add and Mul are sorted by node id, so the order of operands never matters. (One
//     exception to order-independence: distribution applies when a coefficient meets a lone sum,
//     so 3·(a/b) is the product 3·a·b^-1 while (3·a)/b is (3a)·b^-1 with 3 distributed into a.)
//   * Only exact rationals fold. A real constant (measured data, or a decimal too long to be a
//     64-bit rational) is never combined with another number: it stays a Constant operand (a sum
//     term, or a product base), so construction never rounds; bounds/ encloses it instead.
//     Hence c0, the Add coefficients and the Mul coefficient c are always rational. A fold whose
//     result overflows 64 bits gives a real rounded once (within one ulp, see number.hpp),
//     which becomes a Constant operand |r| in the same way (its sign goes to the coefficient,
//     as the parser reads "-r") and is folded no further; as with floating point, grouping may
//     change the result, but no constant is rounded twice, so printing and parsing an
//     expression gives back the same node.
//   * Functions fold only exact special values: sin(0) = 0, cos(0) = 1, exp(0) = 1, log(1) = 0,
//     sqrt of a perfect-square rational, abs of a constant, min/max of constants or of equal
//     arguments. No libm call is ever folded into a constant (that would round it).
//   * Domains are never lost. A node is partial when some real values of its variables are
//     outside its domain (log, sqrt, tan, asin, acos, atan2, real powers, x^-1, x^(1/2), and
//     anything with a partial operand). A simplification that would drop a partial part keeps
//     it as a guard term with coefficient 0, whose value is 0 where it is defined and which is
//     undefined (NaN, or an interval flagged possibly_undefined) elsewhere: log(x) - log(x) is
//     0·log(x), 0·log(x) stays, x/x is 1 + 0·x^-1, sqrt(x)^2 is x + 0·x^(1/2), 1^log(x) is
//     1 + 0·log(x). Only sums carry such zero coefficients, and only on partial terms.
// Subtraction a - b is a + (-1)·b, division a / b is a · b^-1, negation is (-1)·a.
//
// Pools are not thread-safe. Expressions from different pools never mix (checked, throws).
//
// Example:
//   ExprPool pool;
//   Expr x = pool.variable("x"), y = pool.variable("y");
//   Expr f = sin(x) * (y + 2) - x / y;
//   assert(f == sin(x) * (2 + y) - x / y);          // same node: same id
//   double v = evaluate(f, {{"x", 0.5}, {"y", 3.0}});  // see operations.hpp
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "spar/symbolic/functions.hpp"
#include "spar/symbolic/number.hpp"

namespace spar::symbolic {

// A sum or product with more operands than this is not flattened into its parent (see
// "Flattening stops" above).
inline constexpr std::uint32_t kFlattenLimit = 16;

// The functions come from the one table (symbolic/functions.hpp): unary ones, then binary ones.
enum class Op : std::uint8_t {
  kConstant,
  kVariable,
  kAdd,
  kMul,
  kPow,
#define SPAR_OP(Name, ...) k##Name,
  SPAR_UNARY_FUNCTIONS(SPAR_OP) SPAR_BINARY_FUNCTIONS(SPAR_OP)
#undef SPAR_OP
};

// What to write instead of a non-ASCII character (names and the infix syntax are ASCII).
inline constexpr const char* kAsciiHint =
    "the syntax is ASCII: write x^2 for x², '-' for −, '*' for × or ·, pi for π, and ASCII "
    "names (dtheta, not Δθ)";

// Name of a function op as written in the infix syntax ("sin", "atan2", ...); "" for others.
[[nodiscard]] std::string_view function_name(Op op);
[[nodiscard]] bool is_unary_function(Op op);
[[nodiscard]] bool is_binary_function(Op op);  // Atan2, Min, Max (Pow is not a function call)
// Every function op, in the table's order.
inline constexpr Op kFunctionOps[] = {
#define SPAR_OP(Name, ...) Op::k##Name,
    SPAR_UNARY_FUNCTIONS(SPAR_OP) SPAR_BINARY_FUNCTIONS(SPAR_OP)
#undef SPAR_OP
};

class ExprPool;
class Expr;
std::vector<Expr> topological_order(std::span<const Expr> roots);

// A handle to a node of an ExprPool. Cheap to copy; compare with ==. A default-constructed Expr
// is null (belongs to no pool) and may only be assigned to or tested with is_null().
class Expr {
 public:
  Expr() = default;

  [[nodiscard]] bool is_null() const { return pool_ == nullptr; }
  [[nodiscard]] ExprPool& pool() const { return *pool_; }
  [[nodiscard]] std::uint32_t id() const { return id_; }

  [[nodiscard]] Op op() const;
  [[nodiscard]] bool is_constant() const { return op() == Op::kConstant; }
  [[nodiscard]] bool is_variable() const { return op() == Op::kVariable; }
  // Constant: its value; Add: the constant term c0; Mul: the coefficient c; else zero.
  [[nodiscard]] const Number& constant() const;
  // Variable: its name.
  [[nodiscard]] const std::string& name() const;
  // Add terms, Mul bases, function arguments (Atan2: y then x; Pow: base then exponent).
  [[nodiscard]] std::size_t operand_count() const;
  [[nodiscard]] Expr operand(std::size_t i) const;
  // Add: the coefficient of operand(i); Mul: its exponent; else one.
  [[nodiscard]] const Number& factor(std::size_t i) const;
  // Partial: some real values of the variables are outside the domain (see "Domains" above).
  [[nodiscard]] bool is_partial() const;

  friend bool operator==(Expr a, Expr b) { return a.pool_ == b.pool_ && a.id_ == b.id_; }

 private:
  friend class ExprPool;
  friend std::vector<Expr> topological_order(std::span<const Expr> roots);
  Expr(ExprPool* pool, std::uint32_t id) : pool_(pool), id_(id) {}

  ExprPool* pool_{nullptr};
  std::uint32_t id_{0};
};

struct ExprHash {
  std::size_t operator()(Expr e) const { return e.id() * 0x9E3779B97F4A7C15ull; }
};

// A term of a sum (expr with its coefficient) or a factor of a product (base with its exponent).
struct Term {
  Expr expr;
  Number factor;
};

// The arena that owns every node. Lifetime: every Expr of a pool dangles once the pool dies.
class ExprPool {
 public:
  ExprPool();
  ~ExprPool();
  ExprPool(const ExprPool&) = delete;
  ExprPool& operator=(const ExprPool&) = delete;

  [[nodiscard]] Expr constant(const Number& value);
  [[nodiscard]] Expr constant(double value) { return constant(Number::real(value)); }
  [[nodiscard]] Expr integer(std::int64_t value) { return constant(Number::integer(value)); }
  // The variable named `name` (created on first use). Names are ASCII identifiers: a letter or
  // '_', then letters, digits, '_'; throws otherwise (a non-ASCII name with a hint).
  [[nodiscard]] Expr variable(std::string_view name);
  // Every variable created so far, in creation order.
  [[nodiscard]] std::vector<Expr> variables() const;

  // c0 + Σ factor·expr and c · Π expr^factor, canonicalised; O(n log n) in the number of terms.
  [[nodiscard]] Expr sum(const Number& constant, std::span<const Term> terms);
  [[nodiscard]] Expr product(const Number& coefficient, std::span<const Term> factors);
  [[nodiscard]] Expr sum(std::span<const Expr> terms);
  [[nodiscard]] Expr product(std::span<const Expr> factors);
  [[nodiscard]] Expr power(Expr base, const Number& exponent);
  [[nodiscard]] Expr power(Expr base, Expr exponent);
  [[nodiscard]] Expr function(Op op, Expr argument);
  [[nodiscard]] Expr function(Op op, Expr first, Expr second);

  // Number of nodes in the pool.
  [[nodiscard]] std::size_t size() const;
  // Checks every node's canonical-form invariants (listed in the header comment) and the
  // hash-consing table; throws std::logic_error naming the first broken one. O(pool size): call it
  // from tests and debug builds, not from hot paths.
  void check_invariants() const;

 private:
  friend class Expr;
  friend std::vector<Expr> topological_order(std::span<const Expr> roots);
  friend Expr operator+(Expr a, Expr b);
  friend Expr operator*(Expr a, Expr b);
  // (node id, factor) pairs of a sum or product under construction, as terms of this pool.
  [[nodiscard]] std::vector<Term> terms_of(
      std::span<const std::pair<std::uint32_t, Number>> entries);
  struct Impl;
  // sum()'s and product()'s rules, step by step (expr.cpp).
  class CanonicalForm;
  class SumForm;
  class ProductForm;
  std::unique_ptr<Impl> impl_;
};

// Arithmetic. Operands must belong to the same pool; a double operand is an exact constant.
Expr operator+(Expr a, Expr b);
Expr operator-(Expr a, Expr b);
Expr operator*(Expr a, Expr b);
Expr operator/(Expr a, Expr b);
Expr operator-(Expr a);
Expr operator+(Expr a, double b);
Expr operator+(double a, Expr b);
Expr operator-(Expr a, double b);
Expr operator-(double a, Expr b);
Expr operator*(Expr a, double b);
Expr operator*(double a, Expr b);
Expr operator/(Expr a, double b);
Expr operator/(double a, Expr b);
Expr& operator+=(Expr& a, Expr b);
Expr& operator-=(Expr& a, Expr b);
Expr& operator*=(Expr& a, Expr b);

// Every node reachable from `roots`, each once, children before parents (a topological order of
// the DAG). Iterative: safe on arbitrarily deep expressions. All roots must share one pool.
[[nodiscard]] std::vector<Expr> topological_order(std::span<const Expr> roots);

[[nodiscard]] Expr pow(Expr base, Expr exponent);
[[nodiscard]] Expr pow(Expr base, const Number& exponent);
[[nodiscard]] Expr pow(Expr base, std::int64_t exponent);
// sin(a) ... acos(a), atan2(y, x), min(a, b), max(a, b): one per entry of functions.hpp.
#define SPAR_DECLARE_UNARY(Name, name, ...) [[nodiscard]] Expr name(Expr a);
#define SPAR_DECLARE_BINARY(Name, name, ...) [[nodiscard]] Expr name(Expr a, Expr b);
SPAR_UNARY_FUNCTIONS(SPAR_DECLARE_UNARY)
SPAR_BINARY_FUNCTIONS(SPAR_DECLARE_BINARY)
#undef SPAR_DECLARE_UNARY
#undef SPAR_DECLARE_BINARY

}  // namespace spar::symbolic
