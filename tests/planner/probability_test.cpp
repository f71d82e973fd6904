// Probabilistic analysis (issue 15, planner/uncertainty/probability.hpp): the scenario's
// distributions, sensitivities against finite differences, first-order moments against exact
// ones, Monte Carlo against first order on the seed's pickup, zero probability for proved
// preconditions, sensor fusion against the closed form, and tolerance allocation proved by the
// sound bounds (and plugged back into the scenario).
#include "spar/planner/uncertainty/probability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/common/units.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"
#include "tests/common/replaced.hpp"
#include "tests/planner/same_results.hpp"

namespace spar::planner {
namespace {

using bounds::Relation;
using bounds::Verdict;
constexpr double kInch = units::kInch;
constexpr double kDegree = units::kDegree;

// ---- scenario: distribution, sigma, cost ----

const std::string kScenario = R"(units: {length: in, angle: deg}
robot:
  uncertainty: {dx: 0.003, dy: 0.003, dz: 0.003, dtheta: 0.06, distribution: gaussian}
sensors:
  range_scan: {residual: {dx: 0.02, dy: 0.02, dz: 0.02, dtheta: 1, distribution: uniform}}
objects:
  peg:
    builtin: peg
    pose: {stable: P1, at: [14, 12]}
    uncertainty: {dx: 0.11, dy: 0.11, dz: 0.11, dtheta: 5.5, distribution: gaussian, sigma: {dx: 0.05, dtheta: 1}, cost: {dz: 3}}
)";

using test_support::replaced;

std::string error_of(const std::string& yaml) {
  try {
    (void)parse_scenario(yaml, "cell.yaml", ".");
  } catch (const ScenarioError& error) {
    return error.what();
  }
  return "";
}

TEST(ProbabilityScenario, ReadsDistributionSigmaAndCostInTheFilesUnits) {
  const Scenario scenario = parse_scenario(kScenario, "cell.yaml", ".");
  const ObjectSpec& peg = scenario.object("peg");
  EXPECT_EQ(peg.uncertainty_model.distribution, Distribution::kGaussian);
  EXPECT_NEAR(peg.uncertainty_model.sigma.dx, 0.05 * kInch, 1e-15);
  EXPECT_NEAR(peg.uncertainty_model.sigma.dy, 0.11 * kInch / 3, 1e-15);  // default: h / 3
  EXPECT_NEAR(peg.uncertainty_model.sigma.dtheta, 1 * kDegree, 1e-15);
  EXPECT_EQ(peg.uncertainty_model.cost.dz, 3.0);
  EXPECT_EQ(peg.uncertainty_model.cost.dx, 1.0);
  EXPECT_EQ(scenario.robot.uncertainty_model.distribution, Distribution::kGaussian);
  EXPECT_NEAR(scenario.robot.uncertainty_model.sigma.dtheta, 0.02 * kDegree, 1e-15);
  ASSERT_TRUE(scenario.range_scan);
  EXPECT_EQ(scenario.range_scan->residual_model.distribution, Distribution::kUniform);
  EXPECT_EQ(scenario.range_scan->residual_model.sigma.dx, 0.0);
  EXPECT_NEAR(scenario.range_scan->residual.dtheta, 1 * kDegree, 1e-15);
}

TEST(ProbabilityScenario, MistakesAreReportedWithFileLineAndColumn) {
  EXPECT_EQ(error_of(replaced(kScenario, "distribution: gaussian}", "distribution: gausian}")),
            "cell.yaml:3:78: robot.uncertainty.distribution: unknown distribution 'gausian' (did "
            "you mean 'gaussian'?); known: uniform, gaussian");
  EXPECT_EQ(error_of(replaced(kScenario, "distribution: uniform}", "sigma: {dx: 0.01}}")),
            "cell.yaml:5:75: sensors.range_scan.residual.sigma: sigma needs 'distribution: "
            "gaussian'");
  EXPECT_EQ(error_of(replaced(kScenario, "sigma: {dx: 0.05", "sigma: {dx: 0")),
            "cell.yaml:10:98: objects.peg.uncertainty.sigma.dx: must be > 0 where the "
            "half-width is, got 0");
  EXPECT_EQ(error_of(replaced(kScenario, "cost: {dz: 3}", "cost: {dz: 0}")),
            "cell.yaml:10:127: objects.peg.uncertainty.cost.dz: must be a number > 0 and <= "
            "1e+06 (a relative weight), got 0");
  EXPECT_EQ(error_of(replaced(kScenario, "cost: {dz: 3}", "cost: {dq: 3}")),
            "cell.yaml:10:123: objects.peg.uncertainty.cost: unknown key 'dq' (did you mean "
            "'dx'?); known keys: dx, dy, dz, dtheta");
}

// ---- a hand-built instance over the arm's variables (linear and quadratic preconditions) ----

struct Built {
  Scenario scenario;
  InstanceAnalysis analysis;
};

// One step with the given preconditions over dx_g1, dy_g1 (half-widths h, sigmas s: 0 = uniform),
// bounded and decided as phase 2 would.
Built hand_built(const std::vector<std::pair<std::string, std::pair<Relation, double>>>& rows,
                 double hx, double hy, double sx = 0, double sy = 0) {
  Built out;
  out.scenario.robot.uncertainty = {hx, hy, 0, 0};
  out.scenario.robot.uncertainty_model.distribution =
      sx > 0 ? Distribution::kGaussian : Distribution::kUniform;
  out.scenario.robot.uncertainty_model.sigma = {sx, sy, 0, 0};
  out.analysis.pool = std::make_unique<symbolic::ExprPool>();
  symbolic::ExprPool& pool = *out.analysis.pool;
  const Provenance arm{.source = UncertaintySource::kManipulator, .object = -1, .step = 1};
  out.analysis.variables = {{"dx_g1", PoseComponent::kDx, -hx, hx, sx, arm},
                            {"dy_g1", PoseComponent::kDy, -hy, hy, sy, arm}};
  out.analysis.symbols = {pool.variable("dx_g1"), pool.variable("dy_g1")};
  AnalysedStep step;
  for (const auto& [text, relation] : rows) {
    PreconditionResult result;
    result.kind = Builder::kPickup;
    result.inequality = {text, symbolic::parse(pool, text), relation.first, relation.second};
    bounds::Box box;
    for (const symbolic::Expr v : symbolic::free_variables(result.inequality.expression)) {
      const double h = v.name() == "dx_g1" ? hx : hy;
      box.add(v, -h, h);
      result.variables.push_back(VariableId{v.name() == "dx_g1" ? 0u : 1u});
      result.box.push_back(bounds::Interval(-h, h));
    }
    result.bound = bounds::bound(result.inequality.expression, box);
    result.verdict = bounds::decide(result.inequality, result.bound);
    step.preconditions.push_back(std::move(result));
  }
  out.analysis.steps.push_back(std::move(step));
  return out;
}

TEST(ProbabilityMoments, UniformAndTruncatedGaussianVariances) {
  const Provenance any{};
  EXPECT_NEAR(variable_moments({"u", PoseComponent::kDx, -0.3, 0.3, 0.0, any}).variance, 0.09 / 3,
              1e-15);
  EXPECT_NEAR(variable_moments({"u", PoseComponent::kDx, 0.1, 0.4, 0.0, any}).mean, 0.25, 1e-15);
  // Truncated Gaussian against a Simpson integration of the density over the box.
  for (const auto& [lo, hi, sigma] :
       {std::tuple{-0.3, 0.3, 0.1}, std::tuple{-0.1, 0.3, 0.2}, std::tuple{-1.0, 1.0, 10.0}}) {
    const int n = 20000;
    double z = 0, m1 = 0, m2 = 0;
    for (int i = 0; i <= n; ++i) {
      const double x = lo + (hi - lo) * i / n, w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      const double density = w * std::exp(-0.5 * x * x / (sigma * sigma));
      z += density;
      m1 += density * x;
      m2 += density * x * x;
    }
    const VariableMoments moments = variable_moments({"g", PoseComponent::kDx, lo, hi, sigma, any});
    EXPECT_NEAR(moments.mean, m1 / z, 1e-9);
    EXPECT_NEAR(moments.variance, m2 / z - (m1 / z) * (m1 / z), 1e-9);
  }
}

TEST(ProbabilityMoments, LinearPreconditionSigmaIsExact) {
  // f = 2 dx - 3 dy + 1: Var f = 4 Var dx + 9 Var dy exactly, both for uniform and Gaussian.
  for (const double sigma : {0.0, 0.2}) {
    Built built = hand_built({{"2*dx_g1 - 3*dy_g1 + 1", {Relation::kLessEqual, 1.5}}}, 0.5, 0.3,
                             sigma, sigma);
    const ProbabilityAnalysis p =
        analyse_probability(built.analysis, {.samples = 40'000, .seed = 7});
    const auto var = [&](const SpaceVariable& v) { return variable_moments(v).variance; };
    const double exact =
        std::sqrt(4 * var(built.analysis.variables[0]) + 9 * var(built.analysis.variables[1]));
    ASSERT_EQ(p.preconditions.size(), 1u);
    EXPECT_NEAR(p.preconditions[0].sigma, exact, 1e-14 * exact);
    EXPECT_DOUBLE_EQ(p.preconditions[0].mean, 1.0);
    EXPECT_DOUBLE_EQ(p.preconditions[0].second_order_mean, 1.0);  // no curvature
    EXPECT_EQ(p.rows, 1u);
    EXPECT_EQ(p.cols, 2u);
    EXPECT_EQ(p.nonzeros, 2u);
  }
}

TEST(ProbabilityMoments, SecondOrderMeanOfAQuadratic) {
  // f = dx^2 + dy: E f = Var dx exactly; first order says 0.
  Built built = hand_built({{"dx_g1^2 + dy_g1", {Relation::kLessEqual, 10.0}}}, 0.6, 0.1);
  const ProbabilityAnalysis p = analyse_probability(built.analysis, {.samples = 0});
  EXPECT_DOUBLE_EQ(p.preconditions[0].mean, 0.0);
  EXPECT_NEAR(p.preconditions[0].second_order_mean, 0.36 / 3, 1e-15);
}

TEST(ProbabilityMoments, SensitivitiesMatchFiniteDifferences) {
  Built built = hand_built({{"sin(dx_g1) * (2 + dy_g1) - dy_g1^3", {Relation::kLessEqual, 5.0}},
                            {"cos(dy_g1) + 0.5*dy_g1", {Relation::kGreaterEqual, -5.0}}},
                           0.2, 0.2);
  const Sensitivities j = sensitivities(built.analysis);
  ASSERT_EQ(j.rows, 2u);
  ASSERT_EQ(j.cols, 2u);
  // Row 1 does not depend on dx_g1, and row 0's dy-derivative sin(dx) - 3 dy^2 is 0 at the
  // nominal point: J is half full.
  EXPECT_EQ(j.nonzeros(), 2u);
  EXPECT_DOUBLE_EQ(j.density(), 0.5);
  std::map<std::pair<std::int64_t, std::size_t>, double> entries;
  for (std::size_t c = 0; c < j.cols; ++c)
    for (std::int64_t i = j.column_start[c]; i < j.column_start[c + 1]; ++i)
      entries[{j.row_index[i], c}] = j.value[i];
  const double h = 1e-6;
  for (std::size_t k = 0; k < 2; ++k)
    for (std::size_t c = 0; c < 2; ++c) {
      const symbolic::Expr f = built.analysis.steps[0].preconditions[k].inequality.expression;
      std::map<std::string, double> plus{{"dx_g1", 0.0}, {"dy_g1", 0.0}}, minus = plus;
      plus[c == 0 ? "dx_g1" : "dy_g1"] = h;
      minus[c == 0 ? "dx_g1" : "dy_g1"] = -h;
      const double difference =
          (symbolic::evaluate(f, plus) - symbolic::evaluate(f, minus)) / (2 * h);
      const auto found = entries.find({static_cast<std::int64_t>(k), c});
      EXPECT_NEAR(found == entries.end() ? 0.0 : found->second, difference, 1e-8) << k << c;
    }
}

TEST(ProbabilityMoments, SparseAndDenseCovarianceAgree) {
  Built built = hand_built({{"2*dx_g1 - dy_g1", {Relation::kLessEqual, 5.0}},
                            {"dx_g1 + dy_g1", {Relation::kLessEqual, 5.0}},
                            {"dy_g1", {Relation::kLessEqual, 5.0}}},
                           0.2, 0.4);
  const Sensitivities j = sensitivities(built.analysis);
  const PreconditionCovariance sparse =
      precondition_covariance(j, built.analysis.variables, LinearAlgebra::kSparse);
  const PreconditionCovariance dense =
      precondition_covariance(j, built.analysis.variables, LinearAlgebra::kDense);
  ASSERT_EQ(sparse.variance.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(sparse.variance[k], dense.variance[k], 1e-15);
  EXPECT_NEAR(sparse.variance[0], 4 * 0.04 / 3 + 0.16 / 3, 1e-15);
  EXPECT_EQ(sparse.nonzeros, 9u);  // every pair shares a variable
  EXPECT_EQ(dense.nonzeros, 9u);
}

// ---- the seed's pickup (tests/planner/data/phase2_peg_pickup.yaml) ----

Scenario peg_pickup() {
  return load_scenario(std::string(SPAR_SOURCE_DIR) + "/tests/planner/data/phase2_peg_pickup.yaml");
}
ObjectSpec& peg_of(Scenario& scenario) {
  for (ObjectSpec& object : scenario.objects)
    if (object.name == "peg") return object;
  throw PlanError("no peg");
}
// The peg's displacement widened past the 0.5 in to spare (two pickup inequalities fail), no
// repair, no sensor: the pickup's preconditions are left violated.
Scenario widened_without_sensor() {
  Scenario scenario = peg_pickup();
  ObjectSpec& peg = peg_of(scenario);
  peg.uncertainty.dx = peg.uncertainty.dy = peg.uncertainty.dz = 0.7 * kInch;
  scenario.range_scan.reset();
  return scenario;
}
PlanOptions plan_options() {
  PlanOptions options;
  options.max_instances = 2;
  options.analysis.reverse = false;
  options.analysis.blame = false;
  options.analysis.samples = 0;
  options.analysis.repair = false;
  return options;
}

// Every precondition: first order inside Monte Carlo's interval, or the disagreement is noted;
// every proved one has no sampled violation and probability exactly 0 from both.
void expect_consistent(const InstanceAnalysis& analysis, const ProbabilityAnalysis& p) {
  for (const PreconditionProbability& q : p.preconditions) {
    const PreconditionResult& result = analysis.steps[q.step].preconditions[q.precondition];
    SCOPED_TRACE(result.inequality.name);
    EXPECT_TRUE(q.agrees || !q.note.empty());
    EXPECT_EQ(q.note.find("SOUNDNESS"), std::string::npos) << q.note;
    EXPECT_LE(q.ci_lo, q.p_monte_carlo);
    EXPECT_GE(q.ci_hi, q.p_monte_carlo);
    if (result.verdict == Verdict::kSatisfied) {
      EXPECT_TRUE(q.proved);
      EXPECT_EQ(q.violations, 0u);
      EXPECT_EQ(q.p_monte_carlo, 0.0);
      EXPECT_EQ(q.p_first_order, 0.0);
      EXPECT_EQ(q.p_second_order, 0.0);
    }
  }
}

TEST(ProbabilitySeedPickup, Table2IsProvedSoEveryProbabilityIsZero) {
  const PlanResult result = plan(peg_pickup(), builtin_domain(), plan_options());
  ASSERT_TRUE(result.planned());
  const InstanceAnalysis& chosen = *result.chosen_analysis();
  const ProbabilityAnalysis p = analyse_probability(chosen, {.samples = 20'000});
  ASSERT_FALSE(p.preconditions.empty());
  EXPECT_GT(p.cols, 8u);
  EXPECT_LT(p.density, 1.0);
  for (const PreconditionProbability& q : p.preconditions) EXPECT_TRUE(q.proved);
  EXPECT_EQ(p.plan_violations, 0u);
  expect_consistent(chosen, p);
}

TEST(ProbabilitySeedPickup, WidenedPickupMonteCarloAgreesWithFirstOrderOrSaysWhy) {
  for (const Distribution distribution : {Distribution::kUniform, Distribution::kGaussian}) {
    SCOPED_TRACE(to_string(distribution));
    Scenario scenario = widened_without_sensor();
    for (ObjectSpec& object : scenario.objects) {
      object.uncertainty_model.distribution = distribution;
      const kinematics::PoseUncertainty& h = object.uncertainty;
      if (distribution == Distribution::kGaussian)
        object.uncertainty_model.sigma = {h.dx / 3, h.dy / 3, h.dz / 3, h.dtheta / 3};
    }
    const PlanResult result = plan(scenario, builtin_domain(), plan_options());
    ASSERT_TRUE(result.planned());
    const InstanceAnalysis& chosen = *result.chosen_analysis();
    EXPECT_GT(chosen.errors, 0);
    const ProbabilityAnalysis p = analyse_probability(chosen, {.samples = 20'000});
    expect_consistent(chosen, p);
    std::size_t failing = 0;
    for (const PreconditionProbability& q : p.preconditions) {
      if (q.proved) continue;
      ++failing;
      SCOPED_TRACE(chosen.steps[q.step].preconditions[q.precondition].inequality.name);
      EXPECT_GT(q.violations, 0u);  // the worst case is reached with positive probability
      EXPECT_GT(q.sigma, 0.0);
      EXPECT_LT(q.p_monte_carlo, 0.5);
      // The plan fails at least as often as its worst precondition.
      EXPECT_GE(p.p_plan, q.p_monte_carlo);
    }
    EXPECT_GE(failing, 2u);
  }
}

// A proved precondition's sampling is a self-check (P = 0 by soundness): the first tenth of the
// points. Unproved ones see every point, the same points as if all were sampled: their counts
// equal those of a run where nothing is proved (the verdicts cleared).
TEST(ProbabilitySeedPickup, ProvedPreconditionsAreCheckedOnATenthOfThePoints) {
  const PlanResult proved = plan(peg_pickup(), builtin_domain(), plan_options());
  const ProbabilityAnalysis all_proved =
      analyse_probability(*proved.chosen_analysis(), {.samples = 20'000});
  EXPECT_EQ(all_proved.samples, 2'000u);
  for (const PreconditionProbability& q : all_proved.preconditions) EXPECT_EQ(q.samples, 2'000u);

  PlanResult widened = plan(widened_without_sensor(), builtin_domain(), plan_options());
  ASSERT_FALSE(widened.examined.empty());
  InstanceAnalysis& chosen = widened.examined[choose_instance(widened.examined)];
  const ProbabilityAnalysis mixed = analyse_probability(chosen, {.samples = 20'000});
  EXPECT_EQ(mixed.samples, 20'000u);
  std::size_t checked = 0;
  for (const PreconditionProbability& q : mixed.preconditions) {
    EXPECT_EQ(q.samples, q.proved ? 2'000u : 20'000u);
    checked += q.proved ? 1 : 0;
  }
  EXPECT_GT(checked, 0u);
  std::vector<std::size_t> unproved_violations;
  for (const PreconditionProbability& q : mixed.preconditions)
    if (!q.proved) unproved_violations.push_back(q.violations);
  for (AnalysedStep& step : chosen.steps)
    for (PreconditionResult& result : step.preconditions)
      result.verdict = Verdict::kUndecided;  // everything sampled on every point
  const ProbabilityAnalysis unchecked = analyse_probability(chosen, {.samples = 20'000});
  std::vector<std::size_t> same;
  for (std::size_t k = 0; k < unchecked.preconditions.size(); ++k)
    if (!mixed.preconditions[k].proved) same.push_back(unchecked.preconditions[k].violations);
  EXPECT_EQ(same, unproved_violations);
  EXPECT_EQ(unchecked.plan_violations, mixed.plan_violations);
}

TEST(ProbabilitySeedPickup, GaussianFailsLessOftenThanUniformOnTheSameBox) {
  const auto plan_failure = [](Distribution distribution) {
    Scenario scenario = widened_without_sensor();
    ObjectSpec& peg = peg_of(scenario);
    peg.uncertainty_model.distribution = distribution;
    const kinematics::PoseUncertainty& h = peg.uncertainty;
    if (distribution == Distribution::kGaussian)
      peg.uncertainty_model.sigma = {h.dx / 3, h.dy / 3, h.dz / 3, h.dtheta / 3};
    const PlanResult result = plan(scenario, builtin_domain(), plan_options());
    return analyse_probability(*result.chosen_analysis(), {.samples = 20'000});
  };
  const ProbabilityAnalysis uniform = plan_failure(Distribution::kUniform);
  const ProbabilityAnalysis gaussian = plan_failure(Distribution::kGaussian);
  EXPECT_LT(gaussian.p_plan_ci_hi, uniform.p_plan_ci_lo);
}

// ---- sensor fusion ----

TEST(ProbabilityFusion, TwoGaussianReadingsEqualTheClosedForm) {
  Eigen::Matrix4d r1, r2;
  r1 << 4, 1, 0, 0, 1, 3, 0, 0, 0, 0, 2, 0.5, 0, 0, 0.5, 1;
  r2 << 1, 0, 0.2, 0, 0, 2, 0, 0, 0.2, 0, 1, 0, 0, 0, 0, 0.5;
  r1 *= 1e-6;
  r2 *= 1e-6;
  const Eigen::Vector4d z1(0.001, -0.002, 0.0005, 0.01), z2(0.0015, -0.001, 0.0, 0.008);
  const std::vector<PoseReading> readings = {{.object = 3,
                                              .estimate = z1,
                                              .covariance = r1,
                                              .half_width = Eigen::Vector4d::Constant(0.003)},
                                             {.object = 3,
                                              .estimate = z2,
                                              .covariance = r2,
                                              .half_width = Eigen::Vector4d::Constant(0.002)},
                                             {.object = 1,
                                              .estimate = z2,
                                              .covariance = r1,
                                              .half_width = Eigen::Vector4d::Constant(0.001)}};
  const Eigen::Matrix4d covariance = (r1.inverse() + r2.inverse()).inverse();
  const Eigen::Vector4d mean = covariance * (r1.inverse() * z1 + r2.inverse() * z2);
  for (const LinearAlgebra algebra : {LinearAlgebra::kSparse, LinearAlgebra::kDense}) {
    const std::vector<FusedPose> fused = fuse_readings(readings, algebra);
    ASSERT_EQ(fused.size(), 2u);
    EXPECT_EQ(fused[0].object, 1);
    EXPECT_EQ(fused[0].readings, 1);
    EXPECT_TRUE(fused[0].mean.isApprox(z2, 1e-12));
    EXPECT_TRUE(fused[0].covariance.isApprox(r1, 1e-12));
    EXPECT_EQ(fused[1].object, 3);
    EXPECT_EQ(fused[1].readings, 2);
    EXPECT_TRUE(fused[1].mean.isApprox(mean, 1e-12)) << fused[1].mean.transpose();
    EXPECT_TRUE(fused[1].covariance.isApprox(covariance, 1e-12)) << fused[1].covariance;
  }
}

TEST(ProbabilityFusion, WorstCaseIsTheIntersectionOfTheBoxes) {
  const std::vector<PoseReading> readings = {
      {.object = 0,
       .estimate = Eigen::Vector4d(0.0, 0.01, 0.0, 0.0),
       .covariance = Eigen::Matrix4d::Identity(),
       .half_width = Eigen::Vector4d(0.01, 0.01, 0.02, 0.1)},
      {.object = 0,
       .estimate = Eigen::Vector4d(0.005, 0.0, 0.0, 0.05),
       .covariance = Eigen::Matrix4d::Identity(),
       .half_width = Eigen::Vector4d(0.01, 0.02, 0.01, 0.1)}};
  const FusedPose fused = fuse_readings(readings).front();
  EXPECT_TRUE(fused.lower.isApprox(Eigen::Vector4d(-0.005, 0.0, -0.01, -0.05)));
  EXPECT_TRUE(fused.upper.isApprox(Eigen::Vector4d(0.01, 0.02, 0.01, 0.1)));
  EXPECT_TRUE(fused.consistent);
  std::vector<PoseReading> apart = readings;
  apart[1].estimate[0] = 0.05;  // boxes [-0.01, 0.01] and [0.04, 0.06] do not meet
  EXPECT_FALSE(fuse_readings(apart).front().consistent);
}

TEST(ProbabilityFusion, RefusesACovarianceThatIsNotPositiveDefinite) {
  PoseReading bad{.object = 2};
  bad.covariance(3, 3) = -1;
  try {
    (void)fuse_readings({&bad, 1});
    FAIL() << "no error";
  } catch (const PlanError& error) {
    EXPECT_STREQ(error.what(),
                 "fuse_readings: the covariance of a reading of object 2 is not positive definite");
  }
}

int action_with(const Domain& domain, Effect effect) {
  for (std::size_t a = 0; a < domain.actions.size(); ++a)
    if (domain.actions[a].effect == effect) return static_cast<int>(a);
  ADD_FAILURE() << "the domain has no action with that effect";
  return -1;
}

TEST(ProbabilityFusion, PhaseTwoFusesASecondScanOfAnUnmovedObject) {
  for (const Distribution distribution : {Distribution::kGaussian, Distribution::kUniform}) {
    Scenario scenario = peg_pickup();
    RangeScanSensor& sensor = *scenario.range_scan;
    sensor.residual_model.distribution = distribution;
    if (distribution == Distribution::kGaussian)
      sensor.residual_model.sigma = {0.004 * kInch, 0.005 * kInch, 0.006 * kInch, 0.2 * kDegree};
    const WorldModel world(scenario);
    symbolic::ExprPool pool;
    Propagation propagation(world, builtin_domain(), pool);
    const int block = world.object_index("block");
    const Phase2Step scan{.action = action_with(builtin_domain(), Effect::kSense),
                          .effect = Effect::kSense,
                          .object = block};
    (void)propagation.step(scan, 1);
    (void)propagation.step(scan, 2);
    const std::vector<SpaceVariable>& v = propagation.space().variables();
    // Initial errors of both objects (8), then two scans of 4.
    ASSERT_EQ(v.size(), 16u);
    const double sigmas[4] = {0.004 * kInch, 0.005 * kInch, 0.006 * kInch, 0.2 * kDegree};
    for (int c = 0; c < 4; ++c) {
      const SpaceVariable& first = v[8 + c];
      const SpaceVariable& second = v[12 + c];
      EXPECT_EQ(second.provenance.step, 2);
      EXPECT_EQ(second.lower, first.lower);  // the same sensor: the intersection is its box
      EXPECT_EQ(second.upper, first.upper);
      if (distribution == Distribution::kGaussian) {
        EXPECT_NEAR(first.sigma, sigmas[c], 1e-18);
        EXPECT_NEAR(second.sigma, sigmas[c] / std::sqrt(2.0), 1e-12 * sigmas[c]);
      } else {
        EXPECT_EQ(second.sigma, 0.0);
      }
    }
  }
}

// ---- tolerance allocation ----

TEST(ProbabilityTolerance, LinearRowGetsTheWeightedMinimumNormChange) {
  // 2 dx + dy <= 1 with h = (1, 1): worst case 3. Equal costs: δ ∝ (2, 1), 2δx + δy = 2 gives
  // δ = (0.8, 0.4), p = (0.2, 0.6); cost 4 on dx: δ = (0.5, 1), p = (0.5, 0).
  for (const LinearAlgebra algebra : {LinearAlgebra::kSparse, LinearAlgebra::kDense}) {
    Built built = hand_built({{"2*dx_g1 + dy_g1", {Relation::kLessEqual, 1.0}}}, 1.0, 1.0);
    ToleranceAllocation t =
        allocate_tolerances(built.scenario, built.analysis, {.algebra = algebra});
    EXPECT_EQ(t.status, AllocationStatus::kProved) << to_string(t.status);
    ASSERT_EQ(t.parameters.size(), 2u);
    EXPECT_EQ(t.parameters[0].name, "robot.dx");
    // (up to the margin ε = 1e-6 of the row's spread 3 that makes the margin positive)
    EXPECT_NEAR(t.parameters[0].allocated, 0.2, 1e-5);
    EXPECT_NEAR(t.parameters[1].allocated, 0.6, 1e-5);
    EXPECT_NEAR(t.cost, 0.8 * 0.8 + 0.4 * 0.4, 1e-4);
    built.scenario.robot.uncertainty_model.cost.dx = 4;
    t = allocate_tolerances(built.scenario, built.analysis, {.algebra = algebra});
    EXPECT_EQ(t.status, AllocationStatus::kProved);
    EXPECT_NEAR(t.parameters[0].allocated, 0.5, 1e-5);
    EXPECT_NEAR(t.parameters[1].allocated, 0.0, 1e-5);
    const Scenario applied = t.apply(built.scenario);
    EXPECT_EQ(applied.robot.uncertainty.dx, t.parameters[0].allocated);
  }
}

TEST(ProbabilityTolerance, NominalViolationIsInfeasibleAndProvedRowsNeedNothing) {
  Built infeasible = hand_built({{"dx_g1 + 2", {Relation::kLessEqual, 1.0}}}, 0.5, 0.5);
  const ToleranceAllocation t = allocate_tolerances(infeasible.scenario, infeasible.analysis);
  EXPECT_EQ(t.status, AllocationStatus::kInfeasible);
  ASSERT_EQ(t.misses.size(), 1u);
  EXPECT_NEAR(t.misses[0].by, 1.0, 1e-6);
  Built holds = hand_built({{"dx_g1 + dy_g1", {Relation::kLessEqual, 1.5}}}, 0.5, 0.5);
  EXPECT_EQ(allocate_tolerances(holds.scenario, holds.analysis).status,
            AllocationStatus::kNotNeeded);
}

TEST(ProbabilityTolerance, AllocatedToleranceMakesTheSeedPickupProvablyHold) {
  const Scenario scenario = widened_without_sensor();
  const PlanResult before = plan(scenario, builtin_domain(), plan_options());
  ASSERT_TRUE(before.planned());
  ASSERT_GT(before.chosen_analysis()->errors, 0);
  const ToleranceAllocation t = allocate_tolerances(scenario, *before.chosen_analysis());
  ASSERT_EQ(t.status, AllocationStatus::kProved) << to_string(t.status);
  EXPECT_TRUE(t.misses.empty());
  bool tightened = false;
  for (const ToleranceParameter& p : t.parameters) {
    EXPECT_LE(p.allocated, p.half_width) << p.name;
    EXPECT_GE(p.allocated, 0.0) << p.name;
    tightened = tightened || p.allocated < p.half_width;
  }
  EXPECT_TRUE(tightened);
  // Plugged back into the scenario, phase 2 proves every precondition of the plan.
  const PlanResult after = plan(t.apply(scenario), builtin_domain(), plan_options());
  ASSERT_TRUE(after.planned());
  const InstanceAnalysis& chosen = *after.chosen_analysis();
  EXPECT_EQ(chosen.errors, 0);
  for (const AnalysedStep& step : chosen.steps)
    for (const PreconditionResult& result : step.preconditions)
      EXPECT_EQ(result.verdict, Verdict::kSatisfied) << result.inequality.name;
  // The dense solver allocates the same.
  const ToleranceAllocation dense =
      allocate_tolerances(scenario, *before.chosen_analysis(), {.algebra = LinearAlgebra::kDense});
  ASSERT_EQ(dense.parameters.size(), t.parameters.size());
  for (std::size_t i = 0; i < t.parameters.size(); ++i)
    EXPECT_NEAR(dense.parameters[i].allocated, t.parameters[i].allocated,
                1e-6 * t.parameters[i].half_width);
}

// The rows are verified on several threads with the same result, round by round: on_back's
// insertion (two rounds, the second deciding both sides of a clearance at once).
TEST(ProbabilityTolerance, TheSameAllocationOnTwoThreadsAsOnOne) {
  const Scenario scenario =
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/peg_block_on_back.yaml");
  PlanOptions options = plan_options();
  options.max_instances = 1;
  const PlanResult result = plan(scenario, builtin_domain(), options);
  ASSERT_TRUE(result.planned());
  const ToleranceAllocation one =
      allocate_tolerances(scenario, *result.chosen_analysis(), {.threads = 1});
  const ToleranceAllocation two =
      allocate_tolerances(scenario, *result.chosen_analysis(), {.threads = 2});
  EXPECT_GE(one.rounds, 2);
  testing::expect_same_allocation(one, two);
}

}  // namespace
}  // namespace spar::planner
