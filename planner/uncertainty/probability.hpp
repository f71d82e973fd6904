// Probabilistic analysis on the same model as the worst case: how often a precondition fails,
// how readings of one object combine, and which tolerances to buy down.
//
// The worst case asks "can this fail?" over the box of the uncertainty variables. Here each
// variable x_j also has a distribution inside its box (SpaceVariable::sigma, from the scenario's
// `distribution:`): uniform (the box's own measure) or N(0, sigma_j^2) truncated to the box. The
// variables are independent; Σ is diagonal with Σ_jj = Var x_j (uniform on [a, b]: (b - a)^2 / 12,
// i.e. h^2 / 3 on [-h, h]; truncated Gaussian: its own variance, below).
//
// Sensitivities. J (preconditions x variables) holds ∂f_k/∂x_j at the nominal point x = 0, from
// the symbolic Jacobian of each precondition compiled once into a tape with its value and the
// diagonal of its Hessian H_k; only variables f_k depends on get entries (J is sparse: a
// precondition sees the objects and arm steps it involves). Stored in compressed sparse column
// form, CHOLMOD's layout.
//
// Moments and probabilities of f_k (μ = E x, zero for symmetric boxes):
//   first-order mean     m1 = f(0) + J_k μ
//   second-order mean    m2 = m1 + 1/2 Σ_j H_jj E[x_j^2]   (diagonal term: the cross terms
//                        H_ij μ_i μ_j vanish for symmetric boxes and are left out otherwise)
//   sigma                s = sqrt((J Σ J^T)_kk); the whole J Σ J^T is formed (its off-diagonal
//                        entries are the correlations between preconditions)
//   P(violation)         of N(m, s^2) TRUNCATED to the sound enclosure [lo, hi] of f over the box
//                        (PreconditionResult::bound, the support of f): for `f <= t` the mass
//                        above t, for `f >= t` the mass below t. Hence a precondition PROVED
//                        satisfied (hi <= t, resp. lo >= t) gets exactly 0, from first and second
//                        order alike. s = 0 gives 0 or 1.
//   Monte Carlo          `samples` independent points of the box drawn from the variables'
//                        distributions (fixed seed), the preconditions evaluated on one tape;
//                        the violation fraction with its Wilson interval. A proved precondition
//                        has no sampled violation (the samples lie in the box, where the sound
//                        bound holds): its estimate is 0 and its interval [0, 0]; a violation
//                        sampled there would be a soundness bug and is reported in `note`. That
//                        self-check uses the first samples / proved_share points only, and only
//                        those are drawn when every precondition is proved (the plan's P is then
//                        0 exactly); each row says its count.
//   agreement            where first order lies outside the Wilson interval, `note` says so and
//                        gives the second-order estimate (and whether that one agrees).
//
// Sensor fusion (information form). Readings z_r of an object's pose error (dx, dy, dz, dθ) with
// Gaussian covariances R_r combine as Λ = Σ R_r^-1 (one 4x4 block per object: a sparse
// block-diagonal information matrix over every sensed object), η = Σ R_r^-1 z_r, mean = Λ^-1 η,
// covariance = Λ^-1, factored with CHOLMOD. The worst-case model keeps the intersection of the
// readings' boxes z_r ± h_r. Phase 2 uses it when an object is scanned again before it moves
// (planner/uncertainty/propagation.hpp).
//
// Tolerance allocation. Group the variables by the scenario parameter they come from (an
// object's initial dx..dθ, the arm's, the range-scan residual's: "scenario half-widths" p with
// cost c_p). The first-order worst case of f_k over the box is linear in p:
//   f(0) + Σ_p A_kp p_p  with  A_kp = Σ_{j in p} |J_kj| h_j / p_p   (for `<=`; `>=` mirrored),
// so every first-order margin is positive when A p <= b - ε. The smallest weighted change
// min Σ_p c_p (δ_p / p_p)^2 that satisfies the violated rows as equalities is a minimum-norm
// least-squares problem, solved with SPQR (SuiteSparseQR_min2norm) and repeated (clamping to
// [0, p]) until no row is violated (an active-set iteration: exact for the rows it makes active
// when no clamp binds, otherwise a feasible small change, not a certified QP optimum; if clamps
// leave a row violated, all parameters shrink by one common factor, found by bisection until
// every row holds). Then every precondition is bounded soundly over the new box
// (bounds::BoundProblem); a row not proved raises its ε by its miss and the allocation is redone
// (a few rounds). The allocation counts as proved only when every bound proves its precondition.
// When phase 2 proved every precondition already, nothing is allocated (status not_needed).
//
// Example:
//   const PlanResult result = plan(scenario, builtin_domain());
//   const ProbabilityAnalysis p = analyse_probability(*result.chosen_analysis());
//   for (const PreconditionProbability& q : p.preconditions)
//     std::cout << q.sigma << ' ' << q.p_first_order << ' ' << q.p_monte_carlo << '\n';
//   const ToleranceAllocation t = allocate_tolerances(scenario, *result.chosen_analysis());
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/planner/scenario.hpp"
#include "spar/planner/uncertainty/space.hpp"

