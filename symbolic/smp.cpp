#include "spar/symbolic/smp.hpp"

#include <algorithm>
#include <initializer_list>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "spar/symbolic/operations.hpp"

namespace spar::symbolic {
namespace {

// expand() leaves a product as it is rather than build more terms than this.
constexpr std::size_t kMaxExpandTerms = 4096;
// Distribution inside simplify() is a cancellation search: small products only.
constexpr std::size_t kMaxDistributeTerms = 64;
// Largest integer power of a sum that is multiplied out.
constexpr std::int64_t kMaxExpandPower = 8;
constexpr int kMaxRewritesPerNode = 16;
constexpr int kMaxPasses = 16;

std::span<const Expr> just(const Expr& e) { return {&e, 1}; }

// c·e, built directly (there is no Number·Expr operator).
Expr scaled(const Number& c, Expr e) {
  const Term t[] = {{e, Number::one()}};
  return e.pool().product(c, t);
}

bool is_trig(Expr e) { return e.op() == Op::kSin || e.op() == Op::kCos; }

// (occurrence cost, tree size), compared lexicographically.
struct Price {
  double occurrences{0};
  double size{0};
};

bool cheaper(const Price& a, const Price& b) {
  return a.occurrences < b.occurrences || (a.occurrences == b.occurrences && a.size < b.size);
}

// Tree occurrences by counting root-to-node paths: parents come after children in a topological
// order, so walking it backwards hands each node its final path count before its operands.
Price price(Expr f, const std::map<std::string, double>& widths, std::size_t& work) {
  const std::vector<Expr> order = topological_order(just(f));
  work += order.size();
  // Path counts by position in `order`, found by node id in a sorted list (a hash map's node per
  // entry was most of this function's cost; it is called once per candidate rewrite).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> position(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    position[k] = {order[k].id(), static_cast<std::uint32_t>(k)};
  std::sort(position.begin(), position.end());
  const auto at = [&](Expr e) {
    return std::lower_bound(position.begin(), position.end(), std::pair(e.id(), std::uint32_t{0}))
        ->second;
  };
  std::vector<double> paths(order.size(), 0.0);
  paths.back() = 1;  // f, the last in a topological order of it
  Price p;
  for (std::size_t k = order.size(); k-- > 0;) {
    const Expr e = order[k];
    const double n = paths[k];
    p.size += n;
    if (e.is_variable()) {
      const auto width = widths.find(e.name());
      if (n > 1) p.occurrences += (width == widths.end() ? 1.0 : width->second) * (n - 1);
      continue;
    }
    for (std::size_t i = 0; i < e.operand_count(); ++i) {
      // A guard term 0·t (expr.hpp, Domains) encloses to [0, 0] where defined: it costs no
      // occurrences, only its size.
      const bool guard = e.op() == Op::kAdd && e.factor(i).is_zero();
      if (guard) {
        p.size += n;
        continue;
      }
      paths[at(e.operand(i))] += n;
    }
  }
  return p;
}

// A term of a sum as coefficient · Π factors (a product's bases with their exponents).
struct SumTerm {
  Number coefficient;
  std::vector<Term> factors;
};

SumTerm decompose(Expr t, const Number& coefficient) {
  SumTerm term{coefficient, {}};
  if (t.op() == Op::kMul) {
    term.coefficient = coefficient * t.constant();
    for (std::size_t i = 0; i < t.operand_count(); ++i) {
      term.factors.push_back({t.operand(i), t.factor(i)});
    }
  } else {
    term.factors.push_back({t, Number::one()});
  }
  return term;
}

std::vector<SumTerm> terms_of(Expr sum) {
  std::vector<SumTerm> terms;
  for (std::size_t i = 0; i < sum.operand_count(); ++i) {
    terms.push_back(decompose(sum.operand(i), sum.factor(i)));
  }
  return terms;
}

// The product of a term's factors (without its coefficient), with factor j's exponent lowered by
// `by` (and factor l's too, if given).
Expr rest_of(ExprPool& pool, const SumTerm& term, std::size_t j, const Number& by,
             std::optional<std::size_t> l = std::nullopt) {
  std::vector<Term> factors = term.factors;
  factors[j].factor = factors[j].factor - by;
  if (l) factors[*l].factor = factors[*l].factor - by;
  return pool.product(Number::one(), factors);
}

// The sum `e` with terms `drop` removed and `added` appended (with coefficient one).
Expr replace_terms(Expr e, std::initializer_list<std::size_t> drop, std::span<const Expr> added,
                   const Number& constant) {
  std::vector<Term> kept;
  for (std::size_t i = 0; i < e.operand_count(); ++i) {
    if (std::find(drop.begin(), drop.end(), i) == drop.end()) {
      kept.push_back({e.operand(i), e.factor(i)});
    }
  }
  for (Expr a : added) kept.push_back({a, Number::one()});
  return e.pool().sum(constant, kept);
}

// An argument "looks negative" if its leading sign is: the coefficient of a product, else the
// first nonzero-signed of a sum's constant and coefficients. Negation flips exactly that sign,
// so of u and -u at most one looks negative and parity rewrites never cycle.
bool looks_negative(Expr u) {
  if (u.op() == Op::kMul || u.op() == Op::kConstant) return u.constant().sign() < 0;
  if (u.op() != Op::kAdd) return false;
  if (const int s = u.constant().sign(); s != 0) return s < 0;
  for (std::size_t i = 0; i < u.operand_count(); ++i) {
    if (const int s = u.factor(i).sign(); s != 0) return s < 0;
  }
  return false;
}

Expr parity(Expr e) {
  if (!is_unary_function(e.op()) || !looks_negative(e.operand(0))) return e;
  const Expr positive = -e.operand(0);
  switch (e.op()) {
    case Op::kSin:
    case Op::kTan:
    case Op::kAtan:
    case Op::kAsin:
      return -e.pool().function(e.op(), positive);
    case Op::kCos:
    case Op::kAbs:
      return e.pool().function(e.op(), positive);
    default:
      return e;
  }
}

// a·R·sin²u + b·R·cos²u -> a·R + (b - a)·R·cos²u
std::optional<Expr> pythagorean(Expr e) {
  ExprPool& pool = e.pool();
  const std::vector<SumTerm> terms = terms_of(e);
  struct Square {
    Op op;
    Expr argument, rest;
    std::size_t term;
  };
  std::vector<Square> squares;
  const Number two = Number::integer(2);
  for (std::size_t i = 0; i < terms.size(); ++i) {
    for (std::size_t j = 0; j < terms[i].factors.size(); ++j) {
      const Term& f = terms[i].factors[j];
      if (is_trig(f.expr) && f.factor.is_integer() && f.factor.numerator() >= 2) {
        squares.push_back({f.expr.op(), f.expr.operand(0), rest_of(pool, terms[i], j, two), i});
      }
    }
  }
  for (const Square& s : squares) {
    if (s.op != Op::kSin) continue;
    for (const Square& c : squares) {
      if (c.op != Op::kCos || c.term == s.term || !(c.argument == s.argument) ||
          !(c.rest == s.rest)) {
        continue;
      }
      const Number a = terms[s.term].coefficient, b = terms[c.term].coefficient;
      std::vector<Expr> added{scaled(a, s.rest)};
      if (!(b == a)) added.push_back(scaled(b - a, s.rest * pow(cos(c.argument), 2)));
      return replace_terms(e, {s.term, c.term}, added, e.constant());
    }
  }
  return std::nullopt;
}

// a·R·cos x·cos y ∓ a·R·sin x·sin y -> a·R·cos(x ± y),
// a·R·sin x·cos y ± a·R·cos x·sin y -> a·R·sin(x ± y).
std::optional<Expr> angle_sum(Expr e) {
  ExprPool& pool = e.pool();
  const std::vector<SumTerm> terms = terms_of(e);
  enum class Kind { kCosCos, kSinSin, kSinCos };
  struct Pair {
    Kind kind;
    Expr x, y, rest;  // cos x cos y / sin x sin y (x before y by id), or sin x cos y
    std::size_t term;
  };
  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const auto& fs = terms[i].factors;
    for (std::size_t j = 0; j < fs.size(); ++j) {
      for (std::size_t l = j + 1; l < fs.size(); ++l) {
        if (!is_trig(fs[j].expr) || !is_trig(fs[l].expr) || !fs[j].factor.is_integer() ||
            !fs[l].factor.is_integer() || fs[j].factor.numerator() < 1 ||
            fs[l].factor.numerator() < 1) {
          continue;
        }
        Expr x = fs[j].expr.operand(0), y = fs[l].expr.operand(0);
        const Op op_x = fs[j].expr.op(), op_y = fs[l].expr.op();
        Kind kind = Kind::kSinCos;
        if (op_x == op_y) {
          kind = op_x == Op::kCos ? Kind::kCosCos : Kind::kSinSin;
          if (y.id() < x.id()) std::swap(x, y);
        } else if (op_x == Op::kCos) {
          std::swap(x, y);
        }
        pairs.push_back({kind, x, y, rest_of(pool, terms[i], j, Number::one(), l), i});
      }
    }
  }
  for (const Pair& p : pairs) {
    for (const Pair& q : pairs) {
      if (p.term == q.term || !(p.rest == q.rest)) continue;
      const Number a = terms[p.term].coefficient, c = terms[q.term].coefficient;
      std::optional<Expr> contracted;
      if (p.kind == Kind::kCosCos && q.kind == Kind::kSinSin && p.x == q.x && p.y == q.y) {
        if (c == -a) contracted = scaled(a, p.rest * cos(p.x + p.y));
        if (c == a) contracted = scaled(a, p.rest * cos(p.x - p.y));
      } else if (p.kind == Kind::kSinCos && q.kind == Kind::kSinCos && p.x == q.y && p.y == q.x &&
                 !(p.x == p.y)) {
        if (c == a) contracted = scaled(a, p.rest * sin(p.x + p.y));
        if (c == -a) contracted = scaled(a, p.rest * sin(p.x - p.y));
      }
      if (contracted) return replace_terms(e, {p.term, q.term}, just(*contracted), e.constant());
    }
  }
  return std::nullopt;
}

// a·R·cos t + b·R·sin t -> sqrt(a² + b²)·R·cos(t - atan2(b, a)) for constant a, b: with
// r = sqrt(a² + b²), cos φ = a/r and sin φ = b/r, r·cos(t - φ) = a·cos t + b·sin t.
std::optional<Expr> harmonic(Expr e) {
  ExprPool& pool = e.pool();
  const std::vector<SumTerm> terms = terms_of(e);
  struct Single {
    Op op;
    Expr argument, rest;
    std::size_t term;
  };
  std::vector<Single> singles;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    for (std::size_t j = 0; j < terms[i].factors.size(); ++j) {
      const Term& f = terms[i].factors[j];
      if (is_trig(f.expr) && f.factor.is_integer() && f.factor.numerator() >= 1) {
        singles.push_back(
            {f.expr.op(), f.expr.operand(0), rest_of(pool, terms[i], j, Number::one()), i});
      }
    }
  }
  for (const Single& c : singles) {
    if (c.op != Op::kCos) continue;
    for (const Single& s : singles) {
      if (s.op != Op::kSin || s.term == c.term || !(s.argument == c.argument) ||
          !(s.rest == c.rest)) {
        continue;
      }
      const Number a = terms[c.term].coefficient, b = terms[s.term].coefficient;
      const Expr r = sqrt(pool.constant(a * a + b * b));
      const Expr phi = atan2(pool.constant(b), pool.constant(a));
      const Expr combined = r * c.rest * cos(c.argument - phi);
      return replace_terms(e, {c.term, s.term}, just(combined), e.constant());
    }
  }
  return std::nullopt;
}

