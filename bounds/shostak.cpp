#include "spar/bounds/shostak.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"

namespace spar::bounds {
namespace {

using symbolic::Expr;
using symbolic::ExprPool;
using symbolic::Number;
using symbolic::Op;
using symbolic::Term;

// Rational arithmetic that refuses to leave the exact rationals (Number turns an overflowing
// rational into a real enclosure, which would make sign tests unsound here).
Number exact(const Number& value) {
  if (!value.is_rational()) {
    throw ShostakError(ShostakFailure::kOverflow,
                       "SUP-INF: a rational coefficient overflowed 64 bits (got " +
                           value.to_string() + "); scale the constraints to smaller numbers");
  }
  return value;
}

// An expression split as constant + Σ coefficient·variable + Σ coefficient·other, where the
// `other` terms are not variables (non-linear, e.g. x*y or sin(y)).
struct SplitTerms {
  Number constant;
  std::vector<Term> linear;
  std::vector<Term> other;
};

Number checked_coefficient(const Number& value, Expr whole) {
  if (!value.is_rational()) {
    throw ShostakError(ShostakFailure::kInexact, "SUP-INF: coefficient " + value.to_string() +
                                                     " in '" + symbolic::to_string(whole) +
                                                     "' is not an exact rational");
  }
  return value;
}

SplitTerms split_terms(Expr e) {
  SplitTerms split;
  const auto classify = [&](Expr term, const Number& coefficient) {
    if (term.is_variable()) {
      split.linear.push_back({term, checked_coefficient(coefficient, e)});
    } else if (term.op() == Op::kMul && term.operand_count() == 1 &&
               term.operand(0).is_variable() && term.factor(0).is_one()) {
      // c·v is the Mul c·v^1.
      split.linear.push_back(
          {term.operand(0), checked_coefficient(exact(coefficient * term.constant()), e)});
    } else {
      split.other.push_back({term, coefficient});
    }
  };
  if (e.is_constant()) {
    split.constant = checked_coefficient(e.constant(), e);
  } else if (e.op() == Op::kAdd) {
    split.constant = checked_coefficient(e.constant(), e);
    for (std::size_t i = 0; i < e.operand_count(); ++i) classify(e.operand(i), e.factor(i));
  } else {
    classify(e, Number::integer(1));
  }
  return split;
}

LinearConstraint make_constraint(Expr lhs, Expr rhs, LinearConstraint::Relation relation) {
  const Expr expression = lhs - rhs;
  const SplitTerms split = split_terms(expression);
  if (!split.other.empty()) {
    throw ShostakError(
        ShostakFailure::kNotLinear,
        "SUP-INF: constraint term '" + symbolic::to_string(split.other.front().expr) + "' in '" +
            symbolic::to_string(lhs) + " vs " + symbolic::to_string(rhs) + "' is not linear");
  }
  return {expression, relation};
}

// ---- The SUP-INF engine over dense linear forms --------------------------------------------

// constant + Σ coefficients[i]·variable i. coefficients.size() == the engine's variable count.
struct Linear {
  Number constant;
  std::vector<Number> coefficients;
};

// min over `pieces` (a function of the kept variables); +∞ when pieces is empty and not
// minus_infinity; -∞ when minus_infinity (then pieces is empty). Pieces never repeat a
// coefficient vector (only the smallest constant of equal vectors is kept).
struct MinBound {
  bool minus_infinity{false};
  std::vector<Linear> pieces;
};

// A + B·scale (scale exact rational).
Linear add_scaled(const Linear& a, const Linear& b, const Number& scale) {
  Linear sum = a;
  sum.constant = exact(sum.constant + exact(b.constant * scale));
  for (std::size_t i = 0; i < sum.coefficients.size(); ++i) {
    if (!b.coefficients[i].is_zero()) {
      sum.coefficients[i] = exact(sum.coefficients[i] + exact(b.coefficients[i] * scale));
    }
  }
  return sum;
}

Linear scaled(const Linear& a, const Number& scale) {
  Linear zero{Number(), std::vector<Number>(a.coefficients.size())};
  return add_scaled(zero, a, scale);
}

bool is_constant(const Linear& form) {
  return std::all_of(form.coefficients.begin(), form.coefficients.end(),
                     [](const Number& c) { return c.is_zero(); });
}

class Engine {
 public:
  // Each constraint form is `form <= 0`.
  // Variables pinned by their own rows (lo <= v <= hi with lo == hi) are replaced by their value
  // everywhere: an equivalent system, so exactness is kept, and SUP-INF no longer multiplies
  // pieces through variables that cannot move (it hit the effort limit on such systems).
  Engine(std::vector<Linear> constraints, std::size_t max_steps)
      : constraints_(std::move(constraints)), max_steps_(max_steps) {
    const std::size_t n = constraints_.empty() ? 0 : constraints_.front().coefficients.size();
    std::vector<std::optional<Number>>& lower = lower_;
    std::vector<std::optional<Number>>& upper = upper_;
    lower.resize(n);
    upper.resize(n);
    for (const Linear& form : constraints_) {
      std::size_t count = 0, v = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (!form.coefficients[i].is_zero()) ++count, v = i;
      }
      if (count != 1) continue;
      // a·v + c <= 0: v <= -c/a for a > 0, v >= -c/a for a < 0.
      const Number a = form.coefficients[v];
      const Number limit = exact(-form.constant / a);
      std::optional<Number>& side = a.is_negative() ? lower[v] : upper[v];
      if (!side || (a.is_negative() ? *side < limit : limit < *side)) side = limit;
    }
    pinned_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (lower[i] && upper[i] && (*lower[i] - *upper[i]).is_zero()) pinned_[i] = lower[i];
    }
    for (Linear& form : constraints_) {
      form = substitute_pinned(form);
      if (is_constant(form) && !form.constant.is_negative() && !form.constant.is_zero()) {
        throw ShostakError(ShostakFailure::kInfeasible,
                           "SUP-INF: the constraints have no solution (a row is false once the "
                           "variables fixed by their ranges are substituted)");
      }
    }
  }

