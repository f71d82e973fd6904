#include "spar/planner/uncertainty/probability.hpp"

#include <cholmod.h>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <SuiteSparseQR.hpp>
#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>
#include <tuple>
#include <type_traits>

#include "spar/bounds/inequality.hpp"
#include "spar/common/deadline.hpp"
#include "spar/common/parallel.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/uncertainty/analysis.hpp"
#include "spar/planner/uncertainty/internal/bisection.hpp"
#include "spar/planner/uncertainty/internal/own_copy.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::planner {
namespace {

using symbolic::Expr;

static_assert(sizeof(SuiteSparse_long) == sizeof(std::int64_t),
              "Sensitivities' indices are CHOLMOD's long indices");

// ---- the standard normal ----
double normal_pdf(double x) { return std::exp(-0.5 * x * x) / std::sqrt(2 * std::numbers::pi); }
double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::numbers::sqrt2); }
// Φ(b) - Φ(a) for a <= b, without cancellation in either tail.
double normal_mass(double a, double b) {
  if (a >= 0)
    return 0.5 * (std::erfc(a / std::numbers::sqrt2) - std::erfc(b / std::numbers::sqrt2));
  if (b <= 0) return normal_cdf(b) - normal_cdf(a);
  return 1 - normal_cdf(a) - 0.5 * std::erfc(b / std::numbers::sqrt2);
}
// Φ^-1(p), p in (0, 1) (Boost.Math).
double normal_quantile(double p) { return boost::math::quantile(boost::math::normal(), p); }

// Wilson score interval (95%) of `k` successes in `n` trials.
std::pair<double, double> wilson(std::size_t k, std::size_t n) {
  if (n == 0) return {0.0, 1.0};
  static const double z = normal_quantile(0.975);  // 1.95996...
  const double p = static_cast<double>(k) / n, z2n = z * z / n;
  const double centre = (p + z2n / 2) / (1 + z2n);
  const double half = z / (1 + z2n) * std::sqrt(p * (1 - p) / n + z2n / (4 * n));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

// Whether the precondition is violated where its expression has `value` (NaN: undefined there).
bool violated(const bounds::Inequality& inequality, double value) {
  return !holds(value, inequality.relation, inequality.threshold);
}

// P(violation) of N(mean, sigma^2) truncated to the support [lo, hi] of f (the sound bound).
double truncated_violation(const bounds::Inequality& inequality, double mean, double sigma,
                           double lo, double hi) {
  const double t = inequality.threshold;
  const bool above = upper_limit(inequality.relation);
  // The support decides first: a proved precondition gets exactly 0.
  if (above ? t >= hi : t <= lo) return 0.0;
  if (above ? t < lo : t > hi) return 1.0;
  const double m = std::clamp(mean, lo, hi);
  if (!(sigma > 0) || !std::isfinite(sigma)) return violated(inequality, m) ? 1.0 : 0.0;
  const double alpha = (lo - m) / sigma, beta = (hi - m) / sigma, tau = (t - m) / sigma;
  const double support = normal_mass(alpha, beta);
  if (!(support > 0)) return violated(inequality, m) ? 1.0 : 0.0;
  const double mass = above ? normal_mass(tau, beta) : normal_mass(alpha, tau);
  return std::clamp(mass / support, 0.0, 1.0);
}

// One variable's sampler: uniform on its range, or its truncated Gaussian by inversion.
struct Sampler {
  double lo{0.0}, hi{0.0}, sigma{0.0}, cdf_lo{0.0}, cdf_hi{0.0};
  explicit Sampler(const SpaceVariable& v) : lo(v.lower), hi(v.upper), sigma(v.sigma) {
    if (sigma > 0) {
      cdf_lo = normal_cdf(lo / sigma);
      cdf_hi = normal_cdf(hi / sigma);
    }
  }
  template <class Random>
  double operator()(Random& random) const {
    const double u = std::uniform_real_distribution<double>(0.0, 1.0)(random);
    if (!(hi > lo)) return lo;
    if (!(sigma > 0) || !(cdf_hi > cdf_lo)) return lo + u * (hi - lo);
    const double p = cdf_lo + u * (cdf_hi - cdf_lo);
    // p in (0, 1) strictly: the inverse is finite; clamp only against its last-ulp rounding.
    return std::clamp(sigma * normal_quantile(std::clamp(p, 1e-300, 1 - 1e-16)), lo, hi);
  }
};

// ---- CHOLMOD (long interface: SPQR needs it) ----
class Cholmod {
 public:
  Cholmod() { cholmod_l_start(&common_); }
  ~Cholmod() { cholmod_l_finish(&common_); }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;
  cholmod_common* get() { return &common_; }

 private:
  cholmod_common common_;
};
struct SparseDeleter {
  cholmod_common* common;
  void operator()(cholmod_sparse* a) const { cholmod_l_free_sparse(&a, common); }
};
struct DenseDeleter {
  cholmod_common* common;
  void operator()(cholmod_dense* a) const { cholmod_l_free_dense(&a, common); }
};
struct FactorDeleter {
  cholmod_common* common;
  void operator()(cholmod_factor* a) const { cholmod_l_free_factor(&a, common); }
};
struct TripletDeleter {
  cholmod_common* common;
  void operator()(cholmod_triplet* a) const { cholmod_l_free_triplet(&a, common); }
};
using SparsePtr = std::unique_ptr<cholmod_sparse, SparseDeleter>;
using DensePtr = std::unique_ptr<cholmod_dense, DenseDeleter>;

// A matrix in compressed sparse column form that we own (CHOLMOD views it, never frees it).
struct Csc {
  std::size_t rows{0}, cols{0};
  std::vector<std::int64_t> start, index;
  std::vector<double> value;
  // The view CHOLMOD reads; valid while this Csc lives and is not resized.
  cholmod_sparse view() {
    cholmod_sparse a{};
    a.nrow = rows;
    a.ncol = cols;
    a.nzmax = std::max<std::size_t>(1, value.size());
    a.p = start.data();
    a.i = index.data();
    a.x = value.data();
    a.stype = 0;
    a.itype = CHOLMOD_LONG;
    a.xtype = CHOLMOD_REAL;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    return a;
  }
};

struct Triplet {
  std::size_t row, col;
  double value;
};
// Sorts by column then row; duplicates are summed.
Csc to_csc(std::size_t rows, std::size_t cols, std::vector<Triplet> triplets) {
  std::sort(triplets.begin(), triplets.end(), [](const Triplet& a, const Triplet& b) {
    return std::tie(a.col, a.row) < std::tie(b.col, b.row);
  });
  Csc m{.rows = rows,
        .cols = cols,
        .start = std::vector<std::int64_t>(cols + 1, 0),
        .index = {},
        .value = {}};
  for (std::size_t i = 0; i < triplets.size(); ++i) {
    const Triplet& t = triplets[i];
    if (i > 0 && triplets[i - 1].col == t.col && triplets[i - 1].row == t.row) {
      m.value.back() += t.value;
      continue;
    }
    m.index.push_back(static_cast<std::int64_t>(t.row));
    m.value.push_back(t.value);
    ++m.start[t.col + 1];
  }
  for (std::size_t j = 0; j < cols; ++j) m.start[j + 1] += m.start[j];
  return m;
}

Eigen::MatrixXd to_dense(const Csc& m) {
  Eigen::MatrixXd dense =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(m.rows), static_cast<Eigen::Index>(m.cols));
  for (std::size_t j = 0; j < m.cols; ++j)
    for (std::int64_t i = m.start[j]; i < m.start[j + 1]; ++i)
      dense(m.index[i], static_cast<Eigen::Index>(j)) = m.value[i];
  return dense;
}

