// bound(): natural extension, monotonicity, centred form, branch and bound, inner search.
#include "spar/bounds/bound.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <nlopt.hpp>
#include <optional>
#include <queue>
#include <set>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "spar/bounds/inequality.hpp"
#include "spar/bounds/internal/checks.hpp"
#include "spar/bounds/internal/gradient.hpp"
#include "spar/bounds/internal/linear_enclosure.hpp"
#include "spar/bounds/internal/ulp.hpp"
#include "spar/common/deadline.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/smp.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds {
namespace {

using internal::kInf;
using symbolic::Expr;
using symbolic::Tape;
// NLopt's global stage (DIRECT) runs up to this many variables; SLSQP (the local stage) up to
// kMaxSlsqpVariables, MMA above. A box evaluation costs about kPassesPerBox tape passes (value and
// gradient forward and back, the face, the centre); the tree keeps at most kMaxStoredIntervals.
constexpr unsigned kMaxGlobalVariables = 32;
constexpr std::size_t kMaxSlsqpVariables = 64;
constexpr std::size_t kPassesPerBox = 6;
// The share of the budget branch and bound may use before NLopt looks for a witness (deciding)
// or for a better one (a full bound's side that has not converged).
constexpr double kProbeShare = 0.25;
// Rounds of a full bound's vertex ascent (Bounder::vertex_ascent).
constexpr int kAscentRounds = 4;
constexpr std::size_t kPassesPerFaceGradient = 3;  // value and gradient again on a narrower face
constexpr std::size_t kMaxStoredIntervals = std::size_t{1} << 22;
// Witness enclosures crossing by at most this (relative to max(1, |values|)) are rounding.
constexpr double kRoundingCrossing = 1e-12;

using internal::LinearForm;

// g = c0 + Σ ci·vi (or a lone c·v, or v) as a linear form; nullopt otherwise.
std::optional<LinearForm> linear_form(Expr g, const std::vector<Expr>& variables) {
  LinearForm form{std::vector<Interval>(variables.size(), Interval{0.0}), Interval{0.0}};
  const auto add_term = [&](Expr term, const Interval& coefficient) {
    Expr base = term;
    Interval c = coefficient;
    if (term.op() == symbolic::Op::kMul) {
      if (term.operand_count() != 1 || !term.factor(0).is_one()) return false;
      base = term.operand(0);
      c = c * enclose(term.constant());
    }
    if (!base.is_variable()) return false;
    const auto it = std::find(variables.begin(), variables.end(), base);
    if (it == variables.end()) return false;
    form.coefficients[it - variables.begin()] = form.coefficients[it - variables.begin()] + c;
    return true;
  };
  if (g.op() == symbolic::Op::kAdd) {
    form.constant = enclose(g.constant());
    for (std::size_t i = 0; i < g.operand_count(); ++i) {
      if (!add_term(g.operand(i), enclose(g.factor(i)))) return std::nullopt;
    }
    return form;
  }
  if (!add_term(g, Interval{1.0})) return std::nullopt;
  return form;
}

bool certainly_fails(const Interval& g, Relation relation) {
  if (g.is_empty()) return true;
  switch (relation) {
    case Relation::kLess:
      return g.lo >= 0;
    case Relation::kLessEqual:
      return g.lo > 0;
    case Relation::kGreater:
      return g.hi <= 0;
    case Relation::kGreaterEqual:
      return g.hi < 0;
  }
  return false;
}

bool certainly_holds(const Interval& g, Relation relation) {
  if (g.is_empty() || g.possibly_undefined) return false;
  switch (relation) {
    case Relation::kLess:
      return g.hi < 0;
    case Relation::kLessEqual:
      return g.hi <= 0;
    case Relation::kGreater:
      return g.lo > 0;
    case Relation::kGreaterEqual:
      return g.lo >= 0;
  }
  return false;
}

// Work units of one interval pass over a tape: 1 per arithmetic instruction, more for those
// whose interval kernels cost more (measured on this machine: sin ~10x an addition).
std::size_t tape_cost(const Tape& tape) {
  using symbolic::TapeOp;
  std::size_t cost = 0;
  for (const symbolic::Instruction& in : tape.instructions()) {
    switch (in.op) {
      case TapeOp::kDiv:
        cost += 2;
        break;
      case TapeOp::kPowInt:
      case TapeOp::kSqrt:
        cost += 3;
        break;
      case TapeOp::kSin:
      case TapeOp::kCos:
      case TapeOp::kTan:
      case TapeOp::kExp:
      case TapeOp::kLog:
      case TapeOp::kAtan:
      case TapeOp::kAsin:
      case TapeOp::kAcos:
      case TapeOp::kAtan2:
      case TapeOp::kPow:
        cost += 10;
        break;
      default:
        cost += 1;
    }
  }
  return cost;
}

// A box of the branch-and-bound tree. The tree does not depend on the direction: a box's split
// variable and children follow from the box and f's gradient alone, so each box is evaluated once
// for both directions, and the second direction's search reuses every box the first evaluated.
// A direction's face and centred form need only the box and f's interval gradient on it, so they
// are computed when that direction first needs the node (refine()), not for both at once.
struct TreeNode {
  std::vector<Interval> box;       // released once no direction can still expand it (release())
  std::vector<Interval> gradient;  // f's on box while a direction may still refine with it
  std::array<double, 2> bound;     // sound upper bounds of f ([0]) and of -f ([1]) on the box
  std::array<bool, 2> refined;     // bound[d] includes direction d's face and centred form
  int split{0};                    // variable to bisect next
  std::size_t first_child{0};      // the children are first_child and first_child + 1; 0 = none
};

// Per variable, whether f is affine in it (f = A·v + B with A and B free of v), so that over a
// box f's extremes lie on v's end points. Decided from polynomial degrees on the DAG, capped at 2
// ("2 or more, or not a polynomial in v"): a sum takes the largest degree of its terms, a product
// adds its factors' degrees times their exponents when those are non-negative integers, and any
// other use of v (a function's argument, a negative or fractional power) counts as 2. Degrees are
// kept sparsely; past kMaxDegreeEntries entries in all it gives up (no variable is affine).
std::vector<bool> affine_variables(Expr f, std::span<const Expr> variables) {
  constexpr std::size_t kMaxDegreeEntries = 1'000'000;
  constexpr std::uint8_t kNonAffine = 2;
  using Degrees = std::vector<std::pair<std::uint32_t, std::uint8_t>>;  // (variable, degree)
  std::unordered_map<std::uint32_t, std::uint32_t> index;
  for (std::size_t i = 0; i < variables.size(); ++i) index[variables[i].id()] = i;
  std::unordered_map<std::uint32_t, Degrees> degrees;
  std::size_t entries = 0;
  // merged = merged ⊕ d·scale, where ⊕ is max (sums) or + (products), capped at 2.
  const auto merge = [](Degrees& merged, const Degrees& d, int scale, bool add) {
    Degrees out;
    std::size_t i = 0, j = 0;
    const auto scaled = [&](std::uint8_t v) {
      return static_cast<std::uint8_t>(std::min<int>(kNonAffine, v * scale));
    };
    while (i < merged.size() || j < d.size()) {
      if (j == d.size() || (i < merged.size() && merged[i].first < d[j].first)) {
        out.push_back(merged[i++]);
      } else if (i == merged.size() || d[j].first < merged[i].first) {
        out.emplace_back(d[j].first, scaled(d[j].second));
        ++j;
      } else {
        const int v = add ? merged[i].second + scaled(d[j].second)
                          : std::max<int>(merged[i].second, scaled(d[j].second));
        out.emplace_back(merged[i].first, static_cast<std::uint8_t>(std::min<int>(kNonAffine, v)));
        ++i;
        ++j;
      }
    }
    merged = std::move(out);
  };
  for (const Expr e : symbolic::topological_order(std::array{f})) {
    Degrees d;
    switch (e.op()) {
      case symbolic::Op::kConstant:
        break;
      case symbolic::Op::kVariable:
        d.emplace_back(index.at(e.id()), std::uint8_t{1});
        break;
      case symbolic::Op::kAdd:
        for (std::size_t k = 0; k < e.operand_count(); ++k) {
          merge(d, degrees.at(e.operand(k).id()), 1, false);
        }
        break;
      case symbolic::Op::kMul:
        for (std::size_t k = 0; k < e.operand_count(); ++k) {
          const symbolic::Number exponent = e.factor(k);
          const bool polynomial = exponent.is_integer() && exponent.numerator() >= 0;
          const int scale =
              polynomial
                  ? static_cast<int>(std::min<std::int64_t>(kNonAffine, exponent.numerator()))
                  : kNonAffine;
          merge(d, degrees.at(e.operand(k).id()), scale, true);
        }
        break;
      default:
        for (std::size_t k = 0; k < e.operand_count(); ++k) {
          merge(d, degrees.at(e.operand(k).id()), kNonAffine, false);
        }
        break;
    }
    entries += d.size();
    if (entries > kMaxDegreeEntries) return std::vector<bool>(variables.size(), false);
    degrees.emplace(e.id(), std::move(d));
  }
  std::vector<bool> affine(variables.size(), true);
  for (const auto& [variable, degree] : degrees.at(f.id())) affine[variable] = degree <= 1;
  return affine;
}

// One expression compiled over the problem's variables: its tape and the evaluators on it. Pinned
// (the evaluators point into the tape), so it lives behind a unique_ptr.
struct CompiledFunction {
  // `what` names f in the error for a variable not listed ("the expression", "the constraint").
  CompiledFunction(Expr f, std::span<const Expr> variables, const char* what = "the expression")
      : expression(f),
        variables(variables.begin(), variables.end()),
        tape(internal::compile_checked(std::array{f}, variables,
                                       [what](std::size_t) { return std::string(what); })),
        interval(tape),
        real(tape) {}
  // On `tape_of_f`, f's tape over `variables` compiled already.
  CompiledFunction(Expr f, std::span<const Expr> variables, Tape tape_of_f)
      : expression(f),
        variables(variables.begin(), variables.end()),
        tape(std::move(tape_of_f)),
        interval(tape),
        real(tape) {}
  CompiledFunction(const CompiledFunction&) = delete;
  CompiledFunction& operator=(const CompiledFunction&) = delete;

