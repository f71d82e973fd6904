// Step labels (Phase2Step::label, issue 24): while phase 2 searches, a step's variables are named
// after a label that does not move when a range-scan or squeeze is spliced in before it, so a
// replay rebuilds the same expressions and hits the DecisionCache. Soundness first: distinct steps
// never share a variable (a shared one would correlate two independent physical errors), not even
// when the same candidate is spliced in twice; and the analysis' result is numbered by execution
// position again, as the reports show the steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "spar/planner/plan.hpp"
#include "spar/symbolic/operations.hpp"

namespace spar::planner {
namespace {

// peg_block_on_back's first instance: pickup peg, putdown peg, pickup peg, assemble peg into the
// block (the insertion fails at Table 2's uncertainty, so phase 2 splices in a range-scan).
class OnBack : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new WorldModel(
        load_scenario(std::string(SPAR_SOURCE_DIR) + "/examples/peg_block_on_back.yaml"));
    const PlanFamily family = post_plan(*world_, builtin_domain());
    ASSERT_EQ(family.status, PostingStatus::kPlanned);
    instance_ = new PlanInstance(
        enumerate_instances(family, *world_, builtin_domain(), 1).instances.front());
  }
  static void TearDownTestSuite() {
    delete instance_;
    delete world_;
  }

  static int action_with(Effect effect) {
    const Domain& domain = builtin_domain();
    for (std::size_t a = 0; a < domain.actions.size(); ++a)
      if (domain.actions[a].effect == effect) return static_cast<int>(a);
    return -1;
  }
  static int insertion(const std::vector<Phase2Step>& steps) {
    for (std::size_t k = 0; k < steps.size(); ++k)
      if (steps[k].effect == Effect::kInsert) return static_cast<int>(k);
    return -1;
  }
  // `steps` spliced with every candidate of the insertion (scans and squeezes).
  static SplicedPlan with_every_candidate(const std::vector<Phase2Step>& steps) {
    const int k = insertion(steps);
    const RepairKinds kinds{.scan = action_with(Effect::kSense),
                            .squeeze = action_with(Effect::kReduce),
                            .squeeze_grasps = 4};
    const std::vector<RepairCandidate> candidates = repair_candidates(*world_, steps, k, kinds);
    return splice(steps, k, candidates, (1u << candidates.size()) - 1, kinds, 0);
  }

  static WorldModel* world_;
  static PlanInstance* instance_;
};
WorldModel* OnBack::world_ = nullptr;
PlanInstance* OnBack::instance_ = nullptr;

TEST_F(OnBack, AReplayWithAScanSplicedInReusesTheDecisionsOfStepsItDoesNotChange) {
  const std::vector<Phase2Step> steps = phase2_steps(builtin_domain(), *instance_);
  const int k = insertion(steps);
  ASSERT_GE(k, 0);
  const RepairKinds scanning{.scan = action_with(Effect::kSense)};
  const std::vector<RepairCandidate> scans = repair_candidates(*world_, steps, k, scanning);
  ASSERT_FALSE(scans.empty());
  ASSERT_EQ(scans.front().object, steps[k].fixed_object);  // the block, before the second pickup
  const SplicedPlan spliced = splice(steps, k, scans, 1u, scanning, 0);
  const int scan_at = spliced.inserted.front();
  ASSERT_LT(scan_at, spliced.failing - 1);  // an original step with preconditions lies between

  symbolic::ExprPool pool;
  const AnalysisOptions options;
  DecisionCache cache(options.quick, options.bound);
  Propagation plain(*world_, builtin_domain(), pool);
  for (const Phase2Step& step : steps)
    (void)cache.decide(plain.step(step, step.label), plain.space());
  Propagation replay(*world_, builtin_domain(), pool);
  int checked = 0;
  for (int i = 0; i < static_cast<int>(spliced.steps.size()); ++i) {
    const Phase2Step& step = spliced.steps[i];
    const std::vector<Precondition> built = replay.step(step, step.label);
    const std::size_t hits = cache.hits();
    const std::vector<PreconditionResult> results = cache.decide(built, replay.space());
    // After the scan, every original step's pickup preconditions are about the peg and the arm
    // only: the same expressions as without the scan, so decided from the cache.
    if (i <= scan_at || i == spliced.failing || built.empty()) continue;
    ++checked;
    EXPECT_EQ(cache.hits(), hits + 1) << "step " << i + 1 << " was decided again";
    // A hit returns what deciding in this space returns, with this space's variable ids.
    const std::vector<PreconditionResult> fresh =
        decide(built, replay.space(), options.quick, options.bound);
    ASSERT_EQ(results.size(), fresh.size());
    for (std::size_t j = 0; j < results.size(); ++j) {
      EXPECT_EQ(results[j].verdict, fresh[j].verdict);
      EXPECT_EQ(results[j].bound.lo, fresh[j].bound.lo);
      EXPECT_EQ(results[j].bound.hi, fresh[j].bound.hi);
      EXPECT_EQ(results[j].variables, fresh[j].variables);
    }
  }
  EXPECT_GE(checked, 1);
  // The insertion itself sees the scanned block: a new decision.
  EXPECT_LT(cache.hits(), spliced.steps.size());
}

