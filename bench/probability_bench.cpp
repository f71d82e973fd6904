// probability: the probabilistic analysis of issue 15 (planner/uncertainty/probability.hpp) on
// plans of N peg-into-block pairs, SuiteSparse against dense Eigen in the same run.
//   The plan, per pair i (built directly with planner::Propagation, no phase 1): range-scan
//   block i, range-scan it again (the readings are fused), pick peg i up, insert it into block i.
//   Every uncertainty is Gaussian with sigma = half-width / 3; the peg's position uncertainty is
//   wider than its pickup allows, so tolerance allocation has rows to fix. Each precondition is
//   decided as phase 2 does (bounds::ConditionSet over the space's box).
//   Timed per N (median of repeats), each kernel with both linear algebras:
//     J          sensitivities(): symbolic Jacobian + Hessian diagonal on one tape per
//                precondition, evaluated at 0, assembled as CSC (shared by both; the dense
//                column is the extra cost of a dense m x n copy)
//     moments    J Σ J^T: CHOLMOD's A A^T of J Σ^(1/2) vs Eigen's dense product
//     fusion     3N readings of 2N objects (two per block, one per peg, correlated 4x4
//                covariances): CHOLMOD's sparse Cholesky + sparse solve vs Eigen LLT + inverse
//     allocation the first-order tolerance allocation given J (unverified: linear algebra alone):
//                SPQR min-norm vs Eigen's CompleteOrthogonalDecomposition
//   The answers of both are compared (max relative difference). At the largest N, one verified
//   allocation and a Monte Carlo run are reported too.
// Usage: probability_bench [--quick]   (N = 1, 5, 10 instead of 1 .. 50)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench/timing.hpp"
#include "spar/bounds/condition_set.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/uncertainty/probability.hpp"
#include "spar/planner/uncertainty/propagation.hpp"
#include "spar/symbolic/operations.hpp"

namespace planner = spar::planner;
namespace symbolic = spar::symbolic;
using planner::LinearAlgebra;

