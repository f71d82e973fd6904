// bound(): natural extension, monotonicity, centred form, branch and bound, inner search.
#include "bounds/bound.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <nlopt.hpp>
#include <optional>
#include <queue>
#include <set>

#include "bounds/internal/gradient.hpp"
#include "bounds/internal/linear_enclosure.hpp"
#include "symbolic/operations.hpp"
#include "symbolic/smp.hpp"
#include "symbolic/tape.hpp"

namespace spar::bounds {
namespace {

using symbolic::Expr;
using symbolic::Tape;
constexpr double kInf = std::numeric_limits<double>::infinity();

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

// One node of the branch-and-bound queue: a box and an upper bound of s·f over it.
struct Node {
  double bound;
  std::vector<Interval> box;
  int split;  // variable to bisect next
  bool operator<(const Node& other) const { return bound < other.bound; }
};

class Bounder {
 public:
  Bounder(Expr f, const Box& box, const BoundOptions& options,
          std::span<const Constraint> constraints)
      : options_(options),
        variables_(box.variables),
        root_(box.ranges),
        f_tape_(Tape::compile(std::array{f}, variables_)),
        f_interval_(f_tape_),
        f_double_(f_tape_),
        start_(std::chrono::steady_clock::now()) {
    for (const Constraint& c : constraints) {
      relations_.push_back(c.relation);
      g_tapes_.push_back(Tape::compile(std::array{c.g}, variables_));
      if (auto form = linear_form(c.g, variables_)) {
        // g >= 0  <=>  -g <= 0.
        if (c.relation == Relation::kGreater || c.relation == Relation::kGreaterEqual) {
          for (Interval& a : form->coefficients) a = -a;
          form->constant = -form->constant;
        }
        linear_.push_back(std::move(*form));
      }
    }
    if (!linear_.empty()) {
      f_interval_.set_enclosures(
          internal::linear_enclosures(internal::affine_forms(f_tape_), linear_, root_));
    }
    for (const Tape& tape : g_tapes_) {
      g_interval_.emplace_back(tape);
      g_double_.emplace_back(tape);
    }
    gradient_.resize(variables_.size());
    point_.resize(variables_.size());
  }

  BoundResult run() {
    BoundResult result;
    result.inner_lo = kInf;
    result.inner_hi = -kInf;
    result_ = &result;
    std::vector<Interval> root = root_;
    if (!contract(root)) return infeasible(result);
    inner_candidates(root);
    if (options_.inner) {
      nlopt_search(root, +1);
      nlopt_search(root, -1);
    }
    const double hi = search(root, +1);
    const double lo = -search(root, -1);
    result.lo = lo;
    result.hi = hi;
    result.evaluations = evaluations_;
    if (hi < lo && result.argmax.empty()) return infeasible(result);
    result.possibly_undefined = undefined_;
    if (result.argmax.empty()) {  // no verified feasible point: report the outer bounds only
      result.inner_lo = hi;
      result.inner_hi = lo;
    }
    if (!std::isfinite(lo) || !std::isfinite(hi)) {
      result.status = BoundStatus::kUnbounded;
    } else {
      result.status =
          converged_[0] && converged_[1] ? BoundStatus::kConverged : BoundStatus::kEffortLimit;
    }
    return result;
  }

 private:
  BoundResult& infeasible(BoundResult& result) {
    result.lo = kInf;
    result.hi = -kInf;
    result.inner_lo = kInf;
    result.inner_hi = -kInf;
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
    for (std::size_t c = 0; c < g_interval_.size(); ++c) {
      if (certainly_fails(g_interval_[c].value(box), relations_[c])) return false;
      if (!options_.centred_form) continue;
      const Interval g = g_interval_[c].value_and_gradient(box, gradient_);
      bool gradient_ok = !g.possibly_undefined;
      for (const Interval& partial : gradient_) {
        gradient_ok = gradient_ok && partial.is_bounded() && !partial.possibly_undefined;
      }
      if (!gradient_ok) continue;
      centre_.resize(n);
      for (std::size_t i = 0; i < n; ++i) centre_[i] = Interval{box[i].mid()};
      Interval centred = g_interval_[c].value(centre_);
      if (centred.is_empty() || centred.possibly_undefined) continue;
      for (std::size_t i = 0; i < n; ++i) {
        if (box[i].width() > 0) centred = centred + gradient_[i] * (box[i] - centre_[i]);
      }
      if (certainly_fails(centred, relations_[c])) return false;
    }
    return true;
  }