namespace spar::planner {

struct InstanceAnalysis;  // planner/uncertainty/analysis.hpp

// Which linear algebra does the sparse work: SuiteSparse (CHOLMOD, SPQR) or dense Eigen (LLT,
// CompleteOrthogonalDecomposition, a column-pivoting QR) for comparison. Same results.
enum class LinearAlgebra { kSparse, kDense };

// Mean and variance of one variable's distribution in its range.
struct VariableMoments {
  double mean{0.0};
  double variance{0.0};
};
[[nodiscard]] VariableMoments variable_moments(const SpaceVariable& variable);

// J at the nominal point. Row k is analysis.steps[row_step[k]].preconditions[row_precondition[k]]
// (execution order); column j is analysis.variables[j].
struct Sensitivities {
  std::size_t rows{0}, cols{0};
  std::vector<std::size_t> row_step, row_precondition;
  // Compressed sparse column (CHOLMOD's layout, 64-bit indices): column j's entries are rows
  // row_index[i] (ascending), values value[i], for i in [column_start[j], column_start[j + 1]);
  // column_start.size() == cols + 1.
  std::vector<std::int64_t> column_start, row_index;
  std::vector<double> value;
  std::vector<double> nominal;        // f_k(0)
  std::vector<double> hessian_trace;  // 1/2 Σ_j ∂²f_k/∂x_j² E[x_j^2]: m2 - m1
  // Variables with a non-finite derivative at 0 (e.g. |u| at u = 0) are left out and counted.
  std::size_t non_differentiable{0};
  [[nodiscard]] std::size_t nonzeros() const { return value.size(); }
  [[nodiscard]] double density() const;  // nonzeros / (rows x cols); 0 when empty
};
[[nodiscard]] Sensitivities sensitivities(const InstanceAnalysis& analysis);

// J Σ J^T: the first-order covariance of the preconditions.
struct PreconditionCovariance {
  std::vector<double> variance;  // its diagonal, per row of J
  std::size_t nonzeros{0};       // structural nonzeros (pairs of correlated preconditions)
};
[[nodiscard]] PreconditionCovariance precondition_covariance(
    const Sensitivities& jacobian, std::span<const SpaceVariable> variables,
    LinearAlgebra algebra = LinearAlgebra::kSparse);

struct PreconditionProbability {
  std::size_t step{0}, precondition{0};  // into InstanceAnalysis::steps[step].preconditions
  double nominal{0.0};                   // f(0)
  double mean{0.0};                      // m1
  double second_order_mean{0.0};         // m2
  double sigma{0.0};
  double p_first_order{0.0};
  double p_second_order{0.0};
  std::size_t samples{0}, violations{0};
  double p_monte_carlo{0.0};
  double ci_lo{0.0}, ci_hi{0.0};  // Wilson interval of p_monte_carlo (95%)
  bool proved{false};             // verdict satisfied: every probability above is 0
  bool agrees{true};              // p_first_order lies in [ci_lo, ci_hi]
  std::string note;               // disagreement, or a soundness alarm
};

struct ProbabilityOptions {
  std::size_t samples{20'000};   // Monte Carlo points (0: off)
  std::size_t proved_share{10};  // proved preconditions: the first samples / this (1: all)
  std::uint64_t seed{20261201};
  LinearAlgebra algebra{LinearAlgebra::kSparse};
};

struct ProbabilityAnalysis {
  std::size_t rows{0}, cols{0}, nonzeros{0};  // J's size
  double density{0.0};
  std::size_t covariance_nonzeros{0};
  std::size_t non_differentiable{0};
  std::vector<PreconditionProbability> preconditions;  // rows of J, in order
  // The plan: P(some precondition violated) sampled (same points), with its Wilson interval;
  // `samples` points were drawn (fewer than asked when every precondition is proved).
  std::size_t samples{0}, plan_violations{0};
  double p_plan{0.0}, p_plan_ci_lo{0.0}, p_plan_ci_hi{0.0};
};
// The analysis must have its expressions' pool (analysis.pool); derivatives are added to it.
[[nodiscard]] ProbabilityAnalysis analyse_probability(const InstanceAnalysis& analysis,
                                                      const ProbabilityOptions& options = {});
// The same with the instance's J already computed (sensitivities(analysis)): plan() computes it
// once for this and allocate_tolerances.
[[nodiscard]] ProbabilityAnalysis analyse_probability(const InstanceAnalysis& analysis,
                                                      const Sensitivities& jacobian,
                                                      const ProbabilityOptions& options = {});

// ---- Sensor fusion ----
struct PoseReading {
  int object{-1};
  Eigen::Vector4d estimate{Eigen::Vector4d::Zero()};        // (dx, dy, dz, dθ): the sensed error
  Eigen::Matrix4d covariance{Eigen::Matrix4d::Identity()};  // Gaussian model, positive definite
  Eigen::Vector4d half_width{Eigen::Vector4d::Zero()};      // worst case: truth in estimate ± h
};
struct FusedPose {
  int object{-1};
  int readings{0};
  Eigen::Vector4d mean{Eigen::Vector4d::Zero()};        // Λ^-1 η
  Eigen::Matrix4d covariance{Eigen::Matrix4d::Zero()};  // Λ^-1
  Eigen::Vector4d lower{Eigen::Vector4d::Zero()};       // intersection of the readings' boxes
  Eigen::Vector4d upper{Eigen::Vector4d::Zero()};
  bool consistent{true};  // the intersection is not empty (else lower > upper somewhere)
};
// One FusedPose per object read, ascending object. Throws PlanError for a covariance that is not
// symmetric positive definite or a negative half-width.
[[nodiscard]] std::vector<FusedPose> fuse_readings(std::span<const PoseReading> readings,
                                                   LinearAlgebra algebra = LinearAlgebra::kSparse);

// ---- Tolerance allocation ----
struct ToleranceParameter {
  UncertaintySource source{UncertaintySource::kInitial};
  int object{-1};  // initial: the object's index; -1 otherwise
  PoseComponent component{PoseComponent::kDx};
  std::string name;        // "peg.dx", "robot.dtheta", "range_scan.dy"
  double half_width{0.0};  // the scenario's (m, rad)
  double cost{1.0};
  double allocated{0.0};  // the new half-width (<= half_width)
};
enum class AllocationStatus {
  kNotNeeded,   // phase 2 proved every precondition over the scenario's box already
  kProved,      // the allocated box: every precondition proved satisfied by the sound bounds
  kNotProved,   // margins positive to first order, but some bound does not prove it (misses)
  kInfeasible,  // a precondition fails at the nominal point: no tolerance can fix it
};
[[nodiscard]] const char* to_string(AllocationStatus status);
struct ToleranceAllocation {
  AllocationStatus status{AllocationStatus::kNotNeeded};
  std::vector<ToleranceParameter> parameters;  // every parameter with a positive half-width
  double cost{0.0};                            // Σ c_p (δ_p / p_p)^2
  int rounds{0};  // allocations tried (each verified); 0 when phase 2 proved all already
  struct Miss {
    std::size_t step{0}, precondition{0};
    double by{0.0};  // how far the sound bound lies past the threshold (>= 0)
  };
  std::vector<Miss> misses;  // kNotProved / kInfeasible: the preconditions not proved
  // `scenario` with the allocated half-widths (sigmas scaled alike).
  [[nodiscard]] Scenario apply(Scenario scenario) const;
};
struct AllocationOptions {
  LinearAlgebra algebra{LinearAlgebra::kSparse};
  int max_rounds{4};
  bounds::BoundOptions verify_bounds{.tolerance = 1e-3, .max_box_evaluations = 5'000};
  // false: one first-order allocation, not verified (status kNotProved, no misses): benchmarks
  // time the linear algebra alone with it.
  bool verify{true};
  // Threads verifying the rows (common/parallel.hpp); the allocation does not depend on it.
  unsigned threads{1};
};
// `analysis` is an instance of `scenario` (its variables' provenance names the parameters).
[[nodiscard]] ToleranceAllocation allocate_tolerances(const Scenario& scenario,
                                                      const InstanceAnalysis& analysis,
                                                      const AllocationOptions& options = {});
// The same with the instance's J already computed (sensitivities(analysis)).
[[nodiscard]] ToleranceAllocation allocate_tolerances(const Scenario& scenario,
                                                      const InstanceAnalysis& analysis,
                                                      const Sensitivities& jacobian,
                                                      const AllocationOptions& options = {});

// analyse_probability and allocate_tolerances in parts, for plan() to run them beside the
// margins (margins.hpp's MarginWork) on its threads; the results are the two functions'. The
// constructor does all that reads or extends the analysis' pool (J, the Monte Carlo's tapes, the
// allocation's own copies of its rows), on the thread that owns the pool. sample() (the Monte
// Carlo) and allocate() (the tolerance allocation, itself on allocation.threads) read only what
// the constructor made and the analysis' variables and results (boxes, relations, verdicts: not
// the margins' fields), so they may run on any threads, at the same time as each other and as
// the margins, each once. probability() needs sample() and the margins' tight bounds (the
// first-order probabilities truncate to PreconditionResult::bound); tolerances() needs
// allocate(); either before its part throws PlanError. `analysis` must outlive the work.
class ProbabilityWork {
 public:
  ProbabilityWork(const Scenario& scenario, const InstanceAnalysis& analysis,
                  const ProbabilityOptions& probability, const AllocationOptions& allocation);
  ~ProbabilityWork();
  void sample();
  void allocate();
  [[nodiscard]] ProbabilityAnalysis probability() const;
  [[nodiscard]] ToleranceAllocation tolerances() const;
  class Impl;  // probability.cpp's

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace spar::planner