namespace {

using spar::bench::load_average;
using spar::bench::seconds_since;
using spar::bench::time_median;

// N pairs on a grid (the tests' seed pickup layout: the peg on its side, the block hole up);
// Propagation does not need the robot to reach them.
std::string pairs_scenario(int pairs) {
  std::string text =
      "name: probability_pairs\nunits: {length: in, angle: deg}\n"
      "robot:\n  model: puma560\n  tool: {xyz: [0, 0, 8], rpy: [0, 0, 0]}\n"
      "  gripper: {max_opening: 4, finger_length: 3}\n"
      "  uncertainty: {dx: 0.001, dy: 0.001, dz: 0.001, dtheta: 0.0573, distribution: gaussian}\n"
      "sensors:\n  range_scan: {residual: {dx: 0.02, dy: 0.02, dz: 0.02, dtheta: 1, "
      "distribution: gaussian}}\n"
      "objects:\n";
  char line[640];
  for (int i = 0; i < pairs; ++i) {
    const double x = 10 + 12 * (i % 10), y = -30 + 12 * (i / 10);
    std::snprintf(line, sizeof line,
                  "  block%d:\n    builtin: block\n    features: {hole: [2, 6, 10, 12, 16]}\n"
                  "    pose: {stable: P5, at: [%.1f, %.1f], yaw: 45}\n"
                  "    uncertainty: {dx: 0.11, dy: 0.11, dz: 0.11, dtheta: 5.5, distribution: "
                  "gaussian}\n"
                  "  peg%d:\n    builtin: peg\n"
                  "    features: {shaft: [11, 12, 13, 14, 15, 16, 17, 18, 19]}\n"
                  "    pose: {stable: P7, at: [%.1f, %.1f], yaw: 30}\n"
                  "    uncertainty: {dx: 0.7, dy: 0.7, dz: 0.7, dtheta: 5.5, distribution: "
                  "gaussian}\n",
                  i + 1, x, y, i + 1, x + 5, y + 5);
    text += line;
  }
  text += "goals:\n";
  for (int i = 0; i < pairs; ++i) {
    std::snprintf(line, sizeof line,
                  "  - assembled: {held: peg%d, fixed: block%d, held_faces: shaft, fixed_faces: "
                  "hole, relative: {xyz: [0, 0, 6], rpy: [180, 0, 0]}, mating_vector: [0, 0, -1], "
                  "clearance: 0.5, angular_clearance: 10}\n",
                  i + 1, i + 1);
    text += line;
  }
  return text;
}

int action_with(const planner::Domain& domain, planner::Effect effect) {
  for (std::size_t a = 0; a < domain.actions.size(); ++a)
    if (domain.actions[a].effect == effect) return static_cast<int>(a);
  std::fprintf(stderr, "the built-in domain has no action with that effect\n");
  std::exit(1);
}

struct Plan {
  std::unique_ptr<planner::WorldModel> world;
  planner::InstanceAnalysis analysis;
  double build_seconds{0};  // propagation + deciding (not part of the comparison)
};

// The N-pair plan through Propagation, each step's preconditions decided as phase 2 does.
Plan build_plan(int pairs) {
  Plan plan;
  const auto start = std::chrono::steady_clock::now();
  plan.world = std::make_unique<planner::WorldModel>(
      planner::parse_scenario(pairs_scenario(pairs), "<pairs>", SPAR_SOURCE_DIR));
  const planner::WorldModel& world = *plan.world;
  const planner::Domain& domain = planner::builtin_domain();
  plan.analysis.pool = std::make_unique<symbolic::ExprPool>();
  planner::Propagation propagation(world, domain, *plan.analysis.pool);
  int index = 0;
  const auto run = [&](const planner::Phase2Step& step) {
    const std::vector<planner::Precondition> preconditions = propagation.step(step, ++index);
    planner::AnalysedStep analysed;
    analysed.step = step;
    analysed.action = domain.actions[step.action].name;
    if (!preconditions.empty()) {
      std::vector<spar::bounds::Inequality> inequalities;
      std::vector<symbolic::Expr> expressions;
      for (const planner::Precondition& p : preconditions) {
        inequalities.push_back(p.inequality);
        expressions.push_back(p.inequality.expression);
      }
      const planner::UncertaintySpace& space = propagation.space();
      const std::vector<planner::VariableId> ids = planner::variables_of(expressions, space);
      std::vector<symbolic::Expr> variables;
      for (const planner::VariableId id : ids) variables.push_back(space.symbol(id));
      const std::vector<spar::bounds::Interval> box = space.ranges(ids);
      spar::bounds::ConditionSet set(inequalities, variables);
      const std::vector<spar::bounds::ConditionCheck> checks =
          set.check(box, {.tolerance = 1e-2, .max_box_evaluations = 300});
      for (std::size_t i = 0; i < preconditions.size(); ++i) {
        planner::PreconditionResult result;
        result.kind = preconditions[i].kind;
        result.inequality = preconditions[i].inequality;
        result.verdict = checks[i].verdict;
        result.bound = checks[i].bound;
        const std::vector<symbolic::Expr> own = symbolic::free_variables(expressions[i]);
        for (std::size_t v = 0; v < variables.size(); ++v)
          if (std::find(own.begin(), own.end(), variables[v]) != own.end()) {
            result.variables.push_back(ids[v]);
            result.box.push_back(box[v]);
          }
        analysed.preconditions.push_back(std::move(result));
      }
    }
    plan.analysis.steps.push_back(std::move(analysed));
  };
  for (int i = 0; i < pairs; ++i) {
    const int block = world.object_index("block" + std::to_string(i + 1));
    const int peg = world.object_index("peg" + std::to_string(i + 1));
    const planner::ObjectSpec& block_spec = world.scenario().objects[block];
    const planner::ObjectSpec& peg_spec = world.scenario().objects[peg];
    const planner::AssembledGoal& goal =
        std::get<planner::AssembledGoal>(world.scenario().goals[i]);
    planner::Phase2Step scan{.action = action_with(domain, planner::Effect::kSense),
                             .effect = planner::Effect::kSense,
                             .object = block,
                             .object_pose = block_spec.initial_pose};
    run(scan);
    run(scan);  // again before it moves: the readings are fused
    run({.action = action_with(domain, planner::Effect::kGrasp),
         .effect = planner::Effect::kGrasp,
         .object = peg,
         .grasp = 0,
         .position = 0,
         .object_pose = peg_spec.initial_pose});
    run({.action = action_with(domain, planner::Effect::kInsert),
         .effect = planner::Effect::kInsert,
         .object = peg,
         .grasp = 0,
         .fixed_object = block,
         .object_pose = block_spec.initial_pose * goal.relative,
         .fixed_pose = block_spec.initial_pose});
  }
  plan.analysis.variables = propagation.space().variables();
  plan.analysis.symbols = propagation.space().symbols();
  plan.build_seconds = seconds_since(start);
  return plan;
}

// 3N readings of 2N objects with deterministic correlated covariances.
std::vector<planner::PoseReading> readings_of(int pairs) {
  std::mt19937_64 random(15);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<planner::PoseReading> readings;
  for (int object = 0; object < 2 * pairs; ++object)
    for (int r = 0; r < (object % 2 == 0 ? 2 : 1); ++r) {
      Eigen::Matrix4d a;
      for (int i = 0; i < 16; ++i) a(i / 4, i % 4) = normal(random);
      planner::PoseReading reading{.object = object};
      reading.covariance = 1e-7 * (a * a.transpose() + Eigen::Matrix4d::Identity());
      for (int i = 0; i < 4; ++i) reading.estimate[i] = 1e-4 * normal(random);
      reading.half_width = Eigen::Vector4d::Constant(2e-3);
      readings.push_back(reading);
    }
  return readings;
}

double relative_difference(double a, double b) {
  const double scale = std::max({std::abs(a), std::abs(b), 1e-300});
  return std::abs(a - b) / scale;
}

struct Row {
  int pairs{0};
  std::size_t rows{0}, cols{0}, nonzeros{0}, covariance_nonzeros{0}, readings{0};
  std::size_t allocation_parameters{0};
  double density{0}, build{0}, jacobian{0}, dense_copy{0};
  double moments[2]{}, fusion[2]{}, allocation[2]{};  // [sparse, dense]
  double max_difference{0};
};

// One size's row: the plan of `pairs` pairs, its sensitivities, and each kernel (moments, fusion,
// allocation) with SuiteSparse and dense Eigen, with how far the two answers differ.
Row measure(int pairs, const Plan& plan) {
  Row row{.pairs = pairs};
  row.build = plan.build_seconds;
  const planner::InstanceAnalysis& analysis = plan.analysis;
  const int repeats = pairs <= 10 ? 9 : 5;
  planner::Sensitivities jacobian;
  row.jacobian = time_median(repeats, [&] { jacobian = planner::sensitivities(analysis); });
  row.rows = jacobian.rows;
  row.cols = jacobian.cols;
  row.nonzeros = jacobian.nonzeros();
  row.density = jacobian.density();
  row.dense_copy = time_median(repeats, [&] {
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(jacobian.rows),
                                                  static_cast<Eigen::Index>(jacobian.cols));
    for (std::size_t j = 0; j < jacobian.cols; ++j)
      for (std::int64_t i = jacobian.column_start[j]; i < jacobian.column_start[j + 1]; ++i)
        dense(jacobian.row_index[i], static_cast<Eigen::Index>(j)) = jacobian.value[i];
    volatile double sink = dense.sum();  // keep the work
    (void)sink;
  });
  const std::vector<planner::PoseReading> readings = readings_of(pairs);
  row.readings = readings.size();
  const planner::Scenario& scenario = plan.world->scenario();
  planner::PreconditionCovariance covariance[2];
  std::vector<planner::FusedPose> fused[2];
  planner::ToleranceAllocation allocation[2];
  for (int a = 0; a < 2; ++a) {
    const LinearAlgebra algebra = a == 0 ? LinearAlgebra::kSparse : LinearAlgebra::kDense;
    row.moments[a] = time_median(repeats, [&] {
      covariance[a] = planner::precondition_covariance(jacobian, analysis.variables, algebra);
    });
    row.fusion[a] =
        time_median(repeats, [&] { fused[a] = planner::fuse_readings(readings, algebra); });
    row.allocation[a] = time_median(repeats, [&] {
      allocation[a] = planner::allocate_tolerances(scenario, analysis, jacobian,
                                                   {.algebra = algebra, .verify = false});
    });
  }
  row.covariance_nonzeros = covariance[0].nonzeros;
  row.allocation_parameters = allocation[0].parameters.size();
  for (std::size_t k = 0; k < covariance[0].variance.size(); ++k)
    row.max_difference =
        std::max(row.max_difference,
                 relative_difference(covariance[0].variance[k], covariance[1].variance[k]));
  for (std::size_t o = 0; o < fused[0].size(); ++o)
    row.max_difference =
        std::max(row.max_difference, (fused[0][o].covariance - fused[1][o].covariance).norm() /
                                         fused[1][o].covariance.norm());
  for (std::size_t q = 0; q < allocation[0].parameters.size(); ++q)
    row.max_difference = std::max(
        row.max_difference,
        std::abs(allocation[0].parameters[q].allocated - allocation[1].parameters[q].allocated) /
            allocation[0].parameters[q].half_width);
  return row;
}