  // Affine forms of the tape's values, computed on first use (only linear constraints need them).
  const std::vector<std::optional<LinearForm>>& affine() {
    if (!affine_forms) affine_forms = internal::affine_forms(tape);
    return *affine_forms;
  }

  // Whether f is affine in variable i (affine_variables), computed on first use: only branch and
  // bound without constraints asks, and only once it splits a box (costs O(DAG x variables)).
  bool affine_in(std::size_t i) {
    if (!affine_by_variable) affine_by_variable = affine_variables(expression, variables);
    return (*affine_by_variable)[i];
  }

  Expr expression;
  std::vector<Expr> variables;
  Tape tape;
  internal::GradientEvaluator<Interval> interval;  // on tape
  internal::GradientEvaluator<double> real;        // on tape
  std::optional<std::vector<std::optional<LinearForm>>> affine_forms;
  std::optional<std::vector<bool>> affine_by_variable;  // see affine_in()
};

// A constraint `g relation 0` compiled over the problem's variables.
struct CompiledConstraint {
  CompiledConstraint(const Constraint& c, std::span<const Expr> variables)
      : relation(c.relation), function(c.g, variables, "the constraint") {}
  Relation relation;
  CompiledFunction function;
};

// The constraints of a problem, compiled once; `linear` holds the linear ones as forms `L <= 0`.
struct CompiledConstraints {
  std::vector<std::unique_ptr<CompiledConstraint>> all;
  std::vector<LinearForm> linear;
};

// One bounding run of a compiled function over one root box. Holds only per-run state: the
// compiled parts are borrowed, and every value they keep between runs (slot scratch, the linear
// enclosures, which are set afresh here) is overwritten before it is read, so a run's result does
// not depend on earlier runs.
class Bounder {
 public:
  Bounder(CompiledFunction& f, CompiledConstraints& constraints, std::span<const Interval> root,
          const BoundOptions& options)
      : options_(options),
        root_(root.begin(), root.end()),
        f_(f),
        f_interval_(f.interval),
        f_double_(f.real),
        constraints_(constraints.all),
        linear_(constraints.linear),
        start_(std::chrono::steady_clock::now()) {
    if (!linear_.empty()) {
      f_interval_.set_enclosures(internal::linear_enclosures(f_.affine(), linear_, root_));
    }
    gradient_.resize(root_.size());
    point_.resize(root_.size());
    evaluation_cost_ = tape_cost(f.tape) + root_.size() + 1;
    for (const auto& c : constraints_) evaluation_cost_ += tape_cost(c->function.tape);
  }

  BoundResult run() {
    BoundResult result;
    result.inner_lo = kInf;
    result.inner_hi = -kInf;
    result_ = &result;
    std::vector<Interval> root = root_;
    if (!contract(root)) return infeasible(result);
    double lo = 0, hi = 0;
    offer_centre(root);
    if (options_.decide) {
      // One side only (see BoundOptions::decide); the other is the root's enclosure.
      const int sign = upper_limit(options_.decide->relation) ? +1 : -1;
      // The corner the gradient at the centre points to: one point; for a nearly linear f it is
      // the extremum, so a violation usually ends deciding there.
      offer_gradient_corner(root, sign);
      if (options_.stop_at_witness && decided(sign, kInf)) {
        std::tie(lo, hi) = natural_bound(root);
        result.stopped_at_witness = true;
      } else {
        const double side = decide_side(root, sign);
        const int other = sign > 0 ? 1 : 0;
        const double enclosure =
            std::max(tree_[0].bound[other], sign > 0 ? -result.inner_lo : result.inner_hi);
        hi = sign > 0 ? side : enclosure;
        lo = sign > 0 ? -enclosure : -side;
      }
    } else {
      std::tie(lo, hi) = full_bound(root);
    }
    result.lo = lo;
    result.hi = hi;
    result.evaluations = evaluations_;
    if (hi < lo && result.argmax_value.is_empty()) return infeasible(result);
    result.possibly_undefined = undefined_;
    result.time_limited = time_limited_;
    if (!std::isfinite(lo) || !std::isfinite(hi)) {
      result.status = BoundStatus::kUnbounded;
    } else {
      result.status =
          converged_[0] && converged_[1] ? BoundStatus::kConverged : BoundStatus::kEffortLimit;
    }
    order_inner_bounds(result);
    return result;
  }

 private:
  BoundResult& infeasible(BoundResult& result) {
    result.lo = kInf;
    result.hi = -kInf;
    result.argmin.clear();
    result.argmax.clear();
    result.argmin_value = result.argmax_value = Interval::empty();
    order_inner_bounds(result);
    result.status = BoundStatus::kInfeasible;
    result.evaluations = evaluations_;
    return result;
  }

  // Narrows the box with the linear constraints; false if it becomes empty.
  bool contract(std::vector<Interval>& box) const {
    for (int pass = 0; pass < 2; ++pass) {
      for (const LinearForm& form : linear_) {
        for (std::size_t i = 0; i < box.size(); ++i) {
          const Interval& a = form.coefficients[i];
          if (a.lo <= 0 && a.hi >= 0) continue;
          Interval rest = form.constant;
          for (std::size_t j = 0; j < box.size(); ++j) {
            if (j != i && (form.coefficients[j].lo != 0 || form.coefficients[j].hi != 0)) {
              rest = rest + form.coefficients[j] * box[j];
            }
          }
          // a·x_i <= -rest  =>  x_i <= (-rest.lo)/a (a > 0) or x_i >= (-rest.lo)/a (a < 0).
          const Interval limit = Interval{-rest.lo} / a;
          if (limit.is_empty()) continue;
          box[i] = a.lo > 0 ? intersect(box[i], Interval{-kInf, limit.hi})
                            : intersect(box[i], Interval{limit.lo, kInf});
          if (box[i].is_empty()) return false;
        }
      }
    }
    return true;
  }