  // The target with pinned variables replaced by their values; call before sup().
  [[nodiscard]] Linear substitute_pinned(Linear form) const {
    for (std::size_t i = 0; i < pinned_.size(); ++i) {
      if (!pinned_[i] || form.coefficients[i].is_zero()) continue;
      form.constant = exact(form.constant + exact(form.coefficients[i] * *pinned_[i]));
      form.coefficients[i] = Number();
    }
    return form;
  }

  // The final min without pieces that are >= another piece on the whole variable box (so on
  // every feasible point): `min(y, 5)` under y <= 5 becomes `y`. Only for the final answer:
  // inside the recursion SUPP needs the pieces as they are.
  [[nodiscard]] MinBound without_dominated(MinBound bound) const {
    std::vector<Linear> kept;
    for (std::size_t k = 0; k < bound.pieces.size(); ++k) {
      bool dominated = false;
      for (std::size_t other = 0; other < bound.pieces.size() && !dominated; ++other) {
        // Of two pieces equal on the box, the later one goes.
        dominated = other != k && at_least(bound.pieces[k], bound.pieces[other]) &&
                    (other < k || !at_least(bound.pieces[other], bound.pieces[k]));
      }
      if (!dominated) kept.push_back(bound.pieces[k]);
    }
    bound.pieces = std::move(kept);
    return bound;
  }

  // SUP(j, S) with S = {i : kept[i]}: the min of pieces that are forms in S only.
  MinBound sup(const Linear& j, const std::vector<bool>& kept) {
    spend(1);
    std::vector<std::size_t> eliminated;
    for (std::size_t i = 0; i < j.coefficients.size(); ++i) {
      if (!j.coefficients[i].is_zero() && !kept[i]) eliminated.push_back(i);
    }
    if (eliminated.empty()) return {false, {j}};
    const std::size_t v = eliminated.front();
    const Number r = j.coefficients[v];
    Linear rest = j;  // β = j - r·v
    rest.coefficients[v] = Number();
    if (eliminated.size() == 1) {
      // SUP(K + r·v) = K + |r|·SUP(sign(r)·v); for r < 0, SUP(-v) = -INF(v).
      MinBound extreme = extreme_of_variable(v, kept, /*upper=*/!r.is_negative());
      const Number magnitude = r.is_negative() ? -r : r;
      spend(extreme.pieces.size());
      for (Linear& piece : extreme.pieces) piece = add_scaled(rest, piece, magnitude);
      return extreme;
    }
    std::vector<bool> kept_v = kept;
    kept_v[v] = true;
    const MinBound bound_rest = sup(rest, kept_v);
    if (bound_rest.minus_infinity) return bound_rest;
    MinBound result;
    for (const Linear& piece : bound_rest.pieces) {
      Linear with_v = piece;  // r·v + a, a form in S ∪ {v}
      with_v.coefficients[v] = exact(with_v.coefficients[v] + r);
      take_min(result, sup(with_v, kept));
    }
    return result;
  }