// Minimum-norm solution z of M z = r (M: rows <= cols typically).
Eigen::VectorXd min_norm_solve(Csc& m, const Eigen::VectorXd& r, LinearAlgebra algebra) {
  if (algebra == LinearAlgebra::kDense)
    return to_dense(m).completeOrthogonalDecomposition().solve(r);
  Cholmod cholmod;
  cholmod_common* common = cholmod.get();
  cholmod_sparse a = m.view();
  DensePtr b(cholmod_l_allocate_dense(m.rows, 1, m.rows, CHOLMOD_REAL, common),
             DenseDeleter{common});
  std::copy(r.data(), r.data() + r.size(), static_cast<double*>(b->x));
  DensePtr z(
      SuiteSparseQR_min2norm<double>(SPQR_ORDERING_DEFAULT, SPQR_DEFAULT_TOL, &a, b.get(), common),
      DenseDeleter{common});
  if (!z) throw PlanError("internal: SPQR failed (status " + std::to_string(common->status) + ")");
  const double* x = static_cast<const double*>(z->x);
  return Eigen::Map<const Eigen::VectorXd>(x, static_cast<Eigen::Index>(m.cols));
}

// Preconditions with one expression over one variable list (the two sides of a clearance) have
// one compiled problem, one row of J, one bound over a box: this key names them.
using ProblemKey = std::pair<std::uint32_t, std::vector<VariableId>>;
ProblemKey problem_key(const PreconditionResult& result) {
  return {result.inequality.expression.id(), result.variables};
}

std::string format(const char* pattern, double a, double b = 0, double c = 0, double d = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, pattern, a, b, c, d);
  return buffer;
}

// Monte Carlo: points drawn from the variables' distributions (fixed seed, point-major: the same
// points whatever is evaluated on them), in blocks. Unproved preconditions are evaluated on all
// `options.samples` points, on one tape; proved ones, a self-check, on the first `proved_samples`
// only (a second tape with every precondition). Only those points are drawn when all are proved.
struct SampledViolations {
  std::size_t points{0};  // drawn
  std::vector<std::size_t> per_precondition;
  std::vector<std::size_t> samples;  // per precondition: the points it was evaluated on
  std::size_t plan{0};               // points violating at least one precondition
};

// The sampling in two parts: the constructor compiles the tapes (it reads the analysis' pool),
// run() draws and evaluates (it reads the tapes, the variables and the results' relations and
// verdicts only, so it may run on another thread).
class MonteCarlo {
 public:
  MonteCarlo(const InstanceAnalysis& analysis, std::vector<const PreconditionResult*> results,
             const ProbabilityOptions& options)
      : variables_(&analysis.variables),
        results_(std::move(results)),
        options_(options),
        proved_samples_(std::max<std::size_t>(
            1, options.samples / std::max<std::size_t>(1, options.proved_share))),
        unproved_(unproved_rows(results_)),
        all_(tape_of(analysis, results_, every_row(results_.size()))),
        some_(unproved_.empty() ? std::nullopt
                                : std::optional(tape_of(analysis, results_, unproved_))) {}

  [[nodiscard]] SampledViolations run() const {
    const std::size_t inputs = variables_->size(), every = results_.size();
    SampledViolations sampled{.points = unproved_.empty()
                                            ? std::min(options_.samples, proved_samples_)
                                            : options_.samples,
                              .per_precondition = std::vector<std::size_t>(every, 0),
                              .samples = std::vector<std::size_t>(every, 0)};
    std::vector<Sampler> samplers;
    for (const SpaceVariable& v : *variables_) samplers.emplace_back(v);
    std::mt19937_64 random(options_.seed);
    constexpr std::size_t kBlock = 256;
    std::vector<double> points(inputs * kBlock), values(every * kBlock);
    for (std::size_t done = 0; done < sampled.points; done += kBlock) {
      check_deadline();  // a batch's --time-limit (common/deadline.hpp); cheap without one
      const std::size_t n = std::min(kBlock, sampled.points - done);
      for (std::size_t p = 0; p < n; ++p)  // point-major draws: independent of the block size
        for (std::size_t j = 0; j < inputs; ++j) points[j * n + p] = samplers[j](random);
      // Every precondition while the proved ones are checked, then the unproved ones alone.
      const bool checking = done < proved_samples_;
      const symbolic::Tape& tape = checking ? all_ : *some_;
      const std::size_t outputs = checking ? every : unproved_.size();
      symbolic::evaluate_batch(tape, {points.data(), inputs * n}, {values.data(), outputs * n}, n);
      for (std::size_t p = 0; p < n; ++p) {
        bool any = false;
        for (std::size_t row = 0; row < outputs; ++row) {
          const std::size_t k = checking ? row : unproved_[row];
          const bool proved = results_[k]->verdict == bounds::Verdict::kSatisfied;
          if (proved && done + p >= proved_samples_) continue;
          if (violated(results_[k]->inequality, values[row * n + p])) {
            ++sampled.per_precondition[k];
            any = true;
          }
        }
        sampled.plan += any;
      }
    }
    for (std::size_t k = 0; k < every; ++k)
      sampled.samples[k] = results_[k]->verdict == bounds::Verdict::kSatisfied
                               ? std::min(sampled.points, proved_samples_)
                               : sampled.points;
    return sampled;
  }