  // Discards the box if some constraint certainly fails on it: natural extension, then (for
  // boxes it cannot decide) the mean-value form g(c) + G(X)·(X - c), whose overestimation
  // shrinks with the square of the width, so boxes along a curved constraint get decided.
  bool may_be_feasible(std::span<const Interval> box) {
    const std::size_t n = box.size();
    for (const auto& constraint : constraints_) {
      auto& g_interval = constraint->function.interval;
      const Relation relation = constraint->relation;
      if (certainly_fails(g_interval.value(box), relation)) return false;
      if (!options_.centred_form) continue;
      const Interval g = g_interval.value_and_gradient(box, gradient_);
      bool gradient_ok = !g.possibly_undefined;
      for (const Interval& partial : gradient_) {
        gradient_ok = gradient_ok && partial.is_bounded() && !partial.possibly_undefined;
      }
      if (!gradient_ok) continue;
      centre_.resize(n);
      for (std::size_t i = 0; i < n; ++i) centre_[i] = Interval{box[i].mid()};
      Interval centred = g_interval.value(centre_);
      if (centred.is_empty() || centred.possibly_undefined) continue;
      for (std::size_t i = 0; i < n; ++i) {
        if (box[i].width() > 0) centred = centred + gradient_[i] * (box[i] - centre_[i]);
      }
      if (certainly_fails(centred, relation)) return false;
    }
    return true;
  }

  // Offers a point as a witness: kept if it certainly satisfies the constraints and f is
  // defined there; inner bounds use the rigorous enclosure of f at the point.
  void offer(std::span<const double> x) {
    std::vector<Interval> p(x.begin(), x.end());
    for (const auto& constraint : constraints_) {
      if (!certainly_holds(constraint->function.interval.value(p), constraint->relation)) return;
    }
    const Interval v = f_interval_.value(p);
    if (v.is_empty() || v.possibly_undefined) return;
    internal::offer_witness(*result_, x, v);
  }

  void offer_centre(std::span<const Interval> box) {
    for (std::size_t i = 0; i < box.size(); ++i) point_[i] = box[i].mid();
    offer(point_);
  }

  // The corners of the box (up to 10 variables).
  void offer_corners(std::span<const Interval> box) {
    const std::size_t n = box.size();
    if (n > 10) return;
    for (std::size_t mask = 0; mask < (std::size_t{1} << n); ++mask) {
      for (std::size_t i = 0; i < n; ++i) point_[i] = (mask >> i) & 1 ? box[i].hi : box[i].lo;
      offer(point_);
    }
  }

  // The corner the gradient of f at the box's centre points to (sign·f grows that way): where a
  // nearly linear f takes its extremum, for one gradient and one point.
  void offer_gradient_corner(std::span<const Interval> box, int sign) {
    for (std::size_t i = 0; i < box.size(); ++i) point_[i] = box[i].mid();
    std::vector<double> gradient(box.size());
    (void)f_double_.value_and_gradient(point_, gradient);
    for (std::size_t i = 0; i < box.size(); ++i) {
      if (!std::isfinite(gradient[i]) || gradient[i] == 0) continue;
      point_[i] = sign * gradient[i] > 0 ? box[i].hi : box[i].lo;
    }
    offer(point_);
  }

  // {lo, hi}: f's natural interval extension over the box (sound, loose), the whole line where
  // f is defined nowhere in it by that extension.
  std::pair<double, double> natural_bound(std::span<const Interval> box) {
    const Interval value = f_interval_.value(box);
    undefined_ = undefined_ || value.possibly_undefined;
    if (value.is_empty()) return {-kInf, kInf};
    return {value.lo, value.hi};
  }

  // Whether vertex_ascent() runs on this box (it does not check constraints, and each round
  // costs O(n) evaluations).
  bool ascends(std::span<const Interval> box) const {
    return constraints_.empty() && box.size() <= kMaxGlobalVariables;
  }

  // An ascent of sign·f over the box's vertices (and centres) for a full bound's witnesses, from
  // the side's best witness: jump to the corner the gradient points to (a variable with a zero
  // partial stays), then move each variable in turn to another of lo, mid, hi, alone or with the
  // others following the gradient there (flipping a rotation turns the best side of the offsets
  // it carries), keeping a move that improves; repeat while a round improves. Where f is nearly
  // multilinear (offsets through small rotations) this reaches the vertex f peaks at, which the
  // one corner cannot (a partial zero at the centre, as in cos(t) - 1, or changing sign with
  // another variable). A round costs at most 6n + 2 evaluations (kAscentRounds rounds, within a
  // 1/16 share of the work budget, like an NLopt stage), against DIRECT-L's 60(n + 1) and its
  // bookkeeping. Offers the point it ends at. Without constraints only (it does not check them).
  void vertex_ascent(std::span<const Interval> box, int sign) {
    const std::vector<double>& best = sign > 0 ? result_->argmax : result_->argmin;
    if (!ascends(box) || best.empty()) return;
    const std::size_t work_limit = work_ + options_.max_work / 16;
    std::vector<double> x = best, gradient(x.size());
    const auto value = [&](std::span<const double> at) {
      work_ += evaluation_cost_;
      const double v = sign * f_double_.value(at);
      return std::isfinite(v) ? v : -kInf;
    };
    double current = value(x);
    const auto take_if_better = [&](const std::vector<double>& y) {
      const double v = value(y);
      if (!(v > current)) return false;
      current = v;
      x = y;
      return true;
    };
    // The corner the gradient at `from` points to, every variable but `held` moved.
    const auto corner_from = [&](std::vector<double> from, std::size_t held) {
      work_ += evaluation_cost_;
      (void)f_double_.value_and_gradient(from, gradient);
      for (std::size_t i = 0; i < from.size(); ++i) {
        if (i != held && std::isfinite(gradient[i]) && gradient[i] != 0)
          from[i] = sign * gradient[i] > 0 ? box[i].hi : box[i].lo;
      }
      return from;
    };
    for (int round = 0; round < kAscentRounds && work_ < work_limit; ++round) {
      const double start = current;
      take_if_better(corner_from(x, x.size()));
      for (std::size_t i = 0; i < x.size() && work_ < work_limit; ++i) {
        for (const double candidate : {box[i].lo, box[i].mid(), box[i].hi}) {
          if (candidate == x[i]) continue;
          std::vector<double> y = x;
          y[i] = candidate;
          if (take_if_better(y) || take_if_better(corner_from(y, i))) break;
        }
      }
      if (!(current > start)) break;
    }
    offer(x);
  }

  struct Objective {
    Bounder* self;
    int sign;
    std::size_t constraint;  // for constraint callbacks
  };

  // Minimises -sign·f: a global stage (DIRECT-L, or with constraints the original DIRECT-L, which
  // takes inequality constraints; both deterministic, no random numbers), then a local one from
  // where it ended (without the global stage, from the best witness). Witnesses are re-checked
  // by offer().
  void nlopt_search(std::span<const Interval> box, int sign) {
    const unsigned n = static_cast<unsigned>(box.size());
    if (n == 0) return;
    const std::vector<double>& start = sign > 0 ? result_->argmax : result_->argmin;
    std::vector<double> x(n);
    for (unsigned i = 0; i < n; ++i) x[i] = start.empty() ? box[i].mid() : start[i];
    const bool constrained = !constraints_.empty();
    // DIRECT keeps every rectangle it has split (memory ~ evaluations x n) and samples a
    // high-dimensional box too thinly to help: above kMaxGlobalVariables only the local stage runs.
    if (n <= kMaxGlobalVariables) {
      try {
        nlopt::opt global(constrained ? nlopt::GN_ORIG_DIRECT_L : nlopt::GN_DIRECT_L, n);
        configure(global, box, sign);
        global.set_maxeval(nlopt_evaluations(constrained ? 300 * (n + 1) : 60 * (n + 1)));
        double value = 0;
        global.optimize(x, value);
        offer(x);
      } catch (const std::exception&) {
        // NLopt only tightens inner bounds; a failed stage leaves them as they are (x is where
        // it stopped, or the start).
      }
      // The local stage starts where the global one ended, even if a witness found before is
      // better: that one is a local optimum already (the vertex ascent's, a local search's), and
      // the global search's point may lie in the basin of a better one.
    }
    local_search(box, x, sign);
  }

  // SLSQP with tape gradients from `x`, within `box` (MMA above kMaxSlsqpVariables: SLSQP's
  // quasi-Newton matrix is n x n, its steps O(n^3)); offers the point it ends at.
  void local_search(std::span<const Interval> box, std::vector<double> x, int sign) {
    try {
      const bool small = x.size() <= kMaxSlsqpVariables;
      nlopt::opt local(small ? nlopt::LD_SLSQP : nlopt::LD_MMA, static_cast<unsigned>(x.size()));
      configure(local, box, sign);
      local.set_maxeval(nlopt_evaluations(200));
      local.set_xtol_rel(1e-12);
      double value = 0;
      local.optimize(x, value);
    } catch (const std::exception&) {
      // x is the last point NLopt reached (or the start); offering it is still safe.
    }
    offer(x);
  }