 private:
  // True if p >= q at every point of the variable box: the minimum of p - q over the box
  // (exact; a variable without a bound on the needed side makes it false) is >= 0.
  [[nodiscard]] bool at_least(const Linear& p, const Linear& q) const {
    Number least = exact(p.constant - q.constant);
    for (std::size_t i = 0; i < p.coefficients.size(); ++i) {
      const Number d = exact(p.coefficients[i] - q.coefficients[i]);
      if (d.is_zero()) continue;
      const std::optional<Number>& end = d.is_negative() ? upper_[i] : lower_[i];
      if (!end) return false;
      least = exact(least + exact(d * *end));
    }
    return !least.is_negative();
  }

  // Charges `work` steps against the effort limit.
  void spend(std::size_t work) {
    steps_ += work;
    if (steps_ > max_steps_) {
      throw ShostakError(ShostakFailure::kEffortExceeded,
                         "SUP-INF gave up after " + std::to_string(max_steps_) +
                             " steps (ShostakOptions::max_steps); raise the limit or bound fewer "
                             "variables at once");
    }
  }

  // result := min(result, other).
  void take_min(MinBound& result, MinBound other) {
    if (result.minus_infinity) return;
    spend(other.pieces.size() * (result.pieces.size() + 1));
    if (other.minus_infinity) {
      result = std::move(other);
      return;
    }
    for (Linear& piece : other.pieces) {
      const auto same =
          std::find_if(result.pieces.begin(), result.pieces.end(),
                       [&](const Linear& p) { return p.coefficients == piece.coefficients; });
      if (same == result.pieces.end()) {
        result.pieces.push_back(std::move(piece));
      } else if ((piece.constant - same->constant).is_negative()) {
        same->constant = piece.constant;
      }
    }
  }

  // SUP(v, S) when upper, else -INF(v, S); memoized, since they depend on (v, S) only and the
  // recursion asks for the same ones many times.
  MinBound extreme_of_variable(std::size_t v, const std::vector<bool>& kept, bool upper) {
    auto key = std::make_tuple(v, upper, kept);
    if (const auto found = memo_.find(key); found != memo_.end()) return found->second;
    MinBound result = upper ? sup_variable(v, kept) : minus_inf_variable(v, kept);
    memo_.emplace(std::move(key), result);
    return result;
  }

  // SUP(v, S) = SUPP(v, min over upper bounds u of v of SUP(u, S ∪ {v})).
  MinBound sup_variable(std::size_t v, const std::vector<bool>& kept) {
    const MinBound bound = bound_of_bounds(v, kept, /*upper=*/true);
    if (bound.minus_infinity) return bound;
    MinBound result;
    for (const Linear& piece : bound.pieces) {
      // v <= b·v + c.
      const Number b = piece.coefficients[v];
      Linear c = piece;
      c.coefficients[v] = Number();
      const int slope = (b - Number::integer(1)).sign();
      if (slope < 0) {
        take_min(result,
                 {false, {scaled(c, exact(Number::integer(1) / (Number::integer(1) - b)))}});
      } else if (slope == 0 && is_constant(c) && c.constant.is_negative()) {
        return {true, {}};  // v <= v + c with c < 0: no point satisfies the constraints
      }
    }
    return result;
  }