  // Offers a point as a witness: kept if it certainly satisfies the constraints and f is
  // defined there; inner bounds use the rigorous enclosure of f at the point.
  void offer(std::span<const double> x) {
    std::vector<Interval> p(x.begin(), x.end());
    for (std::size_t c = 0; c < g_interval_.size(); ++c) {
      if (!certainly_holds(g_interval_[c].value(p), relations_[c])) return;
    }
    const Interval v = f_interval_.value(p);
    if (v.is_empty() || v.possibly_undefined) return;
    if (v.hi < result_->inner_lo) {
      result_->inner_lo = v.hi;
      result_->argmin.assign(x.begin(), x.end());
    }
    if (v.lo > result_->inner_hi) {
      result_->inner_hi = v.lo;
      result_->argmax.assign(x.begin(), x.end());
    }
  }

  // Centre and (for up to 10 variables) corners of the box.
  void inner_candidates(std::span<const Interval> box) {
    const std::size_t n = box.size();
    for (std::size_t i = 0; i < n; ++i) point_[i] = box[i].mid();
    offer(point_);
    if (n > 10) return;
    for (std::size_t mask = 0; mask < (std::size_t{1} << n); ++mask) {
      for (std::size_t i = 0; i < n; ++i) point_[i] = (mask >> i) & 1 ? box[i].hi : box[i].lo;
      offer(point_);
    }
  }

  struct Objective {
    Bounder* self;
    int sign;
    std::size_t constraint;  // for constraint callbacks
  };

  // Minimises -sign·f: a global stage (DIRECT-L, or ISRES with constraints), then a local one
  // from the best point. Witnesses are re-checked by offer().
  void nlopt_search(std::span<const Interval> box, int sign) {
    const unsigned n = static_cast<unsigned>(box.size());
    if (n == 0) return;
    const std::vector<double>& start = sign > 0 ? result_->argmax : result_->argmin;
    std::vector<double> x(n);
    for (unsigned i = 0; i < n; ++i) x[i] = start.empty() ? box[i].mid() : start[i];
    const bool constrained = !g_tapes_.empty();
    try {
      nlopt::srand(20261123);
      nlopt::opt global(constrained ? nlopt::GN_ISRES : nlopt::GN_DIRECT_L, n);
      configure(global, box, sign);
      global.set_maxeval(constrained ? 300 * (n + 1) : 60 * (n + 1));
      double value = 0;
      global.optimize(x, value);
      offer(x);
    } catch (const std::exception&) {
      // NLopt only tightens inner bounds; a failed stage leaves them as they are.
    }
    const std::vector<double>& best = sign > 0 ? result_->argmax : result_->argmin;
    if (!best.empty()) x = best;
    local_search(box, x, sign);
  }