  void configure(nlopt::opt& opt, std::span<const Interval> box, int sign) {
    std::vector<double> lower(box.size()), upper(box.size());
    for (std::size_t i = 0; i < box.size(); ++i) {
      lower[i] = box[i].lo;
      upper[i] = box[i].hi;
    }
    opt.set_lower_bounds(lower);
    opt.set_upper_bounds(upper);
    objective_ = {this, sign, 0};
    opt.set_min_objective(&Bounder::nlopt_objective, &objective_);
    if (opt.get_algorithm() == nlopt::GN_DIRECT_L) return;
    constraint_data_.clear();
    for (std::size_t c = 0; c < constraints_.size(); ++c) constraint_data_.push_back({this, 0, c});
    for (Objective& data : constraint_data_) {
      opt.add_inequality_constraint(&Bounder::nlopt_constraint, &data, 0.0);
    }
  }

  static double nlopt_objective(unsigned n, const double* x, double* gradient, void* data) {
    auto& objective = *static_cast<Objective*>(data);
    Bounder& self = *objective.self;
    self.work_ += self.evaluation_cost_;
    const std::span<const double> point(x, n);
    double value = 0;
    if (gradient) {
      value = self.f_double_.value_and_gradient(point, std::span<double>(gradient, n));
      for (unsigned i = 0; i < n; ++i) {
        gradient[i] = std::isfinite(gradient[i]) ? -objective.sign * gradient[i] : 0.0;
      }
    } else {
      value = self.f_double_.value(point);
    }
    return std::isfinite(value) ? -objective.sign * value : 1e300;
  }

  // NLopt wants c(x) <= 0.
  static double nlopt_constraint(unsigned n, const double* x, double* gradient, void* data) {
    auto& objective = *static_cast<Objective*>(data);
    Bounder& self = *objective.self;
    CompiledConstraint& constraint = *self.constraints_[objective.constraint];
    const Relation relation = constraint.relation;
    const double flip =
        (relation == Relation::kGreater || relation == Relation::kGreaterEqual) ? -1.0 : 1.0;
    auto& evaluator = constraint.function.real;
    const std::span<const double> point(x, n);
    double value = 0;
    if (gradient) {
      value = evaluator.value_and_gradient(point, std::span<double>(gradient, n));
      for (unsigned i = 0; i < n; ++i) {
        gradient[i] = std::isfinite(gradient[i]) ? flip * gradient[i] : 0.0;
      }
    } else {
      value = evaluator.value(point);
    }
    // The margin keeps NLopt strictly inside: a point on the boundary would fail offer()'s
    // rigorous check half of the time, and strict relations exclude it anyway.
    constexpr double kMargin = 1e-9;
    return std::isfinite(value) ? flip * value + kMargin : 1e300;
  }

  // A box's evaluation: upper bounds of f ([0]) and of -f ([1]) by the natural extension (-inf
  // if the box is discarded), the variable to bisect, and whether gradient_ now holds a usable
  // interval gradient of f on the box.
  struct BoxEvaluation {
    std::array<double, 2> bound{-kInf, -kInf};
    int split{0};
    bool gradient_ok{false};
  };

  // Evaluates the box (after contraction): one value-and-gradient pass serves both directions.
  // Also offers the box midpoint as a witness.
  BoxEvaluation evaluate_box(std::vector<Interval>& box) {
    ++evaluations_;
    work_ += kPassesPerBox * evaluation_cost_;
    BoxEvaluation result;
    result.split = widest(box);
    const BoxEvaluation discarded = result;
    if (!contract(box) || !may_be_feasible(box)) return discarded;
    const std::size_t n = box.size();
    Interval value;
    bool gradient_ok = false;
    if (options_.monotonicity || options_.centred_form) {
      value = f_interval_.value_and_gradient(box, gradient_);
      gradient_ok = !value.possibly_undefined;
      for (const Interval& g : gradient_) {
        gradient_ok = gradient_ok && g.is_bounded() && !g.possibly_undefined;
      }
    } else {
      value = f_interval_.value(box);
    }
    if (f_interval_.has_enclosures()) {
      // Tighter on the feasible points; the gradient (above) stays valid on the whole box.
      const Interval feasible = f_interval_.feasible_value(box);
      if (feasible.is_empty()) return discarded;  // the linear constraints exclude the whole box
      value = Interval{std::max(value.lo, feasible.lo), std::min(value.hi, feasible.hi),
                       feasible.possibly_undefined};
    }
    undefined_ = undefined_ || value.possibly_undefined;
    if (value.is_empty()) return discarded;  // f is defined nowhere in this box
    result.bound = {value.hi, -value.lo};
    for (std::size_t i = 0; i < n; ++i) point_[i] = box[i].mid();
    offer(point_);
    if (!gradient_ok) return result;
    // Smear rule: bisect where |gradient| x width is largest.
    double largest = -1;
    for (std::size_t i = 0; i < n; ++i) {
      const double smear =
          std::max(std::fabs(gradient_[i].lo), std::fabs(gradient_[i].hi)) * box[i].width();
      if (smear > largest && box[i].width() > 0) {
        largest = smear;
        result.split = static_cast<int>(i);
      }
    }
    result.gradient_ok = true;
    return result;
  }

  // An upper bound of sign·f over the box from f's interval gradient on it. Monotone variables
  // sit at the end point that maximises sign·f, so bound that face instead: by the natural
  // extension, and by the centred form on it (at Baumann's centre). Fixing variables narrows the
  // face, and f's gradient over the narrower face may show more variables monotone, so the
  // gradient is taken again on each new face while that fixes more (the extremum over a face lies
  // on the next); each gradient is intersected with the box's, which also holds on the face.
  double face_and_centred_bound(std::span<const Interval> box, std::span<const Interval> gradient,
                                int sign) {
    const std::size_t n = box.size();
    double best = kInf;
    std::vector<Interval>& face = face_;
    std::vector<Interval>& on_face_gradient = face_gradient_;
    face.assign(box.begin(), box.end());
    on_face_gradient.assign(gradient.begin(), gradient.end());
    if (options_.monotonicity) {
      bool fixed_any = false;
      for (std::size_t round = 0; round < n; ++round) {
        bool fixed = false;
        std::size_t free = 0;
        for (std::size_t i = 0; i < n; ++i) {
          if (!(face[i].width() > 0)) continue;
          const Interval g = sign > 0 ? on_face_gradient[i] : -on_face_gradient[i];
          if (g.lo >= 0) {
            face[i] = Interval{face[i].hi};
            fixed = true;
          } else if (g.hi <= 0) {
            face[i] = Interval{face[i].lo};
            fixed = true;
          } else {
            ++free;
          }
        }
        fixed_any = fixed_any || fixed;
        if (!fixed || free == 0) break;
        work_ += kPassesPerFaceGradient * evaluation_cost_;
        const Interval value = f_interval_.value_and_gradient(face, on_face_gradient);
        bool usable = !value.possibly_undefined;
        for (std::size_t i = 0; i < n && usable; ++i) {
          on_face_gradient[i] = intersect(on_face_gradient[i], gradient[i]);
          usable = on_face_gradient[i].is_bounded() && !on_face_gradient[i].possibly_undefined &&
                   !on_face_gradient[i].is_empty();
        }
        if (!usable) {  // the box's gradient still encloses f's on the face
          on_face_gradient.assign(gradient.begin(), gradient.end());
          break;
        }
      }
      if (fixed_any) {
        const Interval on_face = f_interval_.value(face);
        if (!on_face.is_empty()) best = std::min(best, sign > 0 ? on_face.hi : -on_face.lo);
      }
    }
    if (options_.centred_form) {
      // f(X) ⊆ f(c) + Σ G_i (X_i - c_i) on the face, G enclosing f's gradient there.
      std::vector<Interval>& centre = centre_;
      centre.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const Interval& g = on_face_gradient[i];
        centre[i] = Interval{optimal_centre(face[i], sign > 0 ? g : -g)};
      }
      Interval centred = f_interval_.value(centre);
      for (std::size_t i = 0; i < n; ++i) {
        if (face[i].width() > 0) centred = centred + on_face_gradient[i] * (face[i] - centre[i]);
      }
      if (!centred.is_empty() && !centred.possibly_undefined) {
        best = std::min(best, sign > 0 ? centred.hi : -centred.lo);
      }
    }
    return best;
  }