// a·u² + b·u -> a·(u + b/(2a))² - b²/(4a) for constant a, b.
std::optional<Expr> complete_square(Expr e) {
  const std::vector<SumTerm> terms = terms_of(e);
  const Number two = Number::integer(2), four = Number::integer(4);
  for (std::size_t i = 0; i < terms.size(); ++i) {
    if (terms[i].factors.size() != 1 || !(terms[i].factors[0].factor == two)) continue;
    const Expr u = terms[i].factors[0].expr;
    for (std::size_t k = 0; k < terms.size(); ++k) {
      if (terms[k].factors.size() != 1 || !(terms[k].factors[0].expr == u) ||
          !terms[k].factors[0].factor.is_one()) {
        continue;
      }
      const Number a = terms[i].coefficient, b = terms[k].coefficient;
      const Expr square = scaled(a, pow(u + e.pool().constant(b / (two * a)), 2));
      return replace_terms(e, {i, k}, just(square), e.constant() - b * b / (four * a));
    }
  }
  return std::nullopt;
}

// For each base B that occurs with an integer exponent of one sign in two or more terms, the sum
// with B^m (m the exponent nearest zero) factored out of those terms. Most-shared bases first.
std::vector<Expr> factor_common(Expr e, std::size_t max_candidates) {
  ExprPool& pool = e.pool();
  const std::vector<SumTerm> terms = terms_of(e);
  struct Shared {
    Expr base;
    Number exponent;
    std::vector<std::size_t> terms;
  };
  std::vector<Shared> shared;
  std::unordered_map<std::uint64_t, std::size_t> index;  // (base id, sign) -> shared
  for (std::size_t i = 0; i < terms.size(); ++i) {
    for (const Term& f : terms[i].factors) {
      if (!f.factor.is_integer() || f.expr.is_constant()) continue;
      const bool positive = f.factor.sign() > 0;
      const std::uint64_t key = (std::uint64_t{f.expr.id()} << 1) | (positive ? 1 : 0);
      const auto [it, fresh] = index.emplace(key, shared.size());
      if (fresh) {
        shared.push_back({f.expr, f.factor, {}});
      } else {
        Number& m = shared[it->second].exponent;
        if (positive == (f.factor < m)) m = f.factor;
      }
      shared[it->second].terms.push_back(i);
    }
  }
  std::erase_if(shared, [](const Shared& s) { return s.terms.size() < 2; });
  std::stable_sort(shared.begin(), shared.end(), [](const Shared& a, const Shared& b) {
    return a.terms.size() > b.terms.size();
  });
  if (shared.size() > max_candidates) shared.resize(max_candidates);
  std::vector<Expr> candidates;
  for (const Shared& s : shared) {
    std::vector<Term> inner;
    for (std::size_t i : s.terms) {
      std::vector<Term> factors = terms[i].factors;
      for (Term& f : factors) {
        if (f.expr == s.base) f.factor = f.factor - s.exponent;
      }
      inner.push_back({pool.product(terms[i].coefficient, factors), Number::one()});
    }
    const Term factored[] = {{pool.sum(Number(), inner), Number::one()}, {s.base, s.exponent}};
    std::vector<Term> outer;
    for (std::size_t i = 0; i < terms.size(); ++i) {
      if (std::find(s.terms.begin(), s.terms.end(), i) == s.terms.end()) {
        outer.push_back({e.operand(i), e.factor(i)});
      }
    }
    outer.push_back({pool.product(Number::one(), factored), Number::one()});
    candidates.push_back(pool.sum(e.constant(), outer));
  }
  return candidates;
}