// The repair search asks for verdicts only (Need::kVerdicts): on-back's insertion is violated at a
// witness before any box is bounded, and those preconditions keep the natural enclosure. Asked for
// bounds afterwards, the cache decides the step again: what deciding gives, never the looser
// entry; asked for verdicts again, it answers from the exact entry.
TEST_F(OnBack, AVerdictsOnlyDecisionIsNeverGivenForBounds) {
  const std::vector<Phase2Step> steps = phase2_steps(builtin_domain(), *instance_);
  const int k = insertion(steps);
  ASSERT_GE(k, 0);
  symbolic::ExprPool pool;
  const AnalysisOptions options;
  DecisionCache cache(options.quick, options.bound);
  Propagation state(*world_, builtin_domain(), pool);
  std::vector<Precondition> built;
  for (int i = 0; i <= k; ++i) built = state.step(steps[i], steps[i].label);
  const std::vector<PreconditionResult> fresh =
      decide(built, state.space(), options.quick, options.bound);
  const std::vector<PreconditionResult> verdicts =
      cache.decide(built, state.space(), Need::kVerdicts);
  ASSERT_EQ(verdicts.size(), fresh.size());
  int stopped = 0;
  for (std::size_t j = 0; j < fresh.size(); ++j) {
    EXPECT_EQ(verdicts[j].verdict, fresh[j].verdict);
    EXPECT_FALSE(fresh[j].bound.stopped_at_witness);
    if (!verdicts[j].bound.stopped_at_witness) continue;
    ++stopped;
    EXPECT_EQ(verdicts[j].verdict, bounds::Verdict::kViolated);
    EXPECT_EQ(verdicts[j].bound.evaluations, 0u);
    // Sound: the natural enclosure holds the values deciding attained.
    EXPECT_LE(verdicts[j].bound.lo, fresh[j].bound.inner_lo);
    EXPECT_GE(verdicts[j].bound.hi, fresh[j].bound.inner_hi);
  }
  EXPECT_GE(stopped, 1) << "no precondition stopped at a witness: the test checks nothing";
  EXPECT_EQ(cache.misses(), 1u);
  const std::vector<PreconditionResult> bounded = cache.decide(built, state.space());
  EXPECT_EQ(cache.misses(), 2u);  // decided again
  ASSERT_EQ(bounded.size(), fresh.size());
  for (std::size_t j = 0; j < fresh.size(); ++j) {
    EXPECT_EQ(bounded[j].verdict, fresh[j].verdict);
    EXPECT_EQ(bounded[j].bound.lo, fresh[j].bound.lo);
    EXPECT_EQ(bounded[j].bound.hi, fresh[j].bound.hi);
    EXPECT_EQ(bounded[j].bound.inner_lo, fresh[j].bound.inner_lo);
    EXPECT_EQ(bounded[j].bound.inner_hi, fresh[j].bound.inner_hi);
    EXPECT_EQ(bounded[j].witness, fresh[j].witness);
  }
  const std::size_t hits = cache.hits();
  const std::vector<PreconditionResult> again = cache.decide(built, state.space(), Need::kVerdicts);
  EXPECT_EQ(cache.hits(), hits + 1);
  for (std::size_t j = 0; j < fresh.size(); ++j) EXPECT_EQ(again[j].bound.hi, fresh[j].bound.hi);
}