 private:
  static std::vector<std::size_t> unproved_rows(
      const std::vector<const PreconditionResult*>& results) {
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < results.size(); ++k)
      if (results[k]->verdict != bounds::Verdict::kSatisfied) rows.push_back(k);
    return rows;
  }
  static std::vector<std::size_t> every_row(std::size_t rows) {
    std::vector<std::size_t> all(rows);
    std::iota(all.begin(), all.end(), std::size_t{0});
    return all;
  }
  // One tape of the rows' expressions, over every variable of the analysis.
  static symbolic::Tape tape_of(const InstanceAnalysis& analysis,
                                const std::vector<const PreconditionResult*>& results,
                                std::span<const std::size_t> rows) {
    std::vector<Expr> outputs;
    for (const std::size_t k : rows) outputs.push_back(results[k]->inequality.expression);
    return symbolic::Tape::compile(outputs, analysis.symbols);
  }

  const std::vector<SpaceVariable>* variables_;  // the analysis': inputs in this order
  std::vector<const PreconditionResult*> results_;
  ProbabilityOptions options_;
  std::size_t proved_samples_;          // points the proved preconditions are checked on
  std::vector<std::size_t> unproved_;   // indices into results_
  symbolic::Tape all_;                  // every precondition
  std::optional<symbolic::Tape> some_;  // the unproved ones
};

// Sets p's Monte Carlo estimate and its Wilson interval, and notes where the first-order estimate
// disagrees with it (or, for a proved precondition, any sampled violation: a soundness bug).
void compare_with_samples(PreconditionProbability& p, std::size_t samples, std::size_t violations) {
  p.samples = samples;
  p.violations = violations;
  p.p_monte_carlo = static_cast<double>(p.violations) / p.samples;
  if (p.proved) {
    if (p.violations == 0) return;  // exactly 0 from both: the sound bound holds on the support
    p.note = "SOUNDNESS: " + std::to_string(p.violations) +
             " sampled violations of a precondition proved satisfied";
  }
  std::tie(p.ci_lo, p.ci_hi) = wilson(p.violations, p.samples);
  p.agrees = p.p_first_order >= p.ci_lo && p.p_first_order <= p.ci_hi;
  if (p.agrees || !p.note.empty()) return;
  const bool second_agrees = p.p_second_order >= p.ci_lo && p.p_second_order <= p.ci_hi;
  p.note = format("first order %.3g lies outside the Monte Carlo 95%% interval [%.3g, %.3g]; ",
                  p.p_first_order, p.ci_lo, p.ci_hi) +
           format("second order (mean shifted by 1/2 tr(H Sigma)) gives %.3g", p.p_second_order) +
           (second_agrees ? ", inside it"
                          : ", also outside: f is not near-linear over the box (or its "
                            "distribution is far from Gaussian)");
}

}  // namespace

VariableMoments variable_moments(const SpaceVariable& v) {
  const double lo = v.lower, hi = v.upper;
  if (!(hi > lo)) return {lo, 0.0};
  if (!(v.sigma > 0)) return {(lo + hi) / 2, (hi - lo) * (hi - lo) / 12};
  const double s = v.sigma, a = lo / s, b = hi / s, z = normal_mass(a, b);
  if (!(z > 0)) return {(lo + hi) / 2, (hi - lo) * (hi - lo) / 12};  // box far in a tail
  const double pa = normal_pdf(a), pb = normal_pdf(b);
  const double shift = (pa - pb) / z;
  // a·φ(a) with a = ±inf is 0 (φ decays faster); the box is finite here, so no special case.
  return {s * shift, s * s * (1 + (a * pa - b * pb) / z - shift * shift)};
}

double Sensitivities::density() const {
  return rows == 0 || cols == 0 ? 0.0 : static_cast<double>(nonzeros()) / (rows * cols);
}

Sensitivities sensitivities(const InstanceAnalysis& analysis) {
  Sensitivities out;
  out.cols = analysis.variables.size();
  std::vector<Triplet> triplets;
  // [f, ∂f/∂x_1 .. ∂f/∂x_n, ∂²f/∂x_1² .. ∂²f/∂x_n²] at 0, once per problem_key.
  std::map<ProblemKey, std::vector<double>> at_zero;
  for (std::size_t s = 0; s < analysis.steps.size(); ++s)
    for (std::size_t p = 0; p < analysis.steps[s].preconditions.size(); ++p) {
      const PreconditionResult& result = analysis.steps[s].preconditions[p];
      const std::size_t row = out.rows++;
      out.row_step.push_back(s);
      out.row_precondition.push_back(p);
      const std::vector<Expr> inputs = internal::variable_symbols(analysis, result);
      const Expr f = result.inequality.expression;
      auto [known, fresh] = at_zero.try_emplace(problem_key(result));
      std::vector<double>& values = known->second;
      if (fresh) {  // one tape, evaluated at 0
        std::vector<Expr> outputs{f};
        const std::vector<std::vector<Expr>> gradient = symbolic::jacobian({&f, 1}, inputs);
        for (const Expr& g : gradient[0]) outputs.push_back(g);
        for (std::size_t j = 0; j < inputs.size(); ++j)
          outputs.push_back(symbolic::differentiate(gradient[0][j], inputs[j]));
        const symbolic::Tape tape = symbolic::Tape::compile(outputs, inputs);
        symbolic::TapeEvaluator<double> evaluator(tape);
        const std::vector<double> zero(inputs.size(), 0.0);
        values.resize(outputs.size());
        evaluator.evaluate(zero, values);
      }
      out.nominal.push_back(values[0]);
      double trace = 0;
      for (std::size_t j = 0; j < inputs.size(); ++j) {
        const double first = values[1 + j], second = values[1 + inputs.size() + j];
        const std::size_t column = result.variables[j].index;
        const SpaceVariable& variable = analysis.variables[column];
        if (!std::isfinite(first)) {
          ++out.non_differentiable;
          continue;
        }
        if (first != 0) triplets.push_back({row, column, first});
        const VariableMoments moments = variable_moments(variable);
        if (std::isfinite(second))
          trace += 0.5 * second * (moments.variance + moments.mean * moments.mean);
      }
      out.hessian_trace.push_back(trace);
    }
  Csc csc = to_csc(out.rows, out.cols, std::move(triplets));
  out.column_start = std::move(csc.start);
  out.row_index = std::move(csc.index);
  out.value = std::move(csc.value);
  return out;
}