// The addends of a sum (its constant, then each coefficient·term).
std::vector<Expr> addends_of(Expr sum) {
  std::vector<Expr> addends;
  if (!sum.constant().is_zero()) addends.push_back(sum.pool().constant(sum.constant()));
  for (std::size_t i = 0; i < sum.operand_count(); ++i) {
    const Term t[] = {{sum.operand(i), sum.factor(i)}};
    addends.push_back(sum.pool().sum(Number(), t));
  }
  return addends;
}

// The product `e` with its sum factors of exponent 1..kMaxExpandPower multiplied out, as long
// as the number of terms stays within `max_terms` (a factor that would exceed it stays a
// factor). nullopt if nothing was multiplied out.
std::optional<Expr> distribute(Expr e, std::size_t max_terms) {
  if (e.op() != Op::kMul) return std::nullopt;
  ExprPool& pool = e.pool();
  std::vector<Expr> products{pool.constant(e.constant())};
  std::vector<Term> others;
  bool distributed = false;
  for (std::size_t i = 0; i < e.operand_count(); ++i) {
    const Expr base = e.operand(i);
    const Number exponent = e.factor(i);  // a copy: building p * a below may move the nodes
    const bool expandable = base.op() == Op::kAdd && exponent.is_integer() &&
                            exponent.numerator() >= 1 && exponent.numerator() <= kMaxExpandPower;
    std::vector<Expr> addends;
    double count = static_cast<double>(products.size());
    if (expandable) {
      addends = addends_of(base);
      for (std::int64_t k = 0; k < exponent.numerator(); ++k) count *= addends.size();
    }
    if (!expandable || count > static_cast<double>(max_terms)) {
      others.push_back({base, exponent});
      continue;
    }
    for (std::int64_t k = 0; k < exponent.numerator(); ++k) {
      std::vector<Expr> next;
      next.reserve(products.size() * addends.size());
      for (Expr p : products) {
        for (Expr a : addends) next.push_back(p * a);
      }
      products = std::move(next);
    }
    distributed = true;
  }
  if (!distributed) return std::nullopt;
  const Expr rest = pool.product(Number::one(), others);
  for (Expr& p : products) p = p * rest;
  return pool.sum(products);
}