  // Baumann's optimal centre for an upper bound: the point c of x where max over x' in x and g'
  // in g of g'·(x' - c) is smallest, (g.hi·x.hi - g.lo·x.lo)/(g.hi - g.lo) when g.lo < 0 < g.hi
  // (for a g of one sign the face fixed the variable), else the midpoint. The centred form is
  // sound for any centre in the box.
  static double optimal_centre(const Interval& x, const Interval& g) {
    if (!(g.lo < 0 && g.hi > 0) || !g.is_bounded()) return x.mid();
    const double c = (g.hi * x.hi - g.lo * x.lo) / (g.hi - g.lo);
    return std::isfinite(c) ? std::clamp(c, x.lo, x.hi) : x.mid();
  }

  static int widest(std::span<const Interval> box) {
    int index = 0;
    double width = -1;
    for (std::size_t i = 0; i < box.size(); ++i) {
      if (box[i].width() > width) {
        width = box[i].width();
        index = static_cast<int>(i);
      }
    }
    return index;
  }

  // Whether the effort of this direction is spent: the first direction may use half of each
  // budget, the second the rest (times effort_scale_ while deciding's probe runs).
  bool out_of_effort(int direction) {
    const std::size_t share = static_cast<std::size_t>(direction) + 1;
    const auto limit = [&](std::size_t budget) {
      return static_cast<double>(budget / 2 * share) * effort_scale_;
    };
    if (static_cast<double>(evaluations_) >= limit(options_.max_box_evaluations)) return true;
    if (static_cast<double>(work_) >= limit(options_.max_work)) return true;
    if (options_.max_seconds > 0 &&
        elapsed() > options_.max_seconds * static_cast<double>(share) / 2 * effort_scale_) {
      time_limited_ = true;
      return true;
    }
    return false;
  }

  // An NLopt stage's evaluation cap: `wanted`, but at most a 1/16 share of the work budget.
  int nlopt_evaluations(std::size_t wanted) const {
    const std::size_t affordable = options_.max_work / 16 / evaluation_cost_;
    return static_cast<int>(std::clamp<std::size_t>(std::min(wanted, affordable), 1, 1'000'000));
  }

  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  // With BoundOptions::decide and sign its side: whether `top` (a sound bound of sign·f) proves
  // the target, or the attained witness value breaks it (as decide() would judge).
  bool decided(int sign, double top) const {
    if (!options_.decide) return false;
    const double t = sign * options_.decide->threshold;
    const bool is_strict = strict(options_.decide->relation);
    const double attained = sign > 0 ? result_->inner_hi : -result_->inner_lo;
    const bool proved = is_strict ? top < t : top <= t;
    const bool broken = is_strict ? attained >= t : attained > t;
    return proved || broken;
  }

  // Deciding's search of sign·f's maximum, after the gradient's corner (run()): branch and bound
  // on a quarter of the budget with the box midpoints as witnesses (most inequalities
  // hold, and a proof needs no witness), then the corners and branch and bound with the rest,
  // from the same tree (no box is evaluated twice). NLopt's search for a violating point, the
  // dearest witness, runs only if all of that leaves the verdict open.
  double decide_side(const std::vector<Interval>& root, int sign) {
    effort_scale_ = kProbeShare;
    const double probed = search(root, sign);
    effort_scale_ = 1.0;
    if (decided(sign, probed)) return probed;
    time_limited_ = false;  // the probe's share of max_seconds, not the limit, ran out
    offer_corners(root);
    const double searched = search(root, sign);
    if (!options_.inner || decided(sign, searched)) return searched;
    nlopt_search(root, sign);
    return std::max(searched, sign > 0 ? result_->inner_hi : -result_->inner_lo);
  }

  // A full bound, both sides (each converges against its witnesses): each side's gradient corner
  // and vertex ascent (for a nearly multilinear f those find the extrema; where the ascent does
  // not run, the corners and a local search instead), then per side (the maximum first, as the
  // effort shares expect) branch and bound on a quarter of the side's budget (it polishes its
  // best box with the local search now and then), and only if that does not converge NLopt's
  // global search (DIRECT-L, the dearest witness) and the rest of the budget. Returns {lo, hi}.
  std::pair<double, double> full_bound(const std::vector<Interval>& root) {
    const bool ascent = options_.inner && ascends(root);
    if (!ascent) offer_corners(root);
    if (options_.inner) {
      for (const int sign : {+1, -1}) {
        offer_gradient_corner(root, sign);
        if (ascent) {
          vertex_ascent(root, sign);
        } else if (const auto& best = sign > 0 ? result_->argmax : result_->argmin; !best.empty()) {
          local_search(root, best, sign);
        }
      }
    }
    const auto side = [&](int sign) {
      effort_scale_ = kProbeShare;
      const double probed = search(root, sign);
      effort_scale_ = 1.0;
      if (converged_[sign > 0 ? 0 : 1]) return probed;
      time_limited_ = false;  // the probe's share of max_seconds, not the limit, ran out
      if (options_.inner) nlopt_search(root, sign);
      return search(root, sign);
    };
    const double hi = side(+1);
    return {-side(-1), hi};
  }

  // Sound upper bound of sign·f over the feasible box; best-first bisection over tree_, which the
  // first direction grows and the second reuses (a node expanded by either is never re-evaluated).
  double search(const std::vector<Interval>& root, int sign) {
    const int direction = sign > 0 ? 0 : 1;
    direction_ = direction;
    const auto inner = [&] { return sign > 0 ? result_->inner_hi : -result_->inner_lo; };
    const auto target_gap = [&] {
      const double width = result_->inner_hi - result_->inner_lo;
      const double scale = std::max(std::fabs(result_->inner_hi), std::fabs(result_->inner_lo));
      return std::max(options_.tolerance * (std::isfinite(width) ? width : 0.0),
                      std::isfinite(scale) ? 1e-14 * scale : 0.0);
    };
    if (tree_.empty()) add_node(root, {kInf, kInf});
    refine(0, direction);
    // (bound of sign·f, node); equal bounds pop the later node first, deterministically.
    std::priority_queue<std::pair<double, std::size_t>> queue;
    double settled = -kInf;  // bound of boxes too small to bisect
    if (tree_[0].bound[direction] > -kInf) queue.push({tree_[0].bound[direction], 0});
    std::size_t pops = 0, next_polish = 64;
    while (!queue.empty()) {
      check_deadline();  // a batch's --time-limit (common/deadline.hpp); cheap without one
      const double top = std::max(queue.top().first, settled);
      if (top - inner() <= target_gap()) break;
      if (decided(sign, top)) return std::max(top, inner());
      // Boxes kept in the tree: memory stays proportional to the input (capped) however many
      // variables there are.
      if (!options_.branch_and_bound || out_of_effort(direction) ||
          stored_intervals_ > kMaxStoredIntervals) {
        return std::max(top, inner());
      }
      const auto [bound, index] = queue.top();
      queue.pop();
      // A box without variables (f is a constant) or too narrow to halve cannot be refined.
      if (tree_[index].first_child == 0 && !expand(index)) {
        settled = std::max(settled, bound);
        continue;
      }
      const std::size_t first = tree_[index].first_child;
      for (const std::size_t child : {first, first + 1}) {
        if (tree_[child].bound[direction] > inner()) refine(child, direction);
        if (tree_[child].bound[direction] > inner()) {
          queue.push({tree_[child].bound[direction], child});
        }
      }
      // The best box is where the extremum most likely is: polish the inner bound from its
      // centre now and then (a loose inner bound stops convergence as surely as a loose outer).
      if (options_.inner && ++pops >= next_polish) {
        const std::size_t better =
            tree_[first].bound[direction] >= tree_[first + 1].bound[direction] ? first : first + 1;
        if (!tree_[better].box.empty()) {
          next_polish *= 2;
          std::vector<double> centre(tree_[better].box.size());
          for (std::size_t i = 0; i < centre.size(); ++i) centre[i] = tree_[better].box[i].mid();
          local_search(root, std::move(centre), sign);
        }
      }
    }
    converged_[direction] = true;
    const double top = queue.empty() ? settled : std::max(queue.top().first, settled);
    return std::max(top, inner());
  }