PreconditionCovariance precondition_covariance(const Sensitivities& jacobian,
                                               std::span<const SpaceVariable> variables,
                                               LinearAlgebra algebra) {
  if (variables.size() != jacobian.cols)
    throw PlanError("internal: precondition_covariance needs one variable per column of J");
  // B = J Σ^(1/2); J Σ J^T = B B^T.
  Csc b{.rows = jacobian.rows,
        .cols = jacobian.cols,
        .start = jacobian.column_start,
        .index = jacobian.row_index,
        .value = jacobian.value};
  for (std::size_t j = 0; j < b.cols; ++j) {
    const double scale = std::sqrt(variable_moments(variables[j]).variance);
    for (std::int64_t i = b.start[j]; i < b.start[j + 1]; ++i) b.value[i] *= scale;
  }
  PreconditionCovariance out;
  out.variance.assign(jacobian.rows, 0.0);
  if (algebra == LinearAlgebra::kDense) {
    const Eigen::MatrixXd dense = to_dense(b);
    const Eigen::MatrixXd c = dense * dense.transpose();
    for (std::size_t k = 0; k < jacobian.rows; ++k) out.variance[k] = c(k, k);
    out.nonzeros = static_cast<std::size_t>((c.array() != 0).count());
    return out;
  }
  if (jacobian.rows == 0) return out;
  Cholmod cholmod;
  cholmod_common* common = cholmod.get();
  cholmod_sparse view = b.view();
  const SparsePtr c(cholmod_l_aat(&view, nullptr, 0, 1, common), SparseDeleter{common});
  if (!c)
    throw PlanError("internal: CHOLMOD aat failed (status " + std::to_string(common->status) + ")");
  const auto* start = static_cast<const SuiteSparse_long*>(c->p);
  const auto* index = static_cast<const SuiteSparse_long*>(c->i);
  const auto* value = static_cast<const double*>(c->x);
  for (std::size_t k = 0; k < jacobian.rows; ++k)
    for (SuiteSparse_long i = start[k]; i < start[k + 1]; ++i)
      if (static_cast<std::size_t>(index[i]) == k) out.variance[k] = value[i];
  out.nonzeros = static_cast<std::size_t>(cholmod_l_nnz(c.get(), common));
  return out;
}

ProbabilityAnalysis analyse_probability(const InstanceAnalysis& analysis,
                                        const ProbabilityOptions& options) {
  return analyse_probability(analysis, sensitivities(analysis), options);
}

namespace {

// Row k of J's precondition (Sensitivities: execution order).
std::vector<const PreconditionResult*> rows_of(const InstanceAnalysis& analysis,
                                               const Sensitivities& jacobian) {
  std::vector<const PreconditionResult*> results;
  for (std::size_t k = 0; k < jacobian.rows; ++k)
    results.push_back(
        &analysis.steps[jacobian.row_step[k]].preconditions[jacobian.row_precondition[k]]);
  return results;
}

// The analysis up to its Monte Carlo: moments and the first-order probabilities (truncated to
// PreconditionResult::bound).
ProbabilityAnalysis first_order(const InstanceAnalysis& analysis, const Sensitivities& jacobian,
                                const ProbabilityOptions& options) {
  const PreconditionCovariance covariance =
      precondition_covariance(jacobian, analysis.variables, options.algebra);
  ProbabilityAnalysis out{.rows = jacobian.rows,
                          .cols = jacobian.cols,
                          .nonzeros = jacobian.nonzeros(),
                          .density = jacobian.density(),
                          .covariance_nonzeros = covariance.nonzeros,
                          .non_differentiable = jacobian.non_differentiable,
                          .preconditions = {}};
  // m1 = f(0) + J μ.
  std::vector<double> mean = jacobian.nominal;
  for (std::size_t j = 0; j < jacobian.cols; ++j) {
    const double mu = variable_moments(analysis.variables[j]).mean;
    if (mu != 0)
      for (std::int64_t i = jacobian.column_start[j]; i < jacobian.column_start[j + 1]; ++i)
        mean[jacobian.row_index[i]] += jacobian.value[i] * mu;
  }
  const std::vector<const PreconditionResult*> results = rows_of(analysis, jacobian);
  for (std::size_t k = 0; k < jacobian.rows; ++k) {
    const PreconditionResult& result = *results[k];
    PreconditionProbability p{.step = jacobian.row_step[k],
                              .precondition = jacobian.row_precondition[k],
                              .nominal = jacobian.nominal[k],
                              .mean = mean[k],
                              .second_order_mean = mean[k] + jacobian.hessian_trace[k],
                              .sigma = std::sqrt(std::max(0.0, covariance.variance[k])),
                              .note = {}};
    p.proved = result.verdict == bounds::Verdict::kSatisfied;
    p.p_first_order =
        truncated_violation(result.inequality, p.mean, p.sigma, result.bound.lo, result.bound.hi);
    p.p_second_order = truncated_violation(result.inequality, p.second_order_mean, p.sigma,
                                           result.bound.lo, result.bound.hi);
    out.preconditions.push_back(p);
  }
  return out;
}

bool samples_wanted(const Sensitivities& jacobian, const ProbabilityOptions& options) {
  return options.samples > 0 && jacobian.rows > 0;
}

void add_samples(ProbabilityAnalysis& out, const SampledViolations& sampled) {
  out.samples = sampled.points;
  out.plan_violations = sampled.plan;
  out.p_plan = static_cast<double>(sampled.plan) / sampled.points;
  std::tie(out.p_plan_ci_lo, out.p_plan_ci_hi) = wilson(sampled.plan, sampled.points);
  for (std::size_t k = 0; k < out.preconditions.size(); ++k)
    compare_with_samples(out.preconditions[k], sampled.samples[k], sampled.per_precondition[k]);
}

}  // namespace

ProbabilityAnalysis analyse_probability(const InstanceAnalysis& analysis,
                                        const Sensitivities& jacobian,
                                        const ProbabilityOptions& options) {
  ProbabilityAnalysis out = first_order(analysis, jacobian, options);
  if (samples_wanted(jacobian, options))
    add_samples(out, MonteCarlo(analysis, rows_of(analysis, jacobian), options).run());
  return out;
}