// The sum `e` with every product term distributed (one level).
std::optional<Expr> distribute_terms(Expr e, std::size_t max_terms) {
  std::vector<Term> terms;
  bool distributed = false;
  for (std::size_t i = 0; i < e.operand_count(); ++i) {
    const std::optional<Expr> d = distribute(e.operand(i), max_terms);
    distributed |= d.has_value();
    terms.push_back({d.value_or(e.operand(i)), e.factor(i)});
  }
  if (!distributed) return std::nullopt;
  return e.pool().sum(e.constant(), terms);
}

// c·N/D -> c·(a + r/D) when N = a·D + r for constants a and r (t/(t + 1) -> 1 - 1/(t + 1)):
// D's variables then occur once instead of twice. N is the product of the other factors, read as
// a sum (a lone term has coefficient 1); its terms must be D's terms, proportionally.
std::optional<Expr> quotient(Expr e) {
  if (e.op() != Op::kMul) return std::nullopt;
  ExprPool& pool = e.pool();
  for (std::size_t i = 0; i < e.operand_count(); ++i) {
    const Expr d = e.operand(i);
    if (d.op() != Op::kAdd || !e.factor(i).is_minus_one()) continue;
    std::vector<Term> rest;
    for (std::size_t j = 0; j < e.operand_count(); ++j) {
      if (j != i) rest.push_back({e.operand(j), e.factor(j)});
    }
    if (rest.empty()) continue;
    const Expr n = pool.product(Number::one(), rest);
    const bool n_is_sum = n.op() == Op::kAdd;
    const std::size_t n_terms = n_is_sum ? n.operand_count() : 1;
    if (n_terms != d.operand_count()) continue;
    Number a;
    bool proportional = true;
    for (std::size_t k = 0; k < n_terms && proportional; ++k) {
      const Expr term = n_is_sum ? n.operand(k) : n;
      const Number coefficient = n_is_sum ? n.factor(k) : Number::one();
      if (!(term == d.operand(k)) || d.factor(k).is_zero()) {
        proportional = false;
        break;
      }
      const Number ratio = coefficient / d.factor(k);
      if (k == 0) a = ratio;
      proportional = ratio == a;
    }
    if (!proportional) continue;
    const Number remainder = (n_is_sum ? n.constant() : Number()) - a * d.constant();
    const Term parts[] = {{pow(d, -1), remainder}};
    return scaled(e.constant(), pool.sum(a, parts));
  }
  return std::nullopt;
}