  // SLSQP with tape gradients from `x`, within `box`; offers the point it ends at.
  void local_search(std::span<const Interval> box, std::vector<double> x, int sign) {
    try {
      nlopt::opt local(nlopt::LD_SLSQP, static_cast<unsigned>(x.size()));
      configure(local, box, sign);
      local.set_maxeval(200);
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
    for (std::size_t c = 0; c < g_tapes_.size(); ++c) constraint_data_.push_back({this, 0, c});
    for (Objective& data : constraint_data_) {
      opt.add_inequality_constraint(&Bounder::nlopt_constraint, &data, 0.0);
    }
  }

  static double nlopt_objective(unsigned n, const double* x, double* gradient, void* data) {
    auto& objective = *static_cast<Objective*>(data);
    Bounder& self = *objective.self;
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
    const Relation relation = self.relations_[objective.constraint];
    const double flip =
        (relation == Relation::kGreater || relation == Relation::kGreaterEqual) ? -1.0 : 1.0;
    auto& evaluator = self.g_double_[objective.constraint];
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

  // An upper bound of sign·f over the box (after contraction), or -inf if the box is discarded.
  // Also offers the box midpoint as a witness and picks the variable to bisect.
  double evaluate_box(std::vector<Interval>& box, int sign, int& split) {
    ++evaluations_;
    split = widest(box);
    if (!contract(box) || !may_be_feasible(box)) return -kInf;
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
      if (feasible.is_empty()) return -kInf;  // the linear constraints exclude the whole box
      value = Interval{std::max(value.lo, feasible.lo), std::min(value.hi, feasible.hi),
                       feasible.possibly_undefined};
    }
    undefined_ = undefined_ || value.possibly_undefined;
    if (value.is_empty()) return -kInf;  // f is defined nowhere in this box
    double best = sign > 0 ? value.hi : -value.lo;
    for (std::size_t i = 0; i < n; ++i) point_[i] = box[i].mid();
    offer(point_);
    if (!gradient_ok) return best;
    // Smear rule: bisect where |gradient| x width is largest.
    double largest = -1;
    for (std::size_t i = 0; i < n; ++i) {
      const double smear =
          std::max(std::fabs(gradient_[i].lo), std::fabs(gradient_[i].hi)) * box[i].width();
      if (smear > largest && box[i].width() > 0) {
        largest = smear;
        split = static_cast<int>(i);
      }
    }
    // Monotone variables sit at the end point that maximises sign·f: bound that face instead.
    std::vector<Interval>& face = face_;
    face = box;
    bool fixed = false;
    if (options_.monotonicity) {
      for (std::size_t i = 0; i < n; ++i) {
        const Interval g = sign > 0 ? gradient_[i] : -gradient_[i];
        if (g.lo >= 0 && box[i].width() > 0) {
          face[i] = Interval{box[i].hi};
          fixed = true;
        } else if (g.hi <= 0 && box[i].width() > 0) {
          face[i] = Interval{box[i].lo};
          fixed = true;
        }
      }
      if (fixed) {
        const Interval on_face = f_interval_.value(face);
        if (!on_face.is_empty()) best = std::min(best, sign > 0 ? on_face.hi : -on_face.lo);
      }
    }
    if (options_.centred_form) {
      // f(X) ⊆ f(c) + Σ G_i (X_i - c_i) on the face (G over the box encloses G over the face).
      std::vector<Interval>& centre = centre_;
      centre.resize(n);
      for (std::size_t i = 0; i < n; ++i) centre[i] = Interval{face[i].mid()};
      Interval centred = f_interval_.value(centre);
      for (std::size_t i = 0; i < n; ++i) {
        if (face[i].width() > 0) centred = centred + gradient_[i] * (face[i] - centre[i]);
      }
      if (!centred.is_empty() && !centred.possibly_undefined) {
        best = std::min(best, sign > 0 ? centred.hi : -centred.lo);
      }
    }
    return best;
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

  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  // Sound upper bound of sign·f over the feasible box; best-first bisection.
  double search(const std::vector<Interval>& root, int sign) {
    const int direction = sign > 0 ? 0 : 1;
    const auto inner = [&] { return sign > 0 ? result_->inner_hi : -result_->inner_lo; };
    const auto target_gap = [&] {
      const double width = result_->inner_hi - result_->inner_lo;
      const double scale = std::max(std::fabs(result_->inner_hi), std::fabs(result_->inner_lo));
      return std::max(options_.tolerance * (std::isfinite(width) ? width : 0.0),
                      std::isfinite(scale) ? 1e-14 * scale : 0.0);
    };
    std::priority_queue<Node> queue;
    double settled = -kInf;  // bound of boxes too small to bisect
    std::vector<Interval> box = root;
    int split = 0;
    const double root_bound = evaluate_box(box, sign, split);
    if (root_bound > -kInf) queue.push({root_bound, box, split});
    const std::size_t budget = options_.max_box_evaluations / 2 * (direction + 1);
    std::size_t pops = 0, next_polish = 64;
    while (!queue.empty()) {
      const double top = std::max(queue.top().bound, settled);
      if (top - inner() <= target_gap()) break;
      if (!options_.branch_and_bound || evaluations_ >= budget ||
          elapsed() > options_.max_seconds * (direction + 1) / 2) {
        return std::max(top, inner());
      }
      Node node = queue.top();
      queue.pop();
      // The best box is where the extremum most likely is: polish the inner bound from its
      // centre now and then (a loose inner bound stops convergence as surely as a loose outer).
      if (options_.inner && ++pops >= next_polish) {
        next_polish *= 2;
        std::vector<double> centre(node.box.size());
        for (std::size_t i = 0; i < centre.size(); ++i) centre[i] = node.box[i].mid();
        local_search(root, std::move(centre), sign);
      }
      const Interval range = node.box[node.split];
      const double middle = range.mid();
      if (!(middle > range.lo && middle < range.hi)) {
        settled = std::max(settled, node.bound);
        continue;
      }
      for (int half = 0; half < 2; ++half) {
        std::vector<Interval> child = node.box;
        child[node.split] = half == 0 ? Interval{range.lo, middle} : Interval{middle, range.hi};
        int child_split = 0;
        const double child_bound = std::min(evaluate_box(child, sign, child_split), node.bound);
        if (child_bound > inner()) queue.push({child_bound, std::move(child), child_split});
      }
    }
    converged_[direction] = true;
    const double top = queue.empty() ? settled : std::max(queue.top().bound, settled);
    return std::max(top, inner());
  }

  const BoundOptions& options_;
  std::vector<Expr> variables_;
  std::vector<Interval> root_;
  Tape f_tape_;
  internal::GradientEvaluator<Interval> f_interval_;
  internal::GradientEvaluator<double> f_double_;
  std::vector<Tape> g_tapes_;  // one per constraint; complete before the evaluators point at it
  std::vector<Relation> relations_;
  std::vector<internal::GradientEvaluator<Interval>> g_interval_;
  std::vector<internal::GradientEvaluator<double>> g_double_;
  std::vector<LinearForm> linear_;
  Objective objective_{};  // NLopt callback data: stable addresses while an optimiser runs
  std::vector<Objective> constraint_data_;
  std::vector<Interval> gradient_, face_, centre_;
  std::vector<double> point_;
  BoundResult* result_{nullptr};
  std::size_t evaluations_{0};
  bool undefined_{false};
  bool converged_[2]{false, false};
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

void Box::add(Expr variable, double lo, double hi) {
  if (variable.is_null() || !variable.is_variable()) {
    throw BoundsError("a box entry must be a variable");
  }
  const std::string& name = variable.name();
  if (std::isnan(lo) || std::isnan(hi)) throw BoundsError("range of '" + name + "' is NaN");
  if (!std::isfinite(lo) || !std::isfinite(hi)) {
    throw BoundsError("range of '" + name + "' must be finite");
  }
  if (lo > hi) {
    throw BoundsError("range of '" + name + "' is empty: lower bound " + std::to_string(lo) +
                      " > upper bound " + std::to_string(hi));
  }
  if (std::find(variables.begin(), variables.end(), variable) != variables.end()) {
    throw BoundsError("variable '" + name + "' is in the box twice");
  }
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

double BoundResult::relative_gap() const {
  const double gap = std::max(hi - inner_hi, inner_lo - lo);
  const double width = inner_hi - inner_lo;
  if (gap <= 0) return 0.0;
  return width > 0 ? gap / width : kInf;
}

namespace {

// Tightens `result` (a bound of f) with `other`, an earlier bound of f or a bound of SMP's rewrite
// of f. Its witnesses are feasible points (checked by its search): f's value there, where f is
// defined, is a value f attains, so it may improve the inner bounds.
void refine_with(BoundResult& result, const BoundResult& other, Expr f, const Box& box,
                 double tolerance) {
  const Tape tape = Tape::compile(std::array{f}, box.variables);
  symbolic::TapeEvaluator<Interval> evaluator(tape);
  for (const std::vector<double>* point : {&other.argmin, &other.argmax}) {
    if (point->empty()) continue;
    const std::vector<Interval> x(point->begin(), point->end());
    Interval value[1];
    evaluator.evaluate(x, value);
    if (value[0].is_empty() || value[0].possibly_undefined) continue;
    if (value[0].hi < result.inner_lo) {
      result.inner_lo = value[0].hi;
      result.argmin = *point;
    }
    if (value[0].lo > result.inner_hi) {
      result.inner_hi = value[0].lo;
      result.argmax = *point;
    }
  }
  // A rewrite equals f wherever f is defined, so its bounds hold for f. Values f attains outside
  // them would mean the rewrite is wrong: then it is not used.
  if (other.status == BoundStatus::kInfeasible || other.lo > result.inner_lo ||
      other.hi < result.inner_hi) {
    return;
  }
  result.lo = std::max(result.lo, other.lo);
  result.hi = std::min(result.hi, other.hi);
  if (result.relative_gap() <= tolerance) result.status = BoundStatus::kConverged;
}

}  // namespace

BoundResult bound(Expr f, const Box& box, const BoundOptions& options,
                  std::span<const Constraint> constraints) {
  if (f.is_null()) throw BoundsError("no expression to bound");
  const auto check = [&](Expr e, const char* what) {
    for (Expr v : symbolic::free_variables(e)) {
      if (std::find(box.variables.begin(), box.variables.end(), v) == box.variables.end()) {
        throw BoundsError(std::string("unknown variable '") + v.name() + "' in the " + what +
                          ": give it a range");
      }
    }
  };
  check(f, "expression");
  for (const Constraint& c : constraints) check(c.g, "constraint");
  if (!(options.tolerance >= 0)) throw BoundsError("tolerance must be >= 0");
  if (!options.simplify) return Bounder(f, box, options, constraints).run();
  // Staged effort: f gets an eighth of the budget first; if that stops short, SMP's rewrite gets
  // the same share (it often converges at once where f's repeated variables defeat bisection),
  // and then f starts again with the whole budget (so a call may spend up to 1.25 budgets). The
  // earlier stages' bounds are intersected with the last.
  BoundOptions first = options;
  first.max_box_evaluations = std::max<std::size_t>(1, options.max_box_evaluations / 8);
  first.max_seconds = options.max_seconds / 8;
  BoundResult result = Bounder(f, box, first, constraints).run();
  if (result.status != BoundStatus::kEffortLimit) return result;
  std::map<std::string, double> widths;
  for (std::size_t i = 0; i < box.variables.size(); ++i) {
    widths[box.variables[i].name()] = box.ranges[i].width();
  }
  const Expr rewritten = symbolic::simplify(f, {.widths = widths});
  if (rewritten != f) {
    const BoundResult other = Bounder(rewritten, box, first, constraints).run();
    result.evaluations += other.evaluations;
    refine_with(result, other, f, box, options.tolerance);
    if (result.status != BoundStatus::kEffortLimit) return result;
  }
  const BoundResult earlier = result;
  result = Bounder(f, box, options, constraints).run();
  result.evaluations += earlier.evaluations;
  refine_with(result, earlier, f, box, options.tolerance);
  return result;
}

}  // namespace spar::bounds