namespace {

// The information form of pose readings: Λ (upper triangle stored, one 4x4 block per object) and
// η, over the objects' blocks in ascending object order.
struct InformationForm {
  Csc lambda;
  Eigen::VectorXd eta;
};

// Λ and η of `readings`, whose objects' blocks are `out`'s (block_of: object -> index), each
// object's box in `out` the intersection of its readings' boxes. Throws PlanError for a
// covariance that is not symmetric positive definite or a negative half-width.
InformationForm information_form(std::span<const PoseReading> readings,
                                 const std::map<int, std::size_t>& block_of,
                                 std::vector<FusedPose>& out) {
  const std::size_t n = 4 * out.size();
  std::vector<Triplet> information;
  Eigen::VectorXd eta = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  for (const PoseReading& r : readings) {
    if (!((r.covariance - r.covariance.transpose()).cwiseAbs().maxCoeff() <=
          1e-12 * r.covariance.cwiseAbs().maxCoeff()))
      throw PlanError("fuse_readings: the covariance of a reading of object " +
                      std::to_string(r.object) + " is not symmetric");
    const Eigen::LLT<Eigen::Matrix4d> llt(r.covariance);
    if (llt.info() != Eigen::Success)
      throw PlanError("fuse_readings: the covariance of a reading of object " +
                      std::to_string(r.object) + " is not positive definite");
    if (!(r.half_width.array() >= 0).all())
      throw PlanError("fuse_readings: a negative half-width for object " +
                      std::to_string(r.object));
    const Eigen::Matrix4d inverse = llt.solve(Eigen::Matrix4d::Identity());
    FusedPose& fused = out[block_of.at(r.object)];
    const std::size_t base = 4 * block_of.at(r.object);
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) information.push_back({base + i, base + j, inverse(i, j)});
    eta.segment<4>(static_cast<Eigen::Index>(base)) += inverse * r.estimate;
    const Eigen::Vector4d lower = r.estimate - r.half_width, upper = r.estimate + r.half_width;
    fused.lower = fused.readings == 0 ? lower : Eigen::Vector4d(fused.lower.cwiseMax(lower));
    fused.upper = fused.readings == 0 ? upper : Eigen::Vector4d(fused.upper.cwiseMin(upper));
    ++fused.readings;
  }
  return {to_csc(n, n, std::move(information)), std::move(eta)};
}

// Λ^-1 η and the diagonal 4x4 blocks of Λ^-1 (Λ^-1 is block diagonal like Λ).
struct BlockSolution {
  Eigen::VectorXd mean;
  std::vector<Eigen::Matrix4d> covariances;  // per block
};

BlockSolution solve_dense(const InformationForm& form) {
  const auto n = static_cast<std::size_t>(form.eta.size());
  const Eigen::MatrixXd dense = to_dense(form.lambda).selfadjointView<Eigen::Upper>();
  const Eigen::LLT<Eigen::MatrixXd> llt(dense);
  const Eigen::MatrixXd inverse = llt.solve(Eigen::MatrixXd::Identity(n, n));
  BlockSolution out{llt.solve(form.eta), {}};
  for (std::size_t b = 0; 4 * b < n; ++b)
    out.covariances.push_back(inverse.block<4, 4>(4 * b, 4 * b));
  return out;
}

// With CHOLMOD: one factorisation; Λ^-1's blocks from a solve against the sparse identity.
// (Non-const: CHOLMOD's view of a matrix is not.)
BlockSolution solve_sparse(InformationForm& form) {
  const auto n = static_cast<std::size_t>(form.eta.size());
  Cholmod cholmod;
  cholmod_common* common = cholmod.get();
  cholmod_sparse a = form.lambda.view();
  a.stype = 1;  // symmetric, upper triangle stored
  const std::unique_ptr<cholmod_factor, FactorDeleter> factor(cholmod_l_analyze(&a, common),
                                                              FactorDeleter{common});
  if (!factor || !cholmod_l_factorize(&a, factor.get(), common) || common->status != CHOLMOD_OK)
    throw PlanError("internal: CHOLMOD could not factor the information matrix (status " +
                    std::to_string(common->status) + ")");
  DensePtr rhs(cholmod_l_allocate_dense(n, 1, n, CHOLMOD_REAL, common), DenseDeleter{common});
  std::copy(form.eta.data(), form.eta.data() + n, static_cast<double*>(rhs->x));
  const DensePtr solution(cholmod_l_solve(CHOLMOD_A, factor.get(), rhs.get(), common),
                          DenseDeleter{common});
  BlockSolution out{Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(solution->x),
                                                      static_cast<Eigen::Index>(n)),
                    {}};
  const SparsePtr identity(cholmod_l_speye(n, n, CHOLMOD_REAL, common), SparseDeleter{common});
  const SparsePtr inverse(cholmod_l_spsolve(CHOLMOD_A, factor.get(), identity.get(), common),
                          SparseDeleter{common});
  const auto* start = static_cast<const SuiteSparse_long*>(inverse->p);
  const auto* index = static_cast<const SuiteSparse_long*>(inverse->i);
  const auto* value = static_cast<const double*>(inverse->x);
  for (std::size_t b = 0; 4 * b < n; ++b) {
    Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
    for (std::size_t j = 4 * b; j < 4 * b + 4; ++j)
      for (SuiteSparse_long i = start[j]; i < start[j + 1]; ++i)
        if (static_cast<std::size_t>(index[i]) / 4 == b)
          covariance(index[i] - 4 * b, j - 4 * b) = value[i];
    out.covariances.push_back(covariance);
  }
  return out;
}

}  // namespace

std::vector<FusedPose> fuse_readings(std::span<const PoseReading> readings, LinearAlgebra algebra) {
  std::map<int, std::size_t> block_of;  // object -> block index (ascending objects)
  for (const PoseReading& r : readings) block_of.emplace(r.object, 0);
  std::vector<FusedPose> out;
  for (auto& [object, index] : block_of) {
    index = out.size();
    out.push_back({.object = object});
  }
  InformationForm form = information_form(readings, block_of, out);
  if (out.empty()) return out;
  const BlockSolution solved =
      algebra == LinearAlgebra::kDense ? solve_dense(form) : solve_sparse(form);
  for (std::size_t b = 0; b < out.size(); ++b) {
    out[b].covariance = solved.covariances[b];
    out[b].mean = solved.mean.segment<4>(static_cast<Eigen::Index>(4 * b));
    out[b].consistent = (out[b].lower.array() <= out[b].upper.array()).all();
  }
  return out;
}

const char* to_string(AllocationStatus status) {
  switch (status) {
    case AllocationStatus::kNotNeeded:
      return "not_needed";
    case AllocationStatus::kProved:
      return "proved";
    case AllocationStatus::kNotProved:
      return "not_proved";
    case AllocationStatus::kInfeasible:
      return "infeasible";
  }
  return "?";
}

namespace {

constexpr double kinematics::PoseUncertainty::*kComponentMember[] = {
    &kinematics::PoseUncertainty::dx, &kinematics::PoseUncertainty::dy,
    &kinematics::PoseUncertainty::dz, &kinematics::PoseUncertainty::dtheta};

// The scenario block a variable's half-width comes from (its half-widths, model and name), or
// nullopt when the scenario has none (no range-scan sensor). S is Scenario or const Scenario.
template <class S>
auto block_of(S& scenario, UncertaintySource source, int object) {
  constexpr bool kConst = std::is_const_v<S>;
  struct Block {
    std::conditional_t<kConst, const kinematics::PoseUncertainty, kinematics::PoseUncertainty>*
        widths;
    std::conditional_t<kConst, const UncertaintyModel, UncertaintyModel>* model;
    std::string name;
  };
  std::optional<Block> block;
  switch (source) {
    case UncertaintySource::kInitial:
      if (object >= 0 && object < static_cast<int>(scenario.objects.size()))
        block = Block{&scenario.objects[object].uncertainty,
                      &scenario.objects[object].uncertainty_model, scenario.objects[object].name};
      break;
    case UncertaintySource::kManipulator:
      block = Block{&scenario.robot.uncertainty, &scenario.robot.uncertainty_model, "robot"};
      break;
    case UncertaintySource::kJoint:  // per joint, no block of four: not allocated
      break;
    case UncertaintySource::kSensor:
      if (scenario.range_scan)
        block = Block{&scenario.range_scan->residual, &scenario.range_scan->residual_model,
                      "range_scan"};
      break;
  }
  return block;
}

}  // namespace