// Rebuilds `root` bottom-up, replacing each rebuilt node n by node_rule(n).
template <class NodeRule>
Expr rewrite_bottom_up(Expr root, NodeRule&& node_rule) {
  std::unordered_map<std::uint32_t, Expr> image;
  std::vector<Expr> operands;
  for (Expr e : topological_order(just(root))) {
    operands.clear();
    bool changed = false;
    for (std::size_t i = 0; i < e.operand_count(); ++i) {
      const Expr now = image.at(e.operand(i).id());
      changed |= !(now == e.operand(i));
      operands.push_back(now);
    }
    Expr now = e;
    try {
      now = node_rule(changed ? rebuild(e, operands) : e);
    } catch (const SymbolicError&) {
      // A rewritten operand made the node's canonical form fold to an error (1/u with u now the
      // exact constant 0; the original is undefined there anyway): keep the original node.
    }
    image.emplace(e.id(), now);
  }
  return image.at(root.id());
}

class Simplifier {
 public:
  explicit Simplifier(const SimplifyOptions& options) : options_(options) {}

  Expr run(Expr f) {
    Expr current = f;
    for (int pass = 0; pass < kMaxPasses && !exhausted(); ++pass) {
      const Expr next = rewrite_bottom_up(current, [this](Expr e) { return rewrite_node(e); });
      if (next == current) break;
      current = next;
    }
    return current;
  }