  // Evaluates a box into a new node whose bounds are at most `parent`'s; returns its index.
  std::size_t add_node(std::vector<Interval> box, std::array<double, 2> parent) {
    const BoxEvaluation own = evaluate_box(box);
    TreeNode node{std::move(box),
                  {},
                  {std::min(own.bound[0], parent[0]), std::min(own.bound[1], parent[1])},
                  {true, true},
                  own.split};
    if (own.gradient_ok) {
      node.gradient = gradient_;
      node.refined = {false, false};
    }
    stored_intervals_ += node.box.size() + node.gradient.size();
    tree_.push_back(std::move(node));
    return tree_.size() - 1;
  }

  // Tightens a node's bound in a direction with its face and centred form (once; not after its
  // box is released, when the looser bound only orders the queue).
  void refine(std::size_t index, int direction) {
    TreeNode& node = tree_[index];
    if (node.refined[direction] || node.box.empty()) return;
    node.bound[direction] =
        std::min(node.bound[direction],
                 face_and_centred_bound(node.box, node.gradient, direction == 0 ? +1 : -1));
    node.refined[direction] = true;
    if (node.refined[0] && node.refined[1]) {
      stored_intervals_ -= node.gradient.size();
      node.gradient = {};
    }
  }

  // Evaluates the two children of a node; false if it cannot be split (no variables, or its split
  // variable too narrow to halve). The children come after every existing node, so first_child 0
  // means "not expanded".
  bool expand(std::size_t index) {
    if (tree_[index].box.empty()) return false;
    const Interval range = tree_[index].box[tree_[index].split];
    const double middle = range.mid();
    if (!(middle > range.lo && middle < range.hi)) return false;
    // The box is released below, and its bounds cap its children's: refine it now for the search
    // to come if that may pop it.
    if (direction_ == 0 && searches_minimum() && tree_[index].bound[1] > -result_->inner_lo)
      refine(index, 1);
    // f affine in the variable (and no constraints): its extremes over the box lie on the
    // variable's end points, so the children are those two faces, one variable fewer each.
    const bool faces = constraints_.empty() && f_.affine_in(tree_[index].split);
    for (int half = 0; half < 2; ++half) {
      std::vector<Interval> child = tree_[index].box;
      child[tree_[index].split] = faces       ? Interval{half == 0 ? range.lo : range.hi}
                                  : half == 0 ? Interval{range.lo, middle}
                                              : Interval{middle, range.hi};
      const std::size_t added = add_node(std::move(child), tree_[index].bound);
      if (half == 0) tree_[index].first_child = added;
    }
    release(index);
    for (const std::size_t child : {tree_[index].first_child, tree_[index].first_child + 1}) {
      if (!may_be_expanded(tree_[child])) release(child);
    }
    return true;
  }

  // Whether the search running or the one to come could pop the node and need its box: its bound,
  // in a direction not yet finished, exceeds that direction's inner bound (inner bounds only
  // improve, so a node that fails this never passes it later). Max (0) runs before min (1).
  bool may_be_expanded(const TreeNode& node) const {
    return (direction_ == 0 && node.bound[0] > result_->inner_hi) ||
           (searches_minimum() && node.bound[1] > -result_->inner_lo);
  }

  // Whether a search of f's minimum (direction 1) runs: always, except when deciding an upper
  // limit (`<`, `<=`), which searches the maximum only.
  bool searches_minimum() const {
    return !options_.decide || !upper_limit(options_.decide->relation);
  }

  void release(std::size_t index) {
    stored_intervals_ -= tree_[index].box.size() + tree_[index].gradient.size();
    tree_[index].box = {};
    tree_[index].gradient = {};
  }

  const BoundOptions& options_;
  std::vector<Interval> root_;
  CompiledFunction& f_;
  internal::GradientEvaluator<Interval>& f_interval_;  // f_.interval
  internal::GradientEvaluator<double>& f_double_;      // f_.real
  std::span<const std::unique_ptr<CompiledConstraint>> constraints_;
  std::span<const LinearForm> linear_;
  Objective objective_{};  // NLopt callback data: stable addresses while an optimiser runs
  std::vector<Objective> constraint_data_;
  std::vector<Interval> gradient_, face_, face_gradient_, centre_;
  std::vector<double> point_;
  BoundResult* result_{nullptr};
  std::vector<TreeNode> tree_;       // both directions' branch-and-bound tree; tree_[0] is the root
  std::size_t stored_intervals_{0};  // in tree_'s boxes
  int direction_{0};                 // of the search running: 0 maximises f, 1 minimises it
  std::size_t evaluations_{0};
  std::size_t work_{0};             // tape instructions evaluated (approximately: see BoundOptions)
  std::size_t evaluation_cost_{1};  // one pass over f's and the constraints' tapes
  double effort_scale_{1.0};        // of out_of_effort()'s share: kProbeShare during a probe
  bool time_limited_{false};
  bool undefined_{false};
  bool converged_[2]{false, false};
  std::chrono::steady_clock::time_point start_;
};

// Shortest decimal that reads back as the same double ("1e-09", not "0.000000").
std::string format_number(double value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

// Tightens `result` (a bound of f) with `other`, an earlier bound of f or a bound of SMP's rewrite
// of f. Its witnesses are feasible points (checked by its search): f's value there, where f is
// defined, is a value f attains, so it may improve the inner bounds.
void refine_with(BoundResult& result, const BoundResult& other,
                 internal::GradientEvaluator<Interval>& f, double tolerance) {
  // Work on the rigorous witness values (the inner bounds may have been clamped or averaged).
  if (!result.argmin_value.is_empty()) {
    result.inner_lo = result.argmin_value.hi;
    result.inner_hi = result.argmax_value.lo;
  } else {
    result.inner_lo = kInf;
    result.inner_hi = -kInf;
  }
  for (const std::vector<double>* point : {&other.argmin, &other.argmax}) {
    if (point->empty()) continue;
    const std::vector<Interval> x(point->begin(), point->end());
    const Interval value = f.value(x);
    if (value.is_empty() || value.possibly_undefined) continue;
    internal::offer_witness(result, *point, value);
  }
  // A rewrite equals f wherever f is defined, so its bounds hold for f. Values f attains outside
  // them would mean the rewrite is wrong: then it is not used.
  const bool usable = other.status != BoundStatus::kInfeasible &&
                      (result.argmin_value.is_empty() ||
                       (other.lo <= result.argmin_value.hi && other.hi >= result.argmax_value.lo));
  if (usable) {
    result.lo = std::max(result.lo, other.lo);
    result.hi = std::min(result.hi, other.hi);
    if (result.status == BoundStatus::kUnbounded && std::isfinite(result.lo) &&
        std::isfinite(result.hi)) {
      result.status = BoundStatus::kEffortLimit;
    }
  }
  result.time_limited = result.time_limited || other.time_limited;
  order_inner_bounds(result);
  if (usable && result.status == BoundStatus::kEffortLimit && result.relative_gap() <= tolerance) {
    result.status = BoundStatus::kConverged;
  }
}

}  // namespace

namespace internal {

void check_range(const std::string& name, double lo, double hi) {
  if (std::isnan(lo) || std::isnan(hi)) throw BoundsError("range of '" + name + "' is NaN");
  if (!std::isfinite(lo) || !std::isfinite(hi)) {
    throw BoundsError("range of '" + name + "' must be finite");
  }
  if (lo > hi) {
    throw BoundsError("range of '" + name + "' is empty: lower bound " + format_number(lo) +
                      " > upper bound " + format_number(hi));
  }
}

void check_variable(Expr variable, std::span<const Expr> earlier) {
  if (variable.is_null() || !variable.is_variable()) {
    throw BoundsError("a box entry must be a variable");
  }
  if (std::find(earlier.begin(), earlier.end(), variable) != earlier.end()) {
    throw BoundsError("variable '" + variable.name() + "' is in the box twice");
  }
}

void check_ranges(std::span<const Expr> variables, std::span<const Interval> ranges) {
  if (ranges.size() != variables.size()) {
    throw BoundsError("expected " + std::to_string(variables.size()) + " ranges, got " +
                      std::to_string(ranges.size()));
  }
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    check_range(variables[i].name(), ranges[i].lo, ranges[i].hi);
  }
}

