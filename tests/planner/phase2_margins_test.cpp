// The chosen instance's margins (planner/uncertainty/margins.hpp): computed on copies of the
// expressions in pools of their own, they equal what the analysis' own pool gives, and they are
// the same on one thread and on several (every field, bit for bit).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/planner/plan.hpp"

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

TEST(Margins, TheSameOnTwoThreadsAsOnOne) {
  for (const char* example : {"peg_block_on_back", "peg_block_on_sides"}) {
    const Analysed analysed(example);
    InstanceAnalysis one = analysed.analyse(), two = analysed.analyse();
    AnalysisOptions options = analysed.options;
    options.threads = 1;
    add_margins(one, options);
    options.threads = 2;
    add_margins(two, options);
    ASSERT_EQ(one.steps.size(), two.steps.size());
    for (std::size_t k = 0; k < one.steps.size(); ++k) {
      ASSERT_EQ(one.steps[k].preconditions.size(), two.steps[k].preconditions.size());
      for (std::size_t i = 0; i < one.steps[k].preconditions.size(); ++i) {
        const PreconditionResult& a = one.steps[k].preconditions[i];
        const PreconditionResult& b = two.steps[k].preconditions[i];
        const std::string where = std::string(example) + " step " + std::to_string(k + 1) +
                                  " precondition " + std::to_string(i + 1);
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

}  // namespace
}  // namespace spar::planner