 private:
  [[nodiscard]] bool exhausted() const { return work_ >= options_.budget; }

  // Parity, then the cheapest strictly cheaper candidate, repeatedly. A node whose candidates
  // were all priced and rejected is remembered (by id: equal nodes have equal candidates).
  Expr rewrite_node(Expr e) {
    e = parity(e);
    for (int round = 0; round < kMaxRewritesPerNode && !exhausted(); ++round) {
      if (settled_.contains(e.id())) break;
      const std::vector<Expr> candidates = candidates_for(e);
      std::optional<Expr> chosen;
      if (!candidates.empty()) {
        Price best = price(e, options_.widths, work_);
        for (Expr c : candidates) {
          if (exhausted()) return e;
          const Price p = price(c, options_.widths, work_);
          if (cheaper(p, best)) {
            best = p;
            chosen = c;
          }
        }
      }
      if (!chosen) {
        settled_.insert(e.id());
        break;
      }
      e = *chosen;
    }
    return e;
  }

  std::vector<Expr> candidates_for(Expr e) {
    std::vector<Expr> candidates;
    // The rules match terms pairwise: quadratic in the operand count.
    work_ += e.operand_count() * e.operand_count();
    try {
      if (e.op() == Op::kMul) {
        if (auto d = distribute(e, kMaxDistributeTerms)) candidates.push_back(*d);
        if (auto q = quotient(e)) candidates.push_back(*q);
      } else if (e.op() == Op::kAdd) {
        for (auto rule : {pythagorean, angle_sum, harmonic, complete_square}) {
          if (auto c = rule(e)) candidates.push_back(*c);
        }
        for (Expr c : factor_common(e, 4)) candidates.push_back(c);
        if (auto d = distribute_terms(e, kMaxDistributeTerms)) candidates.push_back(*d);
      }
    } catch (const SymbolicError&) {
      // Number arithmetic that cannot be done exactly or soundly (a division by a real enclosing
      // zero): the candidates found so far stand, the failing rule is skipped.
    }
    return candidates;
  }

  const SimplifyOptions& options_;
  std::size_t work_{0};
  std::unordered_set<std::uint32_t> settled_;
};

// The domain of an expression is the intersection of the conditions its nodes impose on their
// operands: a base b of b^e (b != 0 when e < 0, b >= 0 when e is fractional), log u (u > 0),
// sqrt u (u >= 0), tan u, asin u, acos u (conditions symmetric in the sign of u), atan2(y, x) and
// real powers. Conditions are compared by what they constrain, not by the node imposing them:
// a/w + b/w and (a + b)/w both require w != 0.
struct DomainConditions {
  static constexpr int kNonZero = 1, kNonNegative = 2;
  std::unordered_map<std::uint32_t, int> on_base;  // base id -> kNonZero | kNonNegative
  std::unordered_set<std::uint64_t> other;         // (op, operand ids) keys

  explicit DomainConditions(Expr f) {
    for (Expr e : topological_order(just(f))) add(e);
  }

  static std::uint64_t key(Op op, std::uint32_t a, std::uint32_t b = 0) {
    return (static_cast<std::uint64_t>(op) << 56) ^ (static_cast<std::uint64_t>(a) << 24) ^ b;
  }
  // tan, asin, acos: the same condition on u and -u.
  static std::uint32_t sign_free(Expr u) { return std::min(u.id(), (-u).id()); }