TEST_F(OnBack, DistinctStepsHaveDistinctArmVariablesEvenWithACandidateSplicedInTwice) {
  const SplicedPlan once = with_every_candidate(phase2_steps(builtin_domain(), *instance_));
  // The sensor margin splices the insertion's scans again over a kept set: the same labels twice.
  const SplicedPlan twice = with_every_candidate(once.steps);
  ASSERT_GT(twice.steps.size(), once.steps.size());
  symbolic::ExprPool pool;
  Propagation propagation(*world_, builtin_domain(), pool);
  std::vector<std::set<unsigned>> arm_of_step;  // symbol ids of each step's own arm error
  for (const Phase2Step& step : twice.steps) {
    const std::size_t before = propagation.space().size();
    (void)propagation.step(step, step.label);
    std::set<unsigned> arm;
    for (std::size_t v = before; v < propagation.space().size(); ++v) {
      const SpaceVariable& variable = propagation.space().variables()[v];
      if (of_the_arm(variable.provenance.source)) arm.insert(propagation.space().symbols()[v].id());
    }
    if (moves_arm(step.effect)) {
      EXPECT_EQ(arm.size(), 4u);
    }
    arm_of_step.push_back(arm);
  }
  for (std::size_t a = 0; a < arm_of_step.size(); ++a)
    for (std::size_t b = a + 1; b < arm_of_step.size(); ++b)
      for (const unsigned id : arm_of_step[a])
        EXPECT_FALSE(arm_of_step[b].contains(id)) << "steps " << a + 1 << " and " << b + 1;
  // No two variables of the space share a symbol or a name.
  std::set<unsigned> symbols;
  std::set<std::string> names;
  for (std::size_t v = 0; v < propagation.space().size(); ++v) {
    symbols.insert(propagation.space().symbols()[v].id());
    names.insert(propagation.space().variables()[v].name);
  }
  EXPECT_EQ(symbols.size(), propagation.space().size());
  EXPECT_EQ(names.size(), propagation.space().size());
}

TEST_F(OnBack, TheAnalysisNumbersItsVariablesByExecutionPosition) {
  AnalysisOptions options;
  options.reverse = false;
  const InstanceAnalysis analysis =
      analyse_instance(*world_, builtin_domain(), *instance_, options);
  ASSERT_FALSE(analysis.repairs.empty());  // a range-scan was spliced in: labels != positions
  EXPECT_GT(analysis.steps_reused, 0u);
  std::set<std::string> names;
  for (const SpaceVariable& variable : analysis.variables) names.insert(variable.name);
  EXPECT_EQ(names.size(), analysis.variables.size());
  for (std::size_t i = 0; i < analysis.steps.size(); ++i) {
    const int position = static_cast<int>(i) + 1;
    const std::vector<PreconditionResult>& results = analysis.steps[i].preconditions;
    if (results.empty()) continue;
    // The expressions' variables are the step's, by symbol, and the step's own arm error is named
    // and numbered after its position.
    std::vector<symbolic::Expr> expressions;
    for (const PreconditionResult& result : results)
      expressions.push_back(result.inequality.expression);
    std::vector<VariableId> ids;
    for (const symbolic::Expr v : symbolic::free_variables(expressions)) {
      const auto found = std::find(analysis.symbols.begin(), analysis.symbols.end(), v);
      ASSERT_NE(found, analysis.symbols.end()) << v.name();
      ids.push_back({static_cast<std::uint32_t>(found - analysis.symbols.begin())});
    }
    std::sort(ids.begin(), ids.end());
    EXPECT_EQ(ids, results.front().variables);
    bool own_arm = false;
    for (const VariableId id : ids) {
      const SpaceVariable& variable = analysis.variables[id.index];
      EXPECT_LE(variable.provenance.step, position);
      if (variable.provenance.source == UncertaintySource::kManipulator &&
          variable.provenance.step == position) {
        own_arm = true;
        EXPECT_NE(variable.name.find("_g" + std::to_string(position)), std::string::npos)
            << variable.name;
      }
    }
    EXPECT_TRUE(own_arm) << "step " << position;
  }
}

}  // namespace
}  // namespace spar::planner