Scenario ToleranceAllocation::apply(Scenario scenario) const {
  for (const ToleranceParameter& p : parameters) {
    const auto block = block_of(scenario, p.source, p.object);
    if (!block) throw PlanError("tolerance allocation: " + p.name + " is not in the scenario");
    const int c = index_of(p.component);
    double& width = block->widths->*kComponentMember[c];
    double& sigma = block->model->sigma.*kComponentMember[c];
    if (width > 0) sigma *= p.allocated / width;
    width = p.allocated;
  }
  return scenario;
}

ToleranceAllocation allocate_tolerances(const Scenario& scenario, const InstanceAnalysis& analysis,
                                        const AllocationOptions& options) {
  return allocate_tolerances(scenario, analysis, sensitivities(analysis), options);
}

namespace {

// The allocation's parameters (one per block and component with a positive half-width that some
// variable uses), which parameter each variable scales (-1: none), and each variable's reach
// max |x_j| over its range.
struct AllocationParameters {
  std::vector<ToleranceParameter> list;
  std::vector<int> of_variable;
  std::vector<double> reach;
};

AllocationParameters allocation_parameters(const Scenario& scenario,
                                           const InstanceAnalysis& analysis) {
  AllocationParameters out;
  std::map<std::tuple<int, int, int>, std::size_t> parameter_of;
  out.of_variable.assign(analysis.variables.size(), -1);
  out.reach.assign(analysis.variables.size(), 0.0);
  for (std::size_t j = 0; j < analysis.variables.size(); ++j) {
    const SpaceVariable& v = analysis.variables[j];
    out.reach[j] = std::max(std::abs(v.lower), std::abs(v.upper));
    const Provenance& from = v.provenance;
    const int object = from.source == UncertaintySource::kInitial ? from.object : -1;
    if (from.camera >= 0) continue;  // a camera's residual is not allocated (docs/scenario.md)
    const auto block = block_of(scenario, from.source, object);
    const int c = index_of(v.component);
    if (!block || !(block->widths->*kComponentMember[c] > 0)) continue;
    const auto key = std::make_tuple(static_cast<int>(from.source), object, c);
    auto [it, fresh] = parameter_of.emplace(key, out.list.size());
    if (fresh) {
      const double width = block->widths->*kComponentMember[c];
      out.list.push_back({.source = from.source,
                          .object = object,
                          .component = v.component,
                          .name = block->name + "." + std::string(to_string(v.component)),
                          .half_width = width,
                          .cost = block->model->cost.*kComponentMember[c],
                          .allocated = width});
    }
    out.of_variable[j] = static_cast<int>(it->second);
  }
  return out;
}

// The first-order model of every precondition (a row k per row of J): A p <= room - ε, with
// A_kp = Σ_{j in p} |J_kj| reach_j / p0_p and room_k what the nominal value leaves (minus what
// the variables of no parameter take); ε a positive margin relative to the row's spread, raised
// by verification.
struct AllocationRows {
  Eigen::SparseMatrix<double, Eigen::RowMajor> a;  // row k's parameters: those f_k depends on
  std::vector<double> room, epsilon;
  std::vector<const PreconditionResult*> results;
  Eigen::VectorXd spread0;  // A p0

  // The rows the parameters `p` break.
  [[nodiscard]] std::vector<std::size_t> violated(const Eigen::VectorXd& p) const {
    const Eigen::VectorXd spread = a * p;
    std::vector<std::size_t> out;
    for (std::size_t k = 0; k < room.size(); ++k)
      if (spread[static_cast<Eigen::Index>(k)] > room[k] - epsilon[k]) out.push_back(k);
    return out;
  }
};

AllocationRows allocation_rows(const InstanceAnalysis& analysis, const Sensitivities& jacobian,
                               const AllocationParameters& parameters, const Eigen::VectorXd& p0) {
  if (jacobian.cols != analysis.variables.size())
    throw PlanError("internal: allocate_tolerances needs J of this instance");
  const std::size_t rows = jacobian.rows;
  AllocationRows out;
  out.room.resize(rows);
  out.results = rows_of(analysis, jacobian);
  for (std::size_t k = 0; k < rows; ++k) {
    const bounds::Inequality& q = out.results[k]->inequality;
    out.room[k] = upper_limit(q.relation) ? q.threshold - jacobian.nominal[k]
                                          : jacobian.nominal[k] - q.threshold;
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t j = 0; j < jacobian.cols; ++j)
    for (std::int64_t i = jacobian.column_start[j]; i < jacobian.column_start[j + 1]; ++i) {
      const double spread = std::abs(jacobian.value[i]) * parameters.reach[j];
      const int q = parameters.of_variable[j];
      if (q < 0)
        out.room[jacobian.row_index[i]] -= spread;
      else
        entries.emplace_back(jacobian.row_index[i], q,
                             spread / parameters.list[static_cast<std::size_t>(q)].half_width);
    }
  // Duplicates summed.
  out.a.resize(static_cast<Eigen::Index>(rows), p0.size());
  out.a.setFromTriplets(entries.begin(), entries.end());
  out.spread0 = out.a * p0;
  out.epsilon.resize(rows);
  for (std::size_t k = 0; k < rows; ++k)
    out.epsilon[k] = 1e-9 * (1 + std::abs(out.results[k]->inequality.threshold)) +
                     1e-6 * out.spread0[static_cast<Eigen::Index>(k)];
  return out;
}

// One first-order allocation: active-set least squares (the violated rows as equalities,
// min Σ c (δ/p0)^2, clamped to [0, p0]), then, if the clamps left a row violated, a uniform
// shrink (p = 0 satisfies every row, as the caller checked).
Eigen::VectorXd first_order_allocation(const AllocationRows& rows, const Eigen::VectorXd& p0,
                                       const Eigen::VectorXd& cost, LinearAlgebra algebra) {
  const auto np = static_cast<std::size_t>(p0.size());
  Eigen::VectorXd p = p0;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const std::vector<std::size_t> active = rows.violated(p);
    if (active.empty()) break;
    const Eigen::VectorXd spread = rows.a * p;
    std::vector<Triplet> m;
    Eigen::VectorXd r(static_cast<Eigen::Index>(active.size()));
    for (std::size_t i = 0; i < active.size(); ++i) {
      const std::size_t k = active[i];
      r[static_cast<Eigen::Index>(i)] =
          spread[static_cast<Eigen::Index>(k)] - (rows.room[k] - rows.epsilon[k]);
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(
               rows.a, static_cast<Eigen::Index>(k));
           it; ++it) {
        const auto q = static_cast<std::size_t>(it.col());
        if (p[it.col()] > 0 && it.value() != 0)
          m.push_back({i, q, it.value() * p0[it.col()] / std::sqrt(cost[it.col()])});
      }
    }
    Csc matrix = to_csc(active.size(), np, std::move(m));
    const Eigen::VectorXd z = min_norm_solve(matrix, r, algebra);
    for (Eigen::Index q = 0; q < p0.size(); ++q)
      p[q] = std::clamp(p[q] - p0[q] * z[q] / std::sqrt(cost[q]), 0.0, p0[q]);
  }
  if (!rows.violated(p).empty())
    p *= internal::largest_holding(0.0, 1.0, 60,
                                   [&](double scale) { return rows.violated(scale * p).empty(); });
  return p;
}