  // -INF(v, S) as a MinBound (INF = max of the negated pieces), computed dually to SUPP.
  MinBound minus_inf_variable(std::size_t v, const std::vector<bool>& kept) {
    const MinBound bound = bound_of_bounds(v, kept, /*upper=*/false);
    if (bound.minus_infinity) return bound;
    MinBound result;
    for (const Linear& piece : bound.pieces) {
      // v >= -piece = b·v + c with b = -piece_v, c = -(piece without v).
      const Number b = -piece.coefficients[v];
      Linear minus_c = piece;
      minus_c.coefficients[v] = Number();
      const int slope = (b - Number::integer(1)).sign();
      if (slope < 0) {
        // v >= c / (1 - b): the MinBound piece is -c / (1 - b).
        take_min(result,
                 {false, {scaled(minus_c, exact(Number::integer(1) / (Number::integer(1) - b)))}});
      } else if (slope == 0 && is_constant(minus_c) && minus_c.constant.is_negative()) {
        return {true, {}};  // v >= v + c with c > 0: infeasible, INF = +∞
      }
    }
    return result;
  }

  // upper: min over upper bounds u of v of SUP(u, S ∪ {v}). Lower: min over lower bounds l of v
  // of SUP(-l, S ∪ {v}) = -(max of INF(l, S ∪ {v})). +∞ (no pieces) when v has no such bound.
  MinBound bound_of_bounds(std::size_t v, const std::vector<bool>& kept, bool upper) {
    std::vector<bool> kept_v = kept;
    kept_v[v] = true;
    MinBound result;
    for (const Linear& form : constraints_) {
      // form = a·v + g <= 0 gives v <= -g/a for a > 0 and v >= -g/a for a < 0.
      const Number a = form.coefficients[v];
      if (a.is_zero() || a.is_negative() == upper) continue;
      Linear g = form;
      g.coefficients[v] = Number();
      const Linear bound = scaled(g, exact((upper ? -Number::integer(1) : Number::integer(1)) / a));
      take_min(result, sup(bound, kept_v));
      if (result.minus_infinity) break;
    }
    return result;
  }

  std::vector<Linear> constraints_;
  std::vector<std::optional<Number>> lower_, upper_;  // per variable, from one-variable rows
  std::vector<std::optional<Number>> pinned_;         // per variable: its value if the rows fix it
  std::size_t max_steps_;
  std::size_t steps_{0};
  std::map<std::tuple<std::size_t, bool, std::vector<bool>>, MinBound> memo_;
};

enum class Direction { kSup, kInf };

// Variables numbered densely in order of first appearance.
struct VariableIndex {
  std::vector<Expr> variables;
  std::unordered_map<Expr, std::size_t, symbolic::ExprHash> index;

  std::size_t of(Expr variable) {
    const auto [it, inserted] = index.emplace(variable, variables.size());
    if (inserted) variables.push_back(variable);
    return it->second;
  }
  // `split`'s linear part over `count` variables (a wrapped target's z comes last).
  [[nodiscard]] Linear linear(const SplitTerms& split, std::size_t count) const {
    Linear form{split.constant, std::vector<Number>(count)};
    for (const Term& term : split.linear) {
      Number& coefficient = form.coefficients[index.at(term.expr)];
      coefficient = exact(coefficient + term.factor);
    }
    return form;
  }
};

// The target's non-linear terms: they may mention kept variables only, and pass through.
Expr passthrough_of(ExprPool& pool, const SplitTerms& target_terms, std::span<const Expr> keep) {
  Expr passthrough = pool.integer(0);
  for (const Term& term : target_terms.other) {
    for (Expr variable : symbolic::free_variables(term.expr)) {
      if (std::find(keep.begin(), keep.end(), variable) == keep.end()) {
        throw ShostakError(ShostakFailure::kNotLinear,
                           "SUP-INF: target term '" + symbolic::to_string(term.expr) +
                               "' is not linear in the eliminated variable '" + variable.name() +
                               "' (keep it, or bound this target with interval methods)");
      }
    }
    passthrough = passthrough + pool.sum(Number(), std::span<const Term>(&term, 1));
  }
  return passthrough;
}

