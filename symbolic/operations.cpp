#include "spar/symbolic/operations.hpp"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include "spar/symbolic/tape.hpp"

namespace spar::symbolic {
namespace {

bool is_zero(Expr e) { return e.is_constant() && e.constant().is_zero(); }

// The function set the table's derivative formulas (symbolic/functions.hpp) are written over, as
// expressions. min/max are not smooth: d min(a, b)/da is 1 where a < b and 0 where a > b,
// (1 - (a - b)/|a - b|)/2, undefined where a = b (as the derivative is).
struct F {
  static double one() { return 1.0; }  // a double operand is an exact constant (expr.hpp)
  static Expr square(Expr x) { return pow(x, 2); }
  static Expr sin(Expr x) { return symbolic::sin(x); }
  static Expr cos(Expr x) { return symbolic::cos(x); }
  static Expr tan(Expr x) { return symbolic::tan(x); }
  static Expr exp(Expr x) { return symbolic::exp(x); }
  static Expr sqrt(Expr x) { return symbolic::sqrt(x); }
  static Expr sign(Expr x) { return x / abs(x); }
  static Expr min_partial(Expr a, Expr b) { return (1 - (a - b) / abs(a - b)) / 2; }
};

// d e given the derivatives of its operands (`d(operand)`), for every op.
template <class Derivative>
Expr derivative_of_node(Expr e, Expr variable, Derivative&& d) {
  ExprPool& pool = e.pool();
  switch (e.op()) {
    case Op::kConstant:
      return pool.integer(0);
    case Op::kVariable:
      return pool.integer(e == variable ? 1 : 0);
    case Op::kAdd: {
      std::vector<Term> terms;
      for (std::size_t i = 0; i < e.operand_count(); ++i) {
        const Expr di = d(e.operand(i));
        if (!is_zero(di)) terms.push_back({di, e.factor(i)});
      }
      return pool.sum(Number(), terms);
    }
    case Op::kMul: {
      // d(c Π bi^ei) = Σi c·ei·bi^(ei-1)·Π_{j≠i} bj^ej · d bi
      std::vector<Expr> terms;
      std::vector<Term> factors;
      for (std::size_t i = 0; i < e.operand_count(); ++i) {
        const Expr di = d(e.operand(i));
        if (is_zero(di)) continue;
        factors.clear();
        for (std::size_t j = 0; j < e.operand_count(); ++j) {
          factors.push_back({e.operand(j), j == i ? e.factor(j) - Number::one() : e.factor(j)});
        }
        factors.push_back({di, Number::one()});
        terms.push_back(pool.product(e.constant() * e.factor(i), factors));
      }
      return pool.sum(terms);
    }
    case Op::kPow: {  // d a^b = a^b (db log a + b da / a)
      const Expr a = e.operand(0), b = e.operand(1);
      return e * (d(b) * log(a) + b * d(a) / a);
    }
    default:
      break;
  }
  // A function: the chain rule with the table's derivatives (symbolic/functions.hpp).
  const Expr a = e.operand(0);
  const Expr da = d(a);
  if (e.operand_count() == 1) {
    if (is_zero(da)) return pool.integer(0);
    switch (e.op()) {
#define SPAR_DERIVATIVE_UNARY(Name, name, libm, derivative) \
  case Op::k##Name:                                         \
    return (derivative)*da;
      SPAR_UNARY_FUNCTIONS(SPAR_DERIVATIVE_UNARY)
#undef SPAR_DERIVATIVE_UNARY
      default:
        break;
    }
  }
  const Expr b = e.operand(1);
  const Expr db = d(b);
  switch (e.op()) {
#define SPAR_DERIVATIVE_BINARY(Name, name, libm, by_a, by_b) \
  case Op::k##Name:                                          \
    return (by_a)*da + (by_b)*db;
    SPAR_BINARY_FUNCTIONS(SPAR_DERIVATIVE_BINARY)
#undef SPAR_DERIVATIVE_BINARY
    default:
      throw std::logic_error("differentiate: unknown operation");
  }
}

// Differentiates every root with one memo table: each node's derivative is built once.
std::vector<Expr> differentiate_all(std::span<const Expr> roots, Expr variable) {
  if (!variable.is_variable()) throw SymbolicError("differentiate: not a variable");
  std::unordered_map<std::uint32_t, Expr> memo;
  auto d = [&](Expr child) { return memo.at(child.id()); };
  for (Expr e : topological_order(roots)) memo.emplace(e.id(), derivative_of_node(e, variable, d));
  std::vector<Expr> result;
  for (Expr r : roots) result.push_back(memo.at(r.id()));
  return result;
}

}  // namespace

Expr differentiate(Expr f, Expr variable) {
  return differentiate_all(std::span<const Expr>(&f, 1), variable)[0];
}

std::vector<std::vector<Expr>> jacobian(std::span<const Expr> outputs,
                                        std::span<const Expr> variables) {
  std::vector<std::vector<Expr>> j(outputs.size(), std::vector<Expr>(variables.size()));
  for (std::size_t v = 0; v < variables.size(); ++v) {
    const std::vector<Expr> column = differentiate_all(outputs, variables[v]);
    for (std::size_t i = 0; i < outputs.size(); ++i) j[i][v] = column[i];
  }
  return j;
}

namespace {

// rebuild() in `pool` (the operands' pool): constants and variables are made there too.
Expr rebuild_in(ExprPool& pool, Expr e, std::span<const Expr> operands) {
  switch (e.op()) {
    case Op::kConstant:
      return &pool == &e.pool() ? e : pool.constant(e.constant());
    case Op::kVariable:
      return &pool == &e.pool() ? e : pool.variable(e.name());
    case Op::kAdd:
    case Op::kMul: {
      std::vector<Term> terms;
      for (std::size_t i = 0; i < operands.size(); ++i) terms.push_back({operands[i], e.factor(i)});
      return e.op() == Op::kAdd ? pool.sum(e.constant(), terms) : pool.product(e.constant(), terms);
    }
    case Op::kPow:
      return pool.power(operands[0], operands[1]);
    default:
      return operands.size() == 2 ? pool.function(e.op(), operands[0], operands[1])
                                  : pool.function(e.op(), operands[0]);
  }
}

}  // namespace

Expr rebuild(Expr e, std::span<const Expr> operands) { return rebuild_in(e.pool(), e, operands); }

std::vector<Expr> copy_into(ExprPool& to, std::span<const Expr> roots) {
  if (!roots.empty() && &to == &roots.front().pool())
    return std::vector<Expr>(roots.begin(), roots.end());
  if (to.size() != 0) throw SymbolicError("copy_into: the pool to copy into must be empty");
  std::vector<Expr> nodes = topological_order(roots);
  std::sort(nodes.begin(), nodes.end(), [](Expr a, Expr b) { return a.id() < b.id(); });
  std::unordered_map<std::uint32_t, Expr> image;
  image.reserve(nodes.size());
  std::vector<Expr> operands;
  for (const Expr e : nodes) {
    operands.clear();
    for (std::size_t i = 0; i < e.operand_count(); ++i)
      operands.push_back(image.at(e.operand(i).id()));
    image.emplace(e.id(), rebuild_in(to, e, operands));
  }
  std::vector<Expr> copies;
  for (const Expr root : roots) copies.push_back(image.at(root.id()));
  return copies;
}

Expr substitute(Expr f, const std::vector<std::pair<Expr, Expr>>& replacements) {
  std::unordered_map<std::uint32_t, Expr> image;
  for (const auto& [from, to] : replacements) {
    if (!from.is_variable()) throw SymbolicError("substitute: only variables can be replaced");
    image.emplace(from.id(), to);
  }
  std::vector<Expr> operands;
  for (Expr e : topological_order(std::span<const Expr>(&f, 1))) {
    if (image.contains(e.id())) continue;
    operands.clear();
    bool changed = false;
    for (std::size_t i = 0; i < e.operand_count(); ++i) {
      const Expr old = e.operand(i);
      const Expr now = image.at(old.id());
      changed |= !(now == old);
      operands.push_back(now);
    }
    image.emplace(e.id(), changed ? rebuild(e, operands) : e);
  }
  return image.at(f.id());
}

std::vector<Expr> variables_met(std::span<const Expr> roots) {
  std::vector<Expr> vars;
  for (Expr e : topological_order(roots)) {
    if (e.is_variable()) vars.push_back(e);
  }
  return vars;
}

std::vector<Expr> free_variables(std::span<const Expr> roots) {
  std::vector<Expr> vars = variables_met(roots);
  std::sort(vars.begin(), vars.end(), [](Expr a, Expr b) { return a.name() < b.name(); });
  return vars;
}

std::vector<Expr> free_variables(Expr f) { return free_variables(std::span<const Expr>(&f, 1)); }

double evaluate(Expr f, const std::map<std::string, double>& values) {
  const std::vector<Expr> vars = free_variables(f);
  std::vector<double> point;
  for (Expr v : vars) {
    const auto it = values.find(v.name());
    if (it == values.end()) throw SymbolicError("variable '" + v.name() + "' has no value");
    point.push_back(it->second);
  }
  const Tape tape = Tape::compile(std::span<const Expr>(&f, 1), vars);
  TapeEvaluator<double> evaluator(tape);
  double out = 0;
  evaluator.evaluate(point, std::span<double>(&out, 1));
  return out;
}

std::size_t dag_size(std::span<const Expr> roots) { return topological_order(roots).size(); }
std::size_t dag_size(Expr f) { return dag_size(std::span<const Expr>(&f, 1)); }

double tree_size(Expr f) {
  std::unordered_map<std::uint32_t, double> size;
  for (Expr e : topological_order(std::span<const Expr>(&f, 1))) {
    double s = 1;
    for (std::size_t i = 0; i < e.operand_count(); ++i) s += size.at(e.operand(i).id());
    size.emplace(e.id(), s);
  }
  return size.at(f.id());
}

}  // namespace spar::symbolic