// The rows' compiled problems, compiled once for every round: one per row, over its own copy of
// the expression (internal/own_copy.hpp), so that rows are verified on several threads.
struct VerifyProblems {
  std::vector<internal::OwnCopy> copies;       // per row
  std::vector<bounds::BoundProblem> problems;  // per row, over copies[k]
  std::vector<std::size_t> first_row;          // the first row with row k's problem_key

  VerifyProblems(const InstanceAnalysis& analysis, const AllocationRows& rows) {
    std::map<ProblemKey, std::size_t> first_with;
    for (std::size_t k = 0; k < rows.results.size(); ++k) {
      const PreconditionResult& result = *rows.results[k];
      first_row.push_back(first_with.try_emplace(problem_key(result), k).first->second);
      copies.push_back(internal::own_copy(analysis, result));
      problems.emplace_back(copies.back().f, copies.back().inputs);
    }
  }
};

// Checks the allocation `p` with the sound bounds over the scaled box: the rows not proved, and
// their epsilon raised by how far their bound lies past the threshold (for the next round).
// Every row is decided first (one side, early exit; most rows hold); a row that is not proved
// gets the tight bound, which may still prove it or says how far past the threshold it lies, one
// per problem and box (a bound depends on the expression and the box only). Both passes run their
// rows on `threads` threads.
std::vector<ToleranceAllocation::Miss> verify_allocation(
    const Sensitivities& jacobian, const AllocationParameters& parameters,
    const Eigen::VectorXd& p0, const Eigen::VectorXd& p, VerifyProblems& verifying,
    const bounds::BoundOptions& options, unsigned threads, AllocationRows& rows) {
  const std::size_t n = rows.results.size();
  std::vector<std::vector<bounds::Interval>> boxes(n);
  for (std::size_t k = 0; k < n; ++k) {
    const PreconditionResult& result = *rows.results[k];
    boxes[k] = result.box;
    for (std::size_t v = 0; v < boxes[k].size(); ++v) {
      const int q = parameters.of_variable[result.variables[v].index];
      if (q >= 0)
        boxes[k][v] =
            bounds::Interval(boxes[k][v].lo * p[q] / p0[q], boxes[k][v].hi * p[q] / p0[q]);
    }
  }
  // A row phase 2 proved over a box holding its new one stays proved: that bound encloses f over
  // the new box too. Only the others are decided again.
  std::vector<char> proved(n, 0);
  std::vector<std::size_t> deciding_rows;
  for (std::size_t k = 0; k < n; ++k) {
    const PreconditionResult& result = *rows.results[k];
    proved[k] = result.verdict == bounds::Verdict::kSatisfied &&
                std::ranges::equal(boxes[k], result.box, [](const auto& inner, const auto& outer) {
                  return outer.lo <= inner.lo && inner.hi <= outer.hi;
                });
    if (!proved[k]) deciding_rows.push_back(k);
  }
  run_tasks(deciding_rows.size(), threads, [&](std::size_t i) {
    const std::size_t k = deciding_rows[i];
    const bounds::Inequality& inequality = rows.results[k]->inequality;
    bounds::BoundOptions deciding = options;
    deciding.decide = bounds::DecisionTarget{inequality.relation, inequality.threshold};
    deciding.stop_at_witness = true;  // only the verdict: a row not proved gets the tight bound
    proved[k] = bounds::decide(inequality, verifying.problems[k].bound(boxes[k], deciding)) ==
                bounds::Verdict::kSatisfied;
  });
  // The rows not proved, each with the row whose tight bound it takes (the first with its
  // problem and box).
  const auto same = [](const bounds::Interval& a, const bounds::Interval& b) {
    return a.lo == b.lo && a.hi == b.hi;
  };
  std::vector<std::size_t> tight_of(n, n), computing;
  for (std::size_t k = 0; k < n; ++k) {
    if (proved[k]) continue;
    for (const std::size_t j : computing)
      if (verifying.first_row[j] == verifying.first_row[k] &&
          std::ranges::equal(boxes[j], boxes[k], same)) {
        tight_of[k] = j;
        break;
      }
    if (tight_of[k] == n) {
      tight_of[k] = k;
      computing.push_back(k);
    }
  }
  std::vector<bounds::BoundResult> tight(n);
  run_tasks(computing.size(), threads, [&](std::size_t i) {
    const std::size_t k = computing[i];
    tight[k] = verifying.problems[k].bound(boxes[k], options);
  });
  std::vector<ToleranceAllocation::Miss> misses;
  for (std::size_t k = 0; k < n; ++k) {
    if (proved[k]) continue;
    const PreconditionResult& result = *rows.results[k];
    const bounds::BoundResult& bound = tight[tight_of[k]];
    if (bounds::decide(result.inequality, bound) == bounds::Verdict::kSatisfied) continue;
    const double t = result.inequality.threshold;
    const double by = upper_limit(result.inequality.relation) ? bound.hi - t : t - bound.lo;
    misses.push_back({jacobian.row_step[k], jacobian.row_precondition[k], std::max(0.0, by)});
    rows.epsilon[k] += 1.5 * std::max(by, 0.0) + 1e-6 * rows.spread0[static_cast<Eigen::Index>(k)];
  }
  return misses;
}