  void add(Expr e) {
    switch (e.op()) {
      case Op::kLog:
        on_base[e.operand(0).id()] |= kNonZero | kNonNegative;
        return;
      case Op::kSqrt:
        on_base[e.operand(0).id()] |= kNonNegative;
        return;
      case Op::kTan:
      case Op::kAsin:
      case Op::kAcos:
        other.insert(key(e.op(), sign_free(e.operand(0))));
        return;
      case Op::kAtan2:
      case Op::kPow:
        other.insert(key(e.op(), e.operand(0).id(), e.operand(1).id()));
        return;
      case Op::kMul:
        for (std::size_t i = 0; i < e.operand_count(); ++i) {
          const Number& exponent = e.factor(i);
          const Expr base = e.operand(i);
          int flags =
              (exponent.is_negative() ? kNonZero : 0) | (exponent.is_integer() ? 0 : kNonNegative);
          if (base.is_constant()) flags &= base.constant().sign() <= 0 ? kNonNegative : 0;
          if (flags != 0) on_base[base.id()] |= flags;
        }
        return;
      default:
        return;
    }
  }

  // Whether every condition e imposes is among these.
  bool covers(Expr e) const {
    DomainConditions own;
    own.add(e);
    for (const auto& [base, flags] : own.on_base) {
      const auto it = on_base.find(base);
      if (it == on_base.end() || (it->second & flags) != flags) return false;
    }
    for (const std::uint64_t k : own.other) {
      if (!other.contains(k)) return false;
    }
    return true;
  }

 private:
  DomainConditions() = default;
};

// `result`, equal to `original` wherever `original` is defined, made undefined wherever
// `original` is: each node of `original` whose domain condition `result` no longer imposes is
// added back as a guard 0·node (sin(log x)^2 + cos(log x)^2 -> 1 + 0·log(x)). Guards cost no
// occurrences (see price()).
Expr keep_domain(Expr original, Expr result) {
  if (result == original || !original.is_partial()) return result;
  DomainConditions kept(result);
  std::vector<Term> guarded{{result, Number::one()}};
  const std::vector<Expr> order = topological_order(just(original));
  for (auto it = order.rbegin(); it != order.rend(); ++it) {  // outermost first
    if (kept.covers(*it)) continue;
    guarded.push_back({*it, Number()});
    for (Expr inside : topological_order(just(*it))) kept.add(inside);  // now guarded too
  }
  return guarded.size() == 1 ? result : original.pool().sum(Number(), guarded);
}

}  // namespace

double occurrence_cost(Expr f, const std::map<std::string, double>& widths) {
  std::size_t work = 0;
  return price(f, widths, work).occurrences;
}

Expr expand(Expr f) {
  return keep_domain(
      f, rewrite_bottom_up(f, [](Expr e) { return distribute(e, kMaxExpandTerms).value_or(e); }));
}

Expr collect(Expr f, std::span<const Expr> variables) {
  std::unordered_set<std::uint32_t> collected;
  for (Expr v : variables) {
    if (!v.is_variable()) throw SymbolicError("collect: can only collect in variables");
    collected.insert(v.id());
  }
  return keep_domain(f, rewrite_bottom_up(expand(f), [&](Expr e) {
                       if (e.op() != Op::kAdd) return e;
                       ExprPool& pool = e.pool();
                       // Monomial -> the coefficients of its terms, in order of first appearance.
                       std::vector<std::pair<Expr, std::vector<Term>>> groups;
                       std::unordered_map<std::uint32_t, std::size_t> group_of;
                       for (const SumTerm& term : terms_of(e)) {
                         std::vector<Term> monomial, coefficient;
                         for (const Term& factor : term.factors) {
                           const bool in =
                               collected.contains(factor.expr.id()) && factor.factor.is_integer();
                           (in ? monomial : coefficient).push_back(factor);
                         }
                         const Expr m = pool.product(Number::one(), monomial);
                         const auto [it, fresh] = group_of.emplace(m.id(), groups.size());
                         if (fresh) groups.push_back({m, {}});
                         groups[it->second].second.push_back(
                             {pool.product(term.coefficient, coefficient), Number::one()});
                       }
                       std::vector<Expr> grouped;
                       for (const auto& [monomial, coefficients] : groups) {
                         grouped.push_back(monomial * pool.sum(Number(), coefficients));
                       }
                       return pool.constant(e.constant()) + pool.sum(grouped);
                     }));
}

Expr simplify(Expr f, const SimplifyOptions& options) {
  const Expr result = keep_domain(f, Simplifier(options).run(f));
  // Each accepted rewrite lowered the cost of its own node; this guards the whole expression.
  if (occurrence_cost(result, options.widths) > occurrence_cost(f, options.widths)) return f;
  return result;
}

}  // namespace spar::symbolic