void offer_witness(BoundResult& result, std::span<const double> point, const Interval& value) {
  // The first point is both witnesses, even where f's value overflows (exp(1000) is enclosed by
  // [DBL_MAX, inf]): then inner_lo is +inf, which is still an upper bound of f(argmin).
  const bool first = result.argmin_value.is_empty();
  if (first || value.hi < result.inner_lo) {
    result.inner_lo = value.hi;
    result.argmin.assign(point.begin(), point.end());
    result.argmin_value = value;
  }
  if (first || value.lo > result.inner_hi) {
    result.inner_hi = value.lo;
    result.argmax.assign(point.begin(), point.end());
    result.argmax_value = value;
  }
}

Tape compile_checked(std::span<const Expr> outputs, std::span<const Expr> variables,
                     const std::function<std::string(std::size_t)>& what) {
  try {
    return Tape::compile(outputs, variables);
  } catch (const symbolic::SymbolicError&) {
    for (std::size_t i = 0; i < outputs.size(); ++i)
      for (Expr v : symbolic::free_variables(outputs[i]))
        if (std::find(variables.begin(), variables.end(), v) == variables.end())
          throw BoundsError("unknown variable '" + v.name() + "' in " + what(i) +
                            ": give it a range");
    throw;
  }
}

}  // namespace internal

void order_inner_bounds(BoundResult& result) {
  if (result.argmin_value.is_empty() || result.argmax_value.is_empty()) {
    result.inner_lo = result.hi;
    result.inner_hi = result.lo;
    return;
  }
  // f(argmin) <= argmin_value.hi and f(argmin) <= hi, so the smaller is still an attained bound.
  result.inner_lo = std::min(result.argmin_value.hi, result.hi);
  result.inner_hi = std::max(result.argmax_value.lo, result.lo);
  if (result.inner_lo <= result.inner_hi) return;
  // Crossed: f varies less between the witnesses than their enclosures are wide. Within rounding
  // (a point's enclosure a few ulps wide) the midpoint is attained up to that rounding. A wider
  // crossing (an overflow enclosed by [DBL_MAX, inf], a point on atan2's cut enclosed by [-pi, pi])
  // says nothing more than the enclosures do: the inner range is then unknown ([hi, lo]), not a
  // made-up midpoint; the witnesses stay (their enclosures are still rigorous for decide()).
  const double crossing = result.inner_lo - result.inner_hi;
  const double scale = std::max({1.0, std::fabs(result.inner_lo), std::fabs(result.inner_hi)});
  if (std::isfinite(crossing) && crossing <= kRoundingCrossing * scale) {
    result.inner_lo = result.inner_hi = result.inner_hi + crossing / 2;
    return;
  }
  result.inner_lo = result.hi;
  result.inner_hi = result.lo;
}

void Box::add(Expr variable, double lo, double hi) {
  internal::check_variable(variable, variables);
  internal::check_range(variable.name(), lo, hi);
  variables.push_back(variable);
  ranges.push_back(Interval{lo, hi});
}

const char* to_string(BoundStatus status) {
  switch (status) {
    case BoundStatus::kConverged:
      return "converged";
    case BoundStatus::kEffortLimit:
      return "effort_limit";
    case BoundStatus::kUnbounded:
      return "unbounded";
    case BoundStatus::kInfeasible:
      return "infeasible";
  }
  return "?";
}

void BoundResult::check_invariants() const {
  const auto fail = [&](const char* what) {
    throw std::logic_error(std::string("BoundResult: ") + what + " (lo " + format_number(lo) +
                           ", inner_lo " + format_number(inner_lo) + ", inner_hi " +
                           format_number(inner_hi) + ", hi " + format_number(hi) + ")");
  };
  if (argmin_value.is_empty() != argmax_value.is_empty()) fail("one witness without the other");
  if (argmin_value.is_empty()) {
    if (!(inner_lo == hi && inner_hi == lo)) fail("without witnesses, inner must be [hi, lo]");
    return;
  }
  if (inner_lo == hi && inner_hi == lo) return;  // the witnesses' values too loose: unknown
  if (!(lo <= inner_lo && inner_lo <= inner_hi && inner_hi <= hi)) {
    fail("lo <= inner_lo <= inner_hi <= hi is broken");
  }
  if (!(argmin_value.hi >= inner_lo || argmin_value.hi >= hi)) {
    fail("inner_lo is below the value at argmin");
  }
}

std::string_view BoundResult::why_no_inner_range() const {
  if (has_inner_range()) return "";
  if (status == BoundStatus::kInfeasible)
    return "no point of the box satisfies the constraints and gives the expression a defined value";
  if (argmin_value.is_empty())
    return "no point was found where the expression is certainly defined";
  return "the values at the witnesses are enclosed too loosely to say what is attained (an "
         "overflow, or a point on a branch cut)";
}

double BoundResult::relative_gap() const {
  const double gap = std::max(hi - inner_hi, inner_lo - lo);
  const double width = inner_hi - inner_lo;
  if (gap <= 0) return 0.0;
  return width > 0 ? gap / width : kInf;
}

struct BoundProblem::Impl {
  // SMP's rewrite of f compiled for one set of box widths (the rewrite depends on them); null
  // when SMP leaves f as it is.
  struct Rewrite {
    std::vector<double> widths;
    std::unique_ptr<CompiledFunction> function;
  };
  static constexpr std::size_t kRewriteCacheSize = 4;

  Expr f;
  std::vector<Expr> variables;
  std::unique_ptr<CompiledFunction> compiled;
  CompiledConstraints constraints;
  std::vector<Rewrite> rewrites;  // most recently used first, at most kRewriteCacheSize
  // SMP's rewrite of f (unit widths, a small budget) when it uses every variable once and f does
  // not; computed on first use (single_use_rewrite). Null if there is none.
  std::optional<std::unique_ptr<CompiledFunction>> single_use;

  BoundResult run(CompiledFunction& function, std::span<const Interval> ranges,
                  const BoundOptions& options) {
    return Bounder(function, constraints, ranges, options).run();
  }

  // f with the staged effort of BoundOptions::simplify.
  BoundResult staged(std::span<const Interval> ranges, const BoundOptions& options);

  // Tried only on small expressions (at most kMaxInstructions tape instructions): a large one
  // (phase 2's preconditions) is almost never single-use after SMP, and this runs on every problem.
  CompiledFunction* single_use_rewrite() {
    constexpr std::size_t kBudget = 20'000;
    constexpr std::size_t kMaxInstructions = 256;
    if (!single_use) {
      single_use.emplace();
      if (compiled->tape.instructions().size() <= kMaxInstructions &&
          symbolic::occurrence_cost(f) > 0) {
        const Expr g = symbolic::simplify(f, {.budget = kBudget});
        if (symbolic::occurrence_cost(g) == 0) {
          *single_use = std::make_unique<CompiledFunction>(g, variables);
        }
      }
    }
    return single_use->get();
  }

  // The compiled rewrite for these widths (null if SMP does not change f), from the cache or
  // built now. Equal widths give the same rewrite, so caching never changes a result.
  CompiledFunction* rewrite(std::vector<double> widths) {
    const auto cached = std::find_if(rewrites.begin(), rewrites.end(),
                                     [&](const Rewrite& r) { return r.widths == widths; });
    if (cached != rewrites.end()) {
      std::rotate(rewrites.begin(), cached, cached + 1);
      return rewrites.front().function.get();
    }
    std::map<std::string, double> by_name;
    for (std::size_t i = 0; i < variables.size(); ++i) by_name[variables[i].name()] = widths[i];
    const Expr rewritten = symbolic::simplify(f, {.widths = by_name});
    Rewrite entry{
        std::move(widths),
        rewritten == f ? nullptr : std::make_unique<CompiledFunction>(rewritten, variables)};
    if (rewrites.size() == kRewriteCacheSize) rewrites.pop_back();
    rewrites.insert(rewrites.begin(), std::move(entry));
    return rewrites.front().function.get();
  }
};