// allocate_tolerances in two parts: the constructor does what reads the analysis' pool (the
// verification's own copies of the rows, when a verified allocation is to be made), run() the
// rounds, which read those copies and the analysis' results only, so it may run on any thread.
class Allocator {
 public:
  Allocator(const Scenario& scenario, const InstanceAnalysis& analysis,
            const Sensitivities& jacobian, const AllocationOptions& options)
      : jacobian_(&jacobian),
        options_(options),
        parameters_(allocation_parameters(scenario, analysis)) {
    const auto np = static_cast<Eigen::Index>(parameters_.list.size());
    p0_.resize(np);
    cost_.resize(np);
    for (Eigen::Index q = 0; q < np; ++q) {
      p0_[q] = parameters_.list[static_cast<std::size_t>(q)].half_width;
      cost_[q] = parameters_.list[static_cast<std::size_t>(q)].cost;
    }
    rows_ = allocation_rows(analysis, jacobian, parameters_, p0_);
    // Nothing to do when phase 2 proved every precondition over this very box already (even
    // where the first-order margin, which ignores curvature, is not positive).
    needed_ = !std::all_of(
        rows_.results.begin(), rows_.results.end(),
        [](const PreconditionResult* r) { return r->verdict == bounds::Verdict::kSatisfied; });
    // Compiled once, for every round; not when the first round ends before verifying.
    if (needed_ && options.verify && infeasible_rows().empty()) verifying_.emplace(analysis, rows_);
  }

  [[nodiscard]] ToleranceAllocation run() {
    ToleranceAllocation out;
    out.parameters = parameters_.list;
    if (!needed_) return out;  // kNotNeeded, rounds 0: every parameter keeps its half-width
    const Sensitivities& jacobian = *jacobian_;
    Eigen::VectorXd p = p0_;
    for (out.rounds = 1; out.rounds <= options_.max_rounds; ++out.rounds) {
      const std::vector<std::size_t> infeasible = infeasible_rows();
      for (const std::size_t k : infeasible)
        out.misses.push_back(
            {jacobian.row_step[k], jacobian.row_precondition[k], rows_.epsilon[k] - rows_.room[k]});
      if (!infeasible.empty()) {
        out.status = AllocationStatus::kInfeasible;
        return out;
      }
      p = first_order_allocation(rows_, p0_, cost_, options_.algebra);
      if (!options_.verify) break;
      out.misses = verify_allocation(jacobian, parameters_, p0_, p, *verifying_,
                                     options_.verify_bounds, options_.threads, rows_);
      if (out.misses.empty()) break;
    }
    out.rounds = std::min(out.rounds, options_.max_rounds);
    for (Eigen::Index q = 0; q < p0_.size(); ++q) {
      out.parameters[static_cast<std::size_t>(q)].allocated = p[q];
      const double change = (p0_[q] - p[q]) / p0_[q];
      out.cost += cost_[q] * change * change;
    }
    if (!out.misses.empty() || !options_.verify)
      out.status = AllocationStatus::kNotProved;
    else
      out.status = (p == p0_) ? AllocationStatus::kNotNeeded : AllocationStatus::kProved;
    return out;
  }

 private:
  // The rows that fail even with every tolerance 0.
  [[nodiscard]] std::vector<std::size_t> infeasible_rows() const {
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < rows_.room.size(); ++k)
      if (rows_.room[k] - rows_.epsilon[k] < 0) rows.push_back(k);
    return rows;
  }

  const Sensitivities* jacobian_;
  AllocationOptions options_;
  AllocationParameters parameters_;
  Eigen::VectorXd p0_, cost_;
  AllocationRows rows_;  // its epsilon grows by each round's misses
  bool needed_{false};
  std::optional<VerifyProblems> verifying_;
};

}  // namespace

ToleranceAllocation allocate_tolerances(const Scenario& scenario, const InstanceAnalysis& analysis,
                                        const Sensitivities& jacobian,
                                        const AllocationOptions& options) {
  return Allocator(scenario, analysis, jacobian, options).run();
}

// The interface the header hides; Work, below, holds this file's own types.
class ProbabilityWork::Impl {
 public:
  virtual ~Impl() = default;
  virtual void sample() = 0;
  virtual void allocate() = 0;
  [[nodiscard]] virtual ProbabilityAnalysis probability() const = 0;
  [[nodiscard]] virtual ToleranceAllocation tolerances() const = 0;
};

namespace {

class Work final : public ProbabilityWork::Impl {
 public:
  Work(const Scenario& scenario, const InstanceAnalysis& analysis,
       const ProbabilityOptions& probability, const AllocationOptions& allocation)
      : analysis_(&analysis),
        options_(probability),
        jacobian_(sensitivities(analysis)),
        allocator_(scenario, analysis, jacobian_, allocation) {
    if (samples_wanted(jacobian_, probability))
      monte_carlo_.emplace(analysis, rows_of(analysis, jacobian_), probability);
  }
  void sample() override {
    if (monte_carlo_) sampled_ = monte_carlo_->run();
  }
  void allocate() override { tolerances_ = allocator_.run(); }
  [[nodiscard]] ProbabilityAnalysis probability() const override {
    if (monte_carlo_ && !sampled_)
      throw PlanError("internal: ProbabilityWork::probability() before sample()");
    ProbabilityAnalysis out = first_order(*analysis_, jacobian_, options_);
    if (sampled_) add_samples(out, *sampled_);
    return out;
  }
  [[nodiscard]] ToleranceAllocation tolerances() const override {
    if (!tolerances_) throw PlanError("internal: ProbabilityWork::tolerances() before allocate()");
    return *tolerances_;
  }

 private:
  const InstanceAnalysis* analysis_;
  ProbabilityOptions options_;
  Sensitivities jacobian_;  // before allocator_, which keeps a pointer to it
  Allocator allocator_;
  std::optional<MonteCarlo> monte_carlo_;  // when samples are wanted
  std::optional<SampledViolations> sampled_;
  std::optional<ToleranceAllocation> tolerances_;
};

}  // namespace

ProbabilityWork::ProbabilityWork(const Scenario& scenario, const InstanceAnalysis& analysis,
                                 const ProbabilityOptions& probability,
                                 const AllocationOptions& allocation)
    : impl_(std::make_unique<Work>(scenario, analysis, probability, allocation)) {}
ProbabilityWork::~ProbabilityWork() = default;

void ProbabilityWork::sample() { impl_->sample(); }
void ProbabilityWork::allocate() { impl_->allocate(); }
ProbabilityAnalysis ProbabilityWork::probability() const { return impl_->probability(); }
ToleranceAllocation ProbabilityWork::tolerances() const { return impl_->tolerances(); }

}  // namespace spar::planner
