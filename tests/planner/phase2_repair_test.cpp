// The repair search (planner/uncertainty/repair.hpp, issue 24): a kept repair set turns verdicts,
// every inserted step says which, dropped candidates are counted, and better parts never give a
// worse plan: shrinking uncertainty half-widths never raises the chosen plan's error count or its
// number of violated preconditions (peg_block_on_sides with every half-width halved was the
// regression: "errors 1, 4 violated" where Table 2's widths gave none).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <bit>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "spar/planner/plan.hpp"
#include "spar/planner/uncertainty/repair.hpp"
#include "tests/planner/plan_options.hpp"

namespace spar::planner {
namespace {

using testing::example;

const char* const kExampleNames[] = {"peg_block_face_down", "peg_block_on_sides",
                                     "peg_block_face_up", "peg_block_on_back"};

kinematics::PoseUncertainty scaled(kinematics::PoseUncertainty u, double by) {
  u.dx *= by;
  u.dy *= by;
  u.dz *= by;
  u.dtheta *= by;
  return u;
}

// Which half-widths a shrink applies to.
enum class Block { kObjects, kRobot, kSensor, kAll };

Scenario shrunk(Scenario scenario, Block block, double by) {
  if (block == Block::kObjects || block == Block::kAll)
    for (ObjectSpec& object : scenario.objects) {
      object.uncertainty = scaled(object.uncertainty, by);
      object.uncertainty_model.sigma = scaled(object.uncertainty_model.sigma, by);
    }
  if (block == Block::kRobot || block == Block::kAll) {
    scenario.robot.uncertainty = scaled(scenario.robot.uncertainty, by);
    scenario.robot.uncertainty_model.sigma = scaled(scenario.robot.uncertainty_model.sigma, by);
  }
  if ((block == Block::kSensor || block == Block::kAll) && scenario.range_scan) {
    scenario.range_scan->residual = scaled(scenario.range_scan->residual, by);
    scenario.range_scan->residual_model.sigma =
        scaled(scenario.range_scan->residual_model.sigma, by);
  }
  return scenario;
}

struct Outcome {
  int errors{0};
  int violated{0};
};

Outcome outcome_of(const Scenario& scenario) {
  PlanOptions options = testing::quick_options(2);
  options.probability.reset();
  const PlanResult result = plan(scenario, builtin_domain(), options);
  Outcome out;
  const InstanceAnalysis* chosen = result.chosen_analysis();
  if (chosen == nullptr) return out;
  out.errors = chosen->errors;
  for (const AnalysedStep& step : chosen->steps)
    for (const PreconditionResult& p : step.preconditions)
      out.violated += p.verdict == bounds::Verdict::kViolated;
  return out;
}

TEST(Phase2Repair, HalvingEveryHalfWidthOfOnSidesIsNoWorseThanTable2) {
  const Scenario table2 = example("peg_block_on_sides");
  const Outcome at_table2 = outcome_of(table2);
  const Outcome halved = outcome_of(shrunk(table2, Block::kAll, 0.5));
  EXPECT_EQ(at_table2.errors, 0);
  EXPECT_LE(halved.errors, at_table2.errors);
  EXPECT_LE(halved.violated, at_table2.violated);
  // Only the objects' widths halved (the case the greedy repair got wrong).
  const Outcome objects_halved = outcome_of(shrunk(table2, Block::kObjects, 0.5));
  EXPECT_LE(objects_halved.errors, at_table2.errors);
  EXPECT_LE(objects_halved.violated, at_table2.violated);
}

// The property's counterexample at seed 99 (2026-12-05): with every half-width x1.1 the block's
// pickup is repaired by an early scan and the plan holds; with the objects x0.4 more that pickup
// holds, the block is scanned only where it was put down, and replacing its 0.063 deg putdown
// rotation by the scanner's 1.1 deg residual left the u2 offsets violated (1 error). A scan now
// corrects only the components it knows better (Propagation::sense).
TEST(Phase2Repair, ScanningThePutDownBlockNeverLoosensWhatThePutdownKnew) {
  const Scenario wider = shrunk(example("peg_block_on_sides"), Block::kAll, 1.1);
  const Outcome before = outcome_of(wider);
  const Outcome after = outcome_of(shrunk(wider, Block::kObjects, 0.4));
  EXPECT_EQ(before.errors, 0);
  EXPECT_LE(after.errors, before.errors);
  EXPECT_LE(after.violated, before.violated);
}

TEST(Phase2Repair, EveryInsertedStepTurnedAVerdictAndDroppedOnesAreCounted) {
  for (const char* name : kExampleNames) {
    SCOPED_TRACE(name);
    const PlanResult result = plan(example(name), builtin_domain(), testing::quick_options(2));
    ASSERT_TRUE(result.planned());
    const InstanceAnalysis& chosen = *result.chosen_analysis();
    for (const AnalysedStep& step : chosen.steps) {
      if (!step.inserted) continue;
      ASSERT_GE(step.step.repair, 0) << step.action;
      ASSERT_LT(step.step.repair, static_cast<int>(chosen.repairs.size()));
      const RepairAttempt& record = chosen.repairs[step.step.repair];
      EXPECT_TRUE(record.helped);
      EXPECT_FALSE(record.turned.empty()) << step.action << ": a kept insertion turned nothing";
      // Each verdict it turned is satisfied in the final plan.
      for (const PreconditionRef& ref : record.turned) {
        const auto target =
            std::find_if(chosen.steps.begin(), chosen.steps.end(), [&](const AnalysedStep& s) {
              return !s.inserted && s.step.instance_step == ref.instance_step;
            });
        ASSERT_NE(target, chosen.steps.end());
        ASSERT_LT(ref.index, static_cast<int>(target->preconditions.size()));
        EXPECT_EQ(target->preconditions[ref.index].verdict, bounds::Verdict::kSatisfied);
      }
    }
    int kept = 0;
    for (const RepairSearch& search : chosen.repair_searches) {
      int dropped = 0;
      for (const auto& [kind, count] : search.dropped) {
        EXPECT_TRUE(kind == "range-scan" || kind == "squeeze") << kind;
        dropped += count;
      }
      EXPECT_EQ(search.kept + dropped, search.candidates);
      EXPECT_GE(search.sets_tried, search.kept > 0 ? 1 : 0);
      kept += search.kept;
    }
    EXPECT_EQ(kept, static_cast<int>(chosen.repairs.size()));
  }
}

// The sorted candidate indices of a set (SPAR's order compares these lexicographically).
std::vector<int> members(unsigned set) {
  std::vector<int> out;
  for (int i = 0; set >> i; ++i)
    if (set >> i & 1u) out.push_back(i);
  return out;
}

// choose_repair against an exhaustive reference over random scores that are monotone as the real
// ones are (repair.hpp: adding a sensing candidate never makes a set's score worse nor an
// admissible set inadmissible; a set without a squeeze is admissible): the kept set is the
// admissible one with the best score strictly better than no repair, the smallest of those, the
// earliest in SPAR's order among equals; the search may stop early but never tries more than
// every set, and never keeps a set with two squeezes.
// One random instance of the property below.
void choose_as_the_exhaustive_search() {
  const int n = *rc::gen::inRange(1, 7);
  std::vector<RepairCandidate> candidates(n);
  for (RepairCandidate& c : candidates)
    c.effect = *rc::gen::element(Effect::kSense, Effect::kSense, Effect::kReduce);
  RepairScore baseline;
  baseline.failed = 1;
  baseline.unsatisfied = *rc::gen::inRange(1, 4);
  const auto squeezes = [&](unsigned set) {
    int count = 0;
    for (const int i : members(set)) count += candidates[i].effect == Effect::kReduce;
    return count;
  };
  std::map<unsigned, RepairScore> scores = {{0u, baseline}};  // every set, drawn up front
  std::vector<unsigned> by_size;
  for (unsigned set = 1; set < (1u << n); ++set) by_size.push_back(set);
  std::stable_sort(by_size.begin(), by_size.end(),
                   [](unsigned a, unsigned b) { return std::popcount(a) < std::popcount(b); });
  for (const unsigned set : by_size) {
    RepairScore score;
    score.admissible = squeezes(set) == 0 || *rc::gen::inRange(0, 5) > 0;
    score.unsatisfied = *rc::gen::inRange(0, 4);
    // No worse than the set without any one of its sensing candidates.
    for (const int i : members(set)) {
      if (candidates[i].effect == Effect::kReduce) continue;
      const RepairScore& fewer = scores.at(set & ~(1u << i));
      score.unsatisfied = std::min(score.unsatisfied, fewer.unsatisfied);
      score.admissible = score.admissible || fewer.admissible;
    }
    score.failed = score.unsatisfied > 0 ? 1 : 0;
    scores[set] = score;
  }
  unsigned expected = 0;
  const auto key = [&](unsigned set) {
    const RepairScore& score = set == 0 ? baseline : scores.at(set);
    return std::tuple(score.failed, score.unsatisfied, std::popcount(set), members(set));
  };
  int valid_sets = 0;
  for (unsigned set = 1; set < (1u << n); ++set) {
    if (squeezes(set) > 1) continue;
    ++valid_sets;
    const RepairScore& score = scores.at(set);
    if (!score.admissible || !score.better_than(baseline)) continue;
    if (expected == 0 || key(set) < key(expected)) expected = set;
  }
  std::set<unsigned> evaluated;
  const RepairChoice choice =
      choose_repair(candidates, baseline, [&](unsigned set, ScoreDepth depth) {
        RC_ASSERT(squeezes(set) <= 1);
        evaluated.insert(set);
        const RepairScore& score = scores.at(set);
        if (depth == ScoreDepth::kSettles && !(score.admissible && score.unsatisfied == 0))
          return RepairScore::not_settling();
        return score;
      });
  RC_ASSERT(choice.set == expected);
  RC_ASSERT(choice.sets_tried == static_cast<int>(evaluated.size()));
  RC_ASSERT(!choice.score.partial);
  RC_ASSERT(choice.sets_tried <= valid_sets);
  RC_ASSERT(choice.turned.size() == static_cast<std::size_t>(std::popcount(expected)));
}

// This binary runs few cases per property (its others plan whole scenes): each case checks 50
// instances, which finds a search that stops too early (dropping the squeezes from the maximal
// sets) within the first few cases.
RC_GTEST_PROP(Phase2RepairSearch, ChoosesWhatTheExhaustiveSearchChooses, ()) {
  for (int instance = 0; instance < 50; ++instance) choose_as_the_exhaustive_search();
}

// on_back's insertion, in miniature: two range-scans and four squeezes, the first scan turning
// one of two verdicts and no set doing better. The two scans alone, then the five maximal sets
// (both scans, without a squeeze or with one: scored before the first squeeze) show that nothing
// can settle the step, so the squeezes are scored in full; nothing beats the first scan, so the
// search stops after the sets of size 1: 11 sets, not the 19 valid ones.
TEST(Phase2RepairSearch, StopsWhenNoSetCanBeatTheKeptOne) {
  std::vector<RepairCandidate> candidates(6, RepairCandidate{.effect = Effect::kReduce});
  candidates[0].effect = candidates[1].effect = Effect::kSense;
  RepairScore baseline;
  baseline.failed = 1;
  baseline.unsatisfied = 2;
  std::vector<unsigned> tried;
  const RepairChoice choice =
      choose_repair(candidates, baseline, [&](unsigned set, ScoreDepth depth) {
        EXPECT_EQ(depth, ScoreDepth::kFull) << set;
        tried.push_back(set);
        RepairScore score = baseline;
        if (set & 1u) score.unsatisfied = 1;  // with the first scan, one verdict turned
        return score;
      });
  EXPECT_EQ(choice.set, 1u);
  EXPECT_EQ(choice.score.unsatisfied, 1);
  EXPECT_EQ(choice.sets_tried, 11);
  EXPECT_EQ(tried, (std::vector<unsigned>{1u, 2u, 3u, 7u, 11u, 19u, 35u, 4u, 8u, 16u, 32u}));
}

// The seed instances' insertions, in miniature: two range-scans and three squeezes; neither scan
// alone settles the step (each turns one of two verdicts), both do. Once the maximal set (both
// scans) is known to settle it, only a set that settles can be kept, so each squeeze is scored
// only as far as whether it settles (a partial score); the scans, subsets of the kept set, are
// scored in full, and each kept scan turned what the other alone left unsatisfied.
TEST(Phase2RepairSearch, WhereASetSettlesTheStepSqueezesAreScoredOnlyThatFar) {
  std::vector<RepairCandidate> candidates(5, RepairCandidate{.effect = Effect::kReduce});
  candidates[0].effect = candidates[1].effect = Effect::kSense;
  const PreconditionRef first{.instance_step = 2, .index = 0},
      second{.instance_step = 2, .index = 1};
  RepairScore baseline{
      .failed = 1, .unsatisfied = 2, .satisfied = {{first, false}, {second, false}}};
  std::vector<std::pair<unsigned, ScoreDepth>> tried;
  const RepairChoice choice =
      choose_repair(candidates, baseline, [&](unsigned set, ScoreDepth depth) {
        tried.emplace_back(set, depth);
        RepairScore score = baseline;
        score.satisfied[first] = (set & 1u) != 0;
        score.satisfied[second] = (set & 2u) != 0;
        score.unsatisfied = !score.satisfied[first] + !score.satisfied[second];
        score.failed = score.unsatisfied > 0;
        if (depth == ScoreDepth::kSettles && score.unsatisfied > 0)
          return RepairScore::not_settling();
        return score;
      });
  EXPECT_EQ(choice.set, 3u);
  EXPECT_EQ(choice.score.unsatisfied, 0);
  EXPECT_EQ(choice.sets_tried, 6);
  using enum ScoreDepth;
  EXPECT_EQ(
      tried,
      (std::vector<std::pair<unsigned, ScoreDepth>>{
          {1u, kFull}, {2u, kFull}, {3u, kFull}, {4u, kSettles}, {8u, kSettles}, {16u, kSettles}}));
  ASSERT_EQ(choice.turned.size(), 2U);
  EXPECT_EQ(choice.turned[0], (std::vector<PreconditionRef>{first}));
  EXPECT_EQ(choice.turned[1], (std::vector<PreconditionRef>{second}));
}

// Property: shrinking the half-widths of one block (objects, robot, sensor or all) by a factor
// in (0, 1) at a base scale in [0.1, 2] never raises the errors or the violated count.
RC_GTEST_PROP(Phase2RepairProperty, ShrinkingUncertaintyNeverMakesThePlanWorse, ()) {
  const std::string name = *rc::gen::elementOf(std::vector<std::string>(
      std::begin(kExampleNames), std::end(kExampleNames) - 1));  // on_back's phase 1 is the slowest
  const double base = *rc::gen::inRange(1, 21) / 10.0;
  const double factor = *rc::gen::inRange(1, 10) / 10.0;
  const Block block =
      *rc::gen::element(Block::kObjects, Block::kRobot, Block::kSensor, Block::kAll);
  const Scenario wider = shrunk(example(name), Block::kAll, base);
  const Outcome before = outcome_of(wider);
  const Outcome after = outcome_of(shrunk(wider, block, factor));
  RC_TAG(name);
  RC_ASSERT(after.errors <= before.errors);
  RC_ASSERT(after.violated <= before.violated);
}

}  // namespace
}  // namespace spar::planner