BoundProblem::BoundProblem(Expr f, std::span<const Expr> variables,
                           std::span<const Constraint> constraints)
    : impl_(std::make_unique<Impl>()) {
  if (f.is_null()) throw BoundsError("no expression to bound");
  for (std::size_t i = 0; i < variables.size(); ++i) {
    internal::check_variable(variables[i], variables.first(i));
  }
  for (const Constraint& c : constraints) {
    if (c.g.is_null()) throw BoundsError("a constraint has no expression");
  }
  impl_->f = f;
  impl_->variables.assign(variables.begin(), variables.end());
  impl_->compiled = std::make_unique<CompiledFunction>(f, variables);
  for (const Constraint& c : constraints) {
    impl_->constraints.all.push_back(std::make_unique<CompiledConstraint>(c, variables));
    if (auto form = linear_form(c.g, impl_->variables)) {
      // g >= 0  <=>  -g <= 0.
      if (c.relation == Relation::kGreater || c.relation == Relation::kGreaterEqual) {
        for (Interval& a : form->coefficients) a = -a;
        form->constant = -form->constant;
      }
      impl_->constraints.linear.push_back(std::move(*form));
    }
  }
}

BoundProblem::BoundProblem(Expr f, std::span<const Expr> variables, Tape tape_of_f)
    : impl_(std::make_unique<Impl>()) {
  impl_->f = f;
  impl_->variables.assign(variables.begin(), variables.end());
  impl_->compiled = std::make_unique<CompiledFunction>(f, variables, std::move(tape_of_f));
}

BoundProblem::BoundProblem(BoundProblem&&) noexcept = default;
BoundProblem& BoundProblem::operator=(BoundProblem&&) noexcept = default;
BoundProblem::~BoundProblem() = default;

const std::vector<Expr>& BoundProblem::variables() const { return impl_->variables; }

BoundResult BoundProblem::bound(std::span<const Interval> ranges, const BoundOptions& options) {
  internal::check_ranges(impl_->variables, ranges);
  if (!(options.tolerance >= 0)) throw BoundsError("tolerance must be >= 0");
  if (!options.rewrite_widths.empty()) {
    if (options.rewrite_widths.size() != ranges.size())
      throw BoundsError("rewrite_widths: expected " + std::to_string(ranges.size()) +
                        " widths (one per variable), got " +
                        std::to_string(options.rewrite_widths.size()));
    for (std::size_t i = 0; i < ranges.size(); ++i)
      if (!(options.rewrite_widths[i] >= 0 && std::isfinite(options.rewrite_widths[i])))
        throw BoundsError("rewrite_widths: the width of '" + impl_->variables[i].name() +
                          "' must be finite and >= 0, got " +
                          format_number(options.rewrite_widths[i]));
  }
  const BoundResult result = impl_->staged(ranges, options);
#ifndef NDEBUG
  result.check_invariants();
#endif
  return result;
}

std::vector<double> BoundProblem::width_shares(std::span<const Interval> ranges,
                                               std::span<const double> pins) {
  internal::check_ranges(impl_->variables, ranges);
  const std::size_t n = ranges.size();
  if (pins.size() != n) throw BoundsError("width_shares: one pin per variable");
  for (std::size_t i = 0; i < n; ++i) {
    if (!ranges[i].contains(pins[i]))
      throw BoundsError("width_shares: the pin of " + impl_->variables[i].name() +
                        " lies outside its range");
  }
  internal::GradientEvaluator<Interval>& f = impl_->compiled->interval;
  std::vector<double> shares(n, 0.0);
  const auto share = [](double removed, double whole) {
    return whole > 0 && std::isfinite(whole) ? std::clamp(removed / whole, 0.0, 1.0) : 0.0;
  };
  std::vector<Interval> gradient(n);
  const Interval value = f.value_and_gradient(ranges, gradient);
  const bool differentiable =
      !value.possibly_undefined && std::ranges::all_of(gradient, [](const Interval& g) {
        return g.is_bounded() && !g.possibly_undefined && !g.is_empty();
      });
  std::vector<Interval> point(pins.begin(), pins.end());
  if (differentiable) {
    std::vector<double> term(n);
    double whole = f.value(point).width();
    for (std::size_t i = 0; i < n; ++i) {
      term[i] = (gradient[i] * (ranges[i] - Interval{pins[i]})).width();
      whole += term[i];
    }
    for (std::size_t i = 0; i < n; ++i) shares[i] = share(term[i], whole);
    return shares;
  }
  const double whole = f.value(ranges).width();
  std::vector<Interval> pinned(ranges.begin(), ranges.end());
  for (std::size_t i = 0; i < n; ++i) {
    pinned[i] = Interval{pins[i]};
    shares[i] = share(whole - f.value(pinned).width(), whole);
    pinned[i] = ranges[i];
  }
  return shares;
}

BoundResult BoundProblem::Impl::staged(std::span<const Interval> ranges,
                                       const BoundOptions& options) {
  CompiledFunction& f = *compiled;
  if (!options.simplify) return run(f, ranges, options);
  // Deciding: any stage whose result decides the target is the answer.
  const auto known = [&](const BoundResult& r) {
    return options.decide &&
           decide({{}, this->f, options.decide->relation, options.decide->threshold}, r) !=
               Verdict::kUndecided;
  };
  // Staged effort: f gets an eighth of the budget first; if that stops short, SMP's rewrite gets
  // the same share (it often converges at once where f's repeated variables defeat bisection),
  // and then f starts again with the whole budget (so a call may spend up to 1.25 budgets). The
  // earlier stages' bounds are intersected with the last.
  BoundOptions first = options;
  first.max_box_evaluations = std::max<std::size_t>(1, options.max_box_evaluations / 8);
  first.max_seconds = options.max_seconds / 8;
  first.max_work = std::max<std::size_t>(1, options.max_work / 8);
  // Deciding tries f's first stage before any rewrite: most inequalities are decided there, and
  // building a rewrite (SMP) costs more than that stage.
  std::optional<BoundResult> first_result;
  if (options.decide) {
    first_result = run(f, ranges, first);
    if (first_result->status != BoundStatus::kEffortLimit || known(*first_result))
      return *first_result;
  }
  // A rewrite that uses every variable once (t/(t + 1) -> 1 - 1/(t + 1)) encloses f's range up
  // to rounding: bounded first with the same share, it usually settles f alone, and exactly where
  // f would only meet the tolerance. Its witnesses count only where f itself is defined there
  // (refine_with evaluates f), and whether f may be undefined is asked of f's own natural
  // extension too (SMP keeps domains, but the flag must not rest on that alone).
  std::optional<BoundResult> single_use_result;
  if (CompiledFunction* single = single_use_rewrite()) {
    BoundResult settled;
    settled.lo = -kInf;
    settled.hi = kInf;
    settled.status = BoundStatus::kEffortLimit;
    const BoundResult other = run(*single, ranges, first);
    settled.evaluations = other.evaluations;
    settled.time_limited = other.time_limited;
    settled.possibly_undefined =
        other.possibly_undefined || f.interval.value(ranges).possibly_undefined;
    refine_with(settled, other, f.interval, options.tolerance);
    if (settled.status == BoundStatus::kConverged || known(settled)) return settled;
    single_use_result = settled;
  }
  BoundResult result = first_result ? *first_result : run(f, ranges, first);
  if (single_use_result) {
    // Its outer bounds hold for f: intersect them, and count its boxes.
    result.evaluations += single_use_result->evaluations;
    refine_with(result, *single_use_result, f.interval, options.tolerance);
  }
  if (result.status != BoundStatus::kEffortLimit || known(result)) return result;
  std::vector<double> widths = options.rewrite_widths;
  if (widths.empty())
    for (const Interval& range : ranges) widths.push_back(range.width());
  if (CompiledFunction* rewritten = rewrite(std::move(widths))) {
    const BoundResult other = run(*rewritten, ranges, first);
    result.evaluations += other.evaluations;
    refine_with(result, other, f.interval, options.tolerance);
    if (result.status != BoundStatus::kEffortLimit || known(result)) return result;
  }
  const BoundResult earlier = result;
  result = run(f, ranges, options);
  result.evaluations += earlier.evaluations;
  refine_with(result, earlier, f.interval, options.tolerance);
  return result;
}

BoundResult bound(Expr f, const Box& box, const BoundOptions& options,
                  std::span<const Constraint> constraints) {
  if (f.is_null()) throw BoundsError("no expression to bound");
  return BoundProblem(f, box.variables, constraints).bound(box.ranges, options);
}

}  // namespace spar::bounds