// The constraints as rows form <= 0 (an equality as two): one without variables is dropped when
// true, an error when false.
std::vector<Linear> constraint_rows(std::span<const LinearConstraint> constraints,
                                    const std::vector<SplitTerms>& constraint_terms,
                                    const VariableIndex& index, std::size_t count) {
  std::vector<Linear> forms;
  for (std::size_t i = 0; i < constraint_terms.size(); ++i) {
    const Linear form = index.linear(constraint_terms[i], count);
    const bool equality = constraints[i].relation == LinearConstraint::Relation::kEqual;
    if (constraint_terms[i].linear.empty()) {
      if (form.constant.is_zero() || (!equality && form.constant.is_negative())) continue;
      throw ShostakError(ShostakFailure::kInfeasible,
                         "SUP-INF: constraint '" + symbolic::to_string(constraints[i].expression) +
                             (equality ? " = 0" : " <= 0") + "' is false");
    }
    forms.push_back(form);
    if (equality) forms.push_back(scaled(form, Number::integer(-1)));
  }
  return forms;
}

// The bound from the engine's pieces: sup = min of the pieces; inf = max of the negated pieces.
Expr bound_of_pieces(ExprPool& pool, const std::vector<Linear>& pieces,
                     const std::vector<Expr>& variables, bool is_sup) {
  Expr answer;
  for (const Linear& piece : pieces) {
    std::vector<Term> terms;
    for (std::size_t i = 0; i < piece.coefficients.size(); ++i) {
      if (!piece.coefficients[i].is_zero())
        terms.push_back({variables.at(i), piece.coefficients[i]});
    }
    Expr form = pool.sum(piece.constant, terms);
    if (!is_sup) form = -form;
    answer = answer.is_null()
                 ? form
                 : (is_sup ? symbolic::min(answer, form) : symbolic::max(answer, form));
  }
  return answer;
}

Expr bound(Expr target, std::span<const LinearConstraint> constraints, std::span<const Expr> keep,
           const ShostakOptions& options, Direction direction) {
  ExprPool& pool = target.pool();
  // Variables get dense indices in order of first appearance; a wrapped target adds one more.
  VariableIndex index;
  std::vector<SplitTerms> constraint_terms;
  for (const LinearConstraint& constraint : constraints) {
    if (&constraint.expression.pool() != &pool) {
      throw ShostakError(ShostakFailure::kMalformed,
                         "SUP-INF: a constraint belongs to another ExprPool than the target");
    }
    constraint_terms.push_back(split_terms(constraint.expression));
    for (const Term& term : constraint_terms.back().linear) index.of(term.expr);
  }
  const SplitTerms target_terms = split_terms(target);
  for (const Term& term : target_terms.linear) index.of(term.expr);
  for (Expr variable : keep) {
    if (!variable.is_variable()) {
      throw ShostakError(ShostakFailure::kMalformed,
                         "SUP-INF: kept '" + symbolic::to_string(variable) + "' is not a variable");
    }
    index.of(variable);
  }
  const Expr passthrough = passthrough_of(pool, target_terms, keep);

  std::vector<bool> kept(index.variables.size(), false);
  for (Expr variable : keep) kept[index.index.at(variable)] = true;
  std::size_t eliminated_in_target = 0;
  for (const Term& term : target_terms.linear)
    eliminated_in_target += kept[index.index.at(term.expr)] ? 0 : 1;
  const bool wrap = options.wrap_target &&
                    !(target_terms.linear.size() == 1 && target_terms.linear[0].factor.is_one() &&
                      target_terms.constant.is_zero()) &&
                    eliminated_in_target > 0;
  const std::size_t count = index.variables.size() + (wrap ? 1 : 0);
  std::vector<Linear> forms = constraint_rows(constraints, constraint_terms, index, count);
  Linear objective = index.linear(target_terms, count);
  kept.resize(count, false);
  if (wrap) {
    // z = objective as z - objective <= 0 and objective - z <= 0.
    Linear z{Number(), std::vector<Number>(count)};
    z.coefficients.back() = Number::integer(1);
    forms.push_back(add_scaled(z, objective, Number::integer(-1)));
    forms.push_back(add_scaled(objective, z, Number::integer(-1)));
    objective = z;
  }
  const bool is_sup = direction == Direction::kSup;
  Engine engine(std::move(forms), options.max_steps);
  const MinBound result = engine.without_dominated(engine.sup(
      engine.substitute_pinned(is_sup ? objective : scaled(objective, Number::integer(-1))), kept));
  if (result.minus_infinity) {
    throw ShostakError(ShostakFailure::kInfeasible,
                       "SUP-INF: the constraints have no solution (found while bounding '" +
                           symbolic::to_string(target) + "')");
  }
  if (result.pieces.empty()) {
    throw ShostakError(ShostakFailure::kUnbounded,
                       std::string("SUP-INF: '") + symbolic::to_string(target) + "' is unbounded " +
                           (is_sup ? "above" : "below") + " under the constraints");
  }
  return bound_of_pieces(pool, result.pieces, index.variables, is_sup) + passthrough;
}

}  // namespace