// Crossovers: the smallest N from which SuiteSparse stays faster (to the largest N).
void print_crossovers(const std::vector<Row>& table) {
  const char* names[3] = {"moments", "fusion", "allocation"};
  for (int kernel = 0; kernel < 3; ++kernel) {
    const auto times = [&](const Row& r) {
      const double* pair = kernel == 0 ? r.moments : kernel == 1 ? r.fusion : r.allocation;
      return std::pair<double, double>(pair[0], pair[1]);
    };
    int from = -1;
    for (std::size_t i = table.size(); i-- > 0;) {
      const auto [sparse, dense] = times(table[i]);
      if (sparse < dense)
        from = table[i].pairs;
      else
        break;
    }
    const auto [sparse, dense] = times(table.back());
    std::printf(
        "%-10s crossover N %s; at N = %d dense/sparse = %.2f\n", names[kernel],
        from < 0 ? "none (dense faster at the largest N)" : ("= " + std::to_string(from)).c_str(),
        table.back().pairs, dense / sparse);
    std::printf("ratio probability_%s(N=%d) dense_eigen %.2f\n", names[kernel], table.back().pairs,
                dense / sparse);
  }
}

// The largest plan: one verified allocation and a Monte Carlo run.
void verify_largest(const Plan& largest, int pairs) {
  auto start = std::chrono::steady_clock::now();
  const planner::ToleranceAllocation verified =
      planner::allocate_tolerances(largest.world->scenario(), largest.analysis);
  const double verify_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  const planner::ProbabilityAnalysis probability =
      planner::analyse_probability(largest.analysis, {.samples = 2000});
  const double monte_carlo_seconds = seconds_since(start);
  std::size_t disagree = 0, proved = 0;
  for (const planner::PreconditionProbability& p : probability.preconditions) {
    disagree += !p.agrees;
    proved += p.proved;
  }
  std::printf(
      "N = %d: verified allocation %s in %d rounds, %.2f s (cost %.3g); analyse_probability "
      "(2000 samples) %.2f s: %zu proved, %zu first order outside the Monte Carlo "
      "interval, P(plan fails) = %.3g [%.3g, %.3g]\n",
      pairs, planner::to_string(verified.status), verified.rounds, verify_seconds, verified.cost,
      monte_carlo_seconds, proved, disagree, probability.p_plan, probability.p_plan_ci_lo,
      probability.p_plan_ci_hi);
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const std::vector<int> sizes =
      quick ? std::vector<int>{1, 5, 10} : std::vector<int>{1, 2, 5, 10, 20, 30, 40, 50};
  std::printf("probability_bench%s: load average %s at start\n", quick ? " --quick" : "",
              load_average().c_str());
  std::printf("%4s %5s %5s %6s %8s %7s | %9s %9s | %19s | %19s | %19s | %7s\n", "N", "rows", "cols",
              "nnz", "density", "build s", "J ms", "dense J", "moments sparse/dense",
              "fusion sparse/dense", "alloc sparse/dense", "max diff");
  std::vector<Row> table;
  Plan largest;
  for (const int pairs : sizes) {
    Plan plan = build_plan(pairs);
    const Row row = measure(pairs, plan);
    std::printf(
        "%4d %5zu %5zu %6zu %8.4f %7.2f | %9.2f %9.3f | %8.3f / %8.3f | %8.3f / %8.3f | "
        "%8.3f / %8.3f | %7.1e\n",
        pairs, row.rows, row.cols, row.nonzeros, row.density, row.build, 1e3 * row.jacobian,
        1e3 * row.dense_copy, 1e3 * row.moments[0], 1e3 * row.moments[1], 1e3 * row.fusion[0],
        1e3 * row.fusion[1], 1e3 * row.allocation[0], 1e3 * row.allocation[1], row.max_difference);
    std::fflush(stdout);
    table.push_back(row);
    if (pairs == sizes.back()) largest = std::move(plan);
  }
  print_crossovers(table);
  verify_largest(largest, table.back().pairs);
  std::printf("load average %s at end\n", load_average().c_str());
  return 0;
}
