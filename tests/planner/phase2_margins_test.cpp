// Phase 2 on several threads: the chosen instance's margins (planner/uncertainty/margins.hpp),
// computed on copies of the expressions in pools of their own, equal what the analysis' own pool
// gives, and they, like the instances analyse_instances examines and plan()'s probability and
// tolerance allocation run beside the margins (ProbabilityWork), are the same on one thread and
// on several (every field, bit for bit).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/common/parallel.hpp"
#include "spar/planner/error.hpp"
#include "spar/planner/plan.hpp"
#include "tests/planner/same_results.hpp"

namespace spar::planner {
namespace {

// The first instance of an example, analysed with the default options (fewer Monte Carlo points).
struct Analysed {
  explicit Analysed(const std::string& example)
      : world(load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/" + example + ".yaml")) {
    const PlanFamily family = post_plan(world, builtin_domain());
    EXPECT_EQ(family.status, PostingStatus::kPlanned);
    instance = enumerate_instances(family, world, builtin_domain(), 1).instances.front();
    options.samples = 300;
  }
  [[nodiscard]] InstanceAnalysis analyse() const {
    return analyse_instance(world, builtin_domain(), instance, options);
  }
  WorldModel world;
  PlanInstance instance;
  AnalysisOptions options;
};

void expect_same_bound(const bounds::BoundResult& a, const bounds::BoundResult& b,
                       const std::string& where) {
  EXPECT_EQ(a.lo, b.lo) << where;
  EXPECT_EQ(a.hi, b.hi) << where;
  EXPECT_EQ(a.inner_lo, b.inner_lo) << where;
  EXPECT_EQ(a.inner_hi, b.inner_hi) << where;
  EXPECT_EQ(a.argmin, b.argmin) << where;
  EXPECT_EQ(a.argmax, b.argmax) << where;
  EXPECT_EQ(a.status, b.status) << where;
  EXPECT_EQ(a.evaluations, b.evaluations) << where;
}

// Every result field of two analyses of one instance, bit for bit.
void expect_same_analysis(const InstanceAnalysis& one, const InstanceAnalysis& two,
                          const std::string& name) {
  EXPECT_EQ(one.errors, two.errors) << name;
  EXPECT_EQ(one.sensor_margins_pending, two.sensor_margins_pending) << name;
  ASSERT_EQ(one.steps.size(), two.steps.size()) << name;
  for (std::size_t k = 0; k < one.steps.size(); ++k) {
    EXPECT_EQ(one.steps[k].sensor_scale_needed, two.steps[k].sensor_scale_needed)
        << name << " step " << k + 1;
    ASSERT_EQ(one.steps[k].preconditions.size(), two.steps[k].preconditions.size()) << name;
    for (std::size_t i = 0; i < one.steps[k].preconditions.size(); ++i) {
      const PreconditionResult& a = one.steps[k].preconditions[i];
      const PreconditionResult& b = two.steps[k].preconditions[i];
      const std::string where =
          name + " step " + std::to_string(k + 1) + " precondition " + std::to_string(i + 1);
      EXPECT_EQ(a.verdict, b.verdict) << where;
      expect_same_bound(a.bound, b.bound, where);
      EXPECT_EQ(a.witness, b.witness) << where;
      ASSERT_EQ(a.blame.size(), b.blame.size()) << where;
      for (std::size_t v = 0; v < a.blame.size(); ++v) {
        EXPECT_EQ(a.blame[v].variable, b.blame[v].variable) << where;
        EXPECT_EQ(a.blame[v].share, b.blame[v].share) << where;
      }
      EXPECT_EQ(a.holds_up_to_scale, b.holds_up_to_scale) << where;
      EXPECT_EQ(a.monte_carlo_violation, b.monte_carlo_violation) << where;
      EXPECT_EQ(a.monte_carlo_samples, b.monte_carlo_samples) << where;
    }
  }
}

TEST(Margins, TheSameOnTwoThreadsAsOnOne) {
  for (const char* example : {"peg_block_on_back", "peg_block_on_sides"}) {
    const Analysed analysed(example);
    InstanceAnalysis one = analysed.analyse(), two = analysed.analyse();
    AnalysisOptions options = analysed.options;
    options.threads = 1;
    add_margins(one, options);
    options.threads = 2;
    add_margins(two, options);
    expect_same_analysis(one, two, example);
  }
}

// plan() examines instances without their sensor margins and adds the chosen one's: they are
// what the analysis gives (on_back's first instance: its insertion fails, a finer range-scan
// would repair it).
TEST(SensorMargins, AddedLaterTheyAreWhatTheAnalysisGives) {
  const Analysed analysed("peg_block_on_back");
  const InstanceAnalysis at_once = analysed.analyse();
  AnalysisOptions deferring = analysed.options;
  deferring.defer_sensor_margins = true;
  InstanceAnalysis later =
      analyse_instance(analysed.world, builtin_domain(), analysed.instance, deferring);
  std::size_t margins = 0;
  for (std::size_t k = 0; k < later.steps.size(); ++k) {
    EXPECT_FALSE(later.steps[k].sensor_scale_needed.has_value()) << "step " << k + 1;
    margins += at_once.steps[k].sensor_scale_needed.has_value() ? 1 : 0;
  }
  ASSERT_GE(margins, 1u);  // the case under test
  add_sensor_margins(analysed.world, builtin_domain(), later, deferring);
  expect_same_analysis(at_once, later, "peg_block_on_back");
  // An analysis analyse_instance did not make has no pool to propagate in: an error, no crash.
  InstanceAnalysis empty;
  try {
    add_sensor_margins(analysed.world, builtin_domain(), empty, deferring);
    FAIL() << "no error for an analysis without a pool";
  } catch (const PlanError& e) {
    EXPECT_NE(std::string(e.what()).find("no expression pool"), std::string::npos) << e.what();
  }
}

// on_back's instances (three, all with an error), analysed by analyse_instances on one thread
// and on two with `options` (samples 300).
struct OnBackExamined {
  explicit OnBackExamined(AnalysisOptions options)
      : world(load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/peg_block_on_back.yaml")) {
    const PlanFamily family = post_plan(world, builtin_domain());
    EXPECT_EQ(family.status, PostingStatus::kPlanned);
    const std::vector<PlanInstance> instances =
        enumerate_instances(family, world, builtin_domain(), 16).instances;
    options.samples = 300;
    options.threads = 1;
    one = analyse_instances(world, builtin_domain(), instances, options);
    options.threads = 2;
    two = analyse_instances(world, builtin_domain(), instances, options);
  }
  WorldModel world;
  std::vector<InstanceAnalysis> one, two;
};

// After the first instance, two threads analyse the other two at once, and the examined list is
// the one a single thread gives.
TEST(AnalyseInstances, TheSameOnTwoThreadsAsOnOne) {
  const OnBackExamined examined{AnalysisOptions{}};
  ASSERT_GE(examined.one.size(), 3u);  // the case under test: more than the first examined
  ASSERT_EQ(examined.one.size(), examined.two.size());
  for (std::size_t n = 0; n < examined.one.size(); ++n) {
    EXPECT_EQ(examined.one[n].instance, examined.two[n].instance);
    expect_same_analysis(examined.one[n], examined.two[n],
                         "instance " + std::to_string(examined.one[n].instance));
  }
}

// Deferring the sensor margins as plan() does, two threads add the leading instance's in the
// round after it (the first instance, whose insertion fails, while the other two are analysed);
// they are what add_sensor_margins gives it afterwards on one thread, and the instances analysed
// in that round stay pending.
TEST(AnalyseInstances, TwoThreadsAddTheLeadersSensorMarginsAsOneThreadLater) {
  AnalysisOptions deferring;
  deferring.defer_sensor_margins = true;
  OnBackExamined examined(deferring);
  std::vector<InstanceAnalysis>& one = examined.one;
  const std::vector<InstanceAnalysis>& two = examined.two;
  ASSERT_EQ(one.size(), 3u);  // the case under test: one round of two after the first
  ASSERT_EQ(two.size(), 3u);
  for (const InstanceAnalysis& analysis : one) EXPECT_TRUE(analysis.sensor_margins_pending);
  EXPECT_FALSE(two[0].sensor_margins_pending);
  EXPECT_TRUE(two[1].sensor_margins_pending);
  EXPECT_TRUE(two[2].sensor_margins_pending);
  std::size_t margins = 0;
  for (const AnalysedStep& step : two[0].steps) margins += step.sensor_scale_needed ? 1 : 0;
  EXPECT_GE(margins, 1u);
  add_sensor_margins(examined.world, builtin_domain(), one[0], deferring);
  for (std::size_t n = 0; n < one.size(); ++n)
    expect_same_analysis(one[n], two[n], "instance " + std::to_string(one[n].instance));
}

// The copies bound as the originals do: each tight bound equals a BoundProblem's over the
// expression in the analysis' own pool (on_back: its insertion's clearances need hundreds of
// boxes, so every stage of the bound runs).
TEST(Margins, ACopiedExpressionBoundsAsTheOriginal) {
  const Analysed analysed("peg_block_on_back");
  InstanceAnalysis analysis = analysed.analyse();
  AnalysisOptions options = analysed.options;
  options.samples = 0;
  options.reverse = false;
  add_margins(analysis, options);
  int compared = 0;
  for (std::size_t k = 0; k < analysis.steps.size(); ++k)
    for (const PreconditionResult& result : analysis.steps[k].preconditions) {
      std::vector<symbolic::Expr> inputs;
      for (const VariableId id : result.variables) inputs.push_back(analysis.symbols[id.index]);
      bounds::BoundProblem original(result.inequality.expression, inputs);
      expect_same_bound(original.bound(result.box, options.report), result.bound,
                        "step " + std::to_string(k + 1));
      ++compared;
    }
  EXPECT_GT(compared, 10);
}

void expect_same_probability(const ProbabilityAnalysis& a, const ProbabilityAnalysis& b) {
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.plan_violations, b.plan_violations);
  EXPECT_EQ(a.p_plan, b.p_plan);
  ASSERT_EQ(a.preconditions.size(), b.preconditions.size());
  for (std::size_t k = 0; k < a.preconditions.size(); ++k) {
    const PreconditionProbability& p = a.preconditions[k];
    const PreconditionProbability& q = b.preconditions[k];
    const std::string where = "row " + std::to_string(k);
    EXPECT_EQ(p.sigma, q.sigma) << where;
    EXPECT_EQ(p.p_first_order, q.p_first_order) << where;
    EXPECT_EQ(p.p_second_order, q.p_second_order) << where;
    EXPECT_EQ(p.samples, q.samples) << where;
    EXPECT_EQ(p.violations, q.violations) << where;
    EXPECT_EQ(p.note, q.note) << where;
  }
}

// ProbabilityWork's parts, run at once on two threads beside nothing else, give what
// analyse_probability and allocate_tolerances give. On on_back's first instance (an error: some
// preconditions unproved) the allocation verifies rounds and the Monte Carlo samples them all.
TEST(ProbabilityWork, GivesWhatTheTwoFunctionsGive) {
  const Analysed analysed("peg_block_on_back");
  InstanceAnalysis analysis = analysed.analyse();
  AnalysisOptions options = analysed.options;
  add_margins(analysis, options);
  const ProbabilityOptions probability{.samples = 3'000};
  const Scenario& scenario = analysed.world.scenario();
  const ProbabilityAnalysis expected = analyse_probability(analysis, probability);
  const ToleranceAllocation allocated = allocate_tolerances(scenario, analysis);
  ASSERT_GT(allocated.rounds, 0);
  ASSERT_GT(expected.plan_violations, 0u);

  ProbabilityWork work(scenario, analysis, probability, {});
  run_tasks(2, 2, [&](std::size_t t) { t == 0 ? work.allocate() : work.sample(); });
  expect_same_probability(work.probability(), expected);
  testing::expect_same_allocation(work.tolerances(), allocated);
}

TEST(ProbabilityWork, APartAskedBeforeItRanIsAnError) {
  const Analysed analysed("peg_block_on_back");
  InstanceAnalysis analysis = analysed.analyse();
  const ProbabilityWork work(analysed.world.scenario(), analysis, {.samples = 100}, {});
  EXPECT_THROW((void)work.probability(), PlanError);
  EXPECT_THROW((void)work.tolerances(), PlanError);
}

// plan() runs the margins, the Monte Carlo and the allocation as one list of tasks: on two
// threads its chosen analysis, probability and allocation are one thread's, bit for bit.
TEST(Plan, TheSameExtrasOnTwoThreadsAsOnOne) {
  const Scenario scenario =
      load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/peg_block_on_back.yaml");
  PlanOptions options;
  options.analysis.samples = 300;
  options.probability->samples = 3'000;
  options.threads = 1;
  const PlanResult one = plan(scenario, builtin_domain(), options);
  options.threads = 2;
  const PlanResult two = plan(scenario, builtin_domain(), options);
  ASSERT_NE(one.chosen_analysis(), nullptr);
  ASSERT_NE(two.chosen_analysis(), nullptr);
  expect_same_analysis(*one.chosen_analysis(), *two.chosen_analysis(), "chosen");
  ASSERT_TRUE(one.probability && two.probability && one.tolerances && two.tolerances);
  expect_same_probability(*one.probability, *two.probability);
  testing::expect_same_allocation(*one.tolerances, *two.tolerances);
}

}  // namespace
}  // namespace spar::planner