LinearConstraint LinearConstraint::less_equal(Expr lhs, Expr rhs) {
  return make_constraint(lhs, rhs, Relation::kLessEqual);
}

LinearConstraint LinearConstraint::equal(Expr lhs, Expr rhs) {
  return make_constraint(lhs, rhs, Relation::kEqual);
}

std::vector<LinearConstraint> parse_linear_constraints(ExprPool& pool, std::string_view text) {
  // Split at the relations <=, >=, ==, =, <, > (they never occur inside an expression).
  enum class Relation { kLess, kGreater, kEqual };
  std::vector<std::string_view> sides;
  std::vector<Relation> relations;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c != '<' && c != '>' && c != '=' && c != '!') continue;
    if (c == '!') {
      throw ShostakError(ShostakFailure::kMalformed,
                         "SUP-INF: '!=' is not a linear constraint in '" + std::string(text) + "'");
    }
    sides.push_back(text.substr(start, i - start));
    relations.push_back(c == '<'   ? Relation::kLess
                        : c == '>' ? Relation::kGreater
                                   : Relation::kEqual);
    if (i + 1 < text.size() && text[i + 1] == '=') ++i;
    start = i + 1;
  }
  sides.push_back(text.substr(start));
  if (relations.empty()) {
    throw ShostakError(
        ShostakFailure::kMalformed,
        "SUP-INF: no relation (<=, >=, =, <, >) in constraint '" + std::string(text) + "'");
  }
  std::vector<Expr> expressions;
  for (std::string_view side : sides) {
    try {
      expressions.push_back(symbolic::parse(pool, side));
    } catch (const symbolic::SymbolicError& error) {
      throw ShostakError(ShostakFailure::kMalformed,
                         "SUP-INF: in constraint '" + std::string(text) + "': " + error.what());
    }
  }
  std::vector<LinearConstraint> constraints;
  for (std::size_t i = 0; i < relations.size(); ++i) {
    const Expr lhs = expressions[i], rhs = expressions[i + 1];
    switch (relations[i]) {
      case Relation::kLess:
        constraints.push_back(LinearConstraint::less_equal(lhs, rhs));
        break;
      case Relation::kGreater:
        constraints.push_back(LinearConstraint::less_equal(rhs, lhs));
        break;
      case Relation::kEqual:
        constraints.push_back(LinearConstraint::equal(lhs, rhs));
        break;
    }
  }
  return constraints;
}

LinearConstraint parse_linear_constraint(ExprPool& pool, std::string_view text) {
  std::vector<LinearConstraint> constraints = parse_linear_constraints(pool, text);
  if (constraints.size() != 1) {
    throw ShostakError(ShostakFailure::kMalformed, "SUP-INF: expected exactly one relation in '" +
                                                       std::string(text) + "', found " +
                                                       std::to_string(constraints.size()));
  }
  return constraints.front();
}

Expr sup(Expr target, std::span<const LinearConstraint> constraints, std::span<const Expr> keep,
         const ShostakOptions& options) {
  return bound(target, constraints, keep, options, Direction::kSup);
}

Expr inf(Expr target, std::span<const LinearConstraint> constraints, std::span<const Expr> keep,
         const ShostakOptions& options) {
  return bound(target, constraints, keep, options, Direction::kInf);
}

}  // namespace spar::bounds
