// Dempster-Shafer evidence (sensing/evidence.hpp) against a brute-force implementation written
// here: mass functions as dense tables over all 2^n subsets (n <= 6), Dempster's rule as the double
// loop over subsets, belief / plausibility / pignistic probability by their definitions. Random
// mass functions come from RapidCheck (fixed seed, tests/CMakeLists.txt).
#include "spar/sensing/evidence.hpp"

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "spar/sensing/error.hpp"
#include "spar/sensing/evidence_json.hpp"
#include "tests/common/expect_message.hpp"
#include "tests/sensing/dense_evidence.hpp"

namespace spar::sensing {
namespace {

constexpr double kTolerance = 1e-12;

void expect_equal(const MassFunction& actual, const Dense& expected) {
  const Dense got = dense(actual);
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t s = 0; s < got.size(); ++s)
    RC_ASSERT(std::abs(got[s] - expected[s]) <= kTolerance);
}

void expect_same(const MassFunction& a, const MassFunction& b) { expect_equal(a, dense(b)); }

// A random mass function over n hypotheses: 1-6 focal sets, positive masses summing to 1.
MassFunction random_mass(int n) {
  const int count = *rc::gen::inRange(1, 7);
  std::vector<FocalElement> elements;
  double total = 0;
  for (int i = 0; i < count; ++i) {
    const unsigned mask = *rc::gen::inRange(1U, 1U << n);
    const double weight = *rc::gen::inRange(1, 1001) / 1000.0;
    elements.push_back({set_of(mask, n), weight});
    total += weight;
  }
  for (FocalElement& element : elements) element.mass /= total;
  return MassFunction::from_elements(n, std::move(elements));
}

// A random mass function that keeps some mass on the whole frame, so no combination with it
// conflicts totally.
MassFunction random_open_mass(int n) {
  const MassFunction m = random_mass(n);
  std::vector<FocalElement> elements = m.elements();
  for (FocalElement& element : elements) element.mass *= 0.9;
  elements.push_back({FocalSet::whole(n), 0.1});
  return MassFunction::from_elements(n, std::move(elements));
}

// ---- properties against the brute force ----

RC_GTEST_PROP(Evidence, DempsterMatchesBruteForce, ()) {
  const int n = *rc::gen::inRange(1, 7);
  const MassFunction a = random_open_mass(n), b = random_mass(n);
  const Combination got = combine(a, b);
  const DenseCombination want = brute_dempster(dense(a), dense(b));
  got.mass.debug_check();
  expect_equal(got.mass, want.mass);
  RC_ASSERT(std::abs(got.conflict - want.conflict) <= kTolerance);
}

RC_GTEST_PROP(Evidence, BeliefPlausibilityPignisticMatchBruteForce, ()) {
  const int n = *rc::gen::inRange(1, 7);
  const MassFunction m = random_mass(n);
  const Dense table = dense(m);
  const std::vector<double> betp = m.pignistic();
  for (unsigned set = 0; set < (1U << n); ++set) {
    RC_ASSERT(std::abs(m.belief(set_of(set, n)) - brute_belief(table, set)) <= kTolerance);
    RC_ASSERT(std::abs(m.plausibility(set_of(set, n)) - brute_plausibility(table, set)) <=
              kTolerance);
  }
  for (int x = 0; x < n; ++x)
    RC_ASSERT(std::abs(betp[x] - brute_pignistic(table, x)) <= kTolerance);
}

RC_GTEST_PROP(Evidence, DempsterIsCommutative, ()) {
  const int n = *rc::gen::inRange(1, 7);
  const MassFunction a = random_open_mass(n), b = random_mass(n);
  const Combination ab = combine(a, b), ba = combine(b, a);
  expect_same(ab.mass, ba.mass);
  RC_ASSERT(std::abs(ab.conflict - ba.conflict) <= kTolerance);
}

RC_GTEST_PROP(Evidence, DempsterIsAssociative, ()) {
  const int n = *rc::gen::inRange(1, 7);
  const MassFunction a = random_open_mass(n), b = random_open_mass(n), c = random_mass(n);
  const MassFunction left = combine(combine(a, b).mass, c).mass;
  const MassFunction right = combine(a, combine(b, c).mass).mass;
  expect_same(left, right);
}

RC_GTEST_PROP(Evidence, VacuousMassIsTheIdentity, ()) {
  const int n = *rc::gen::inRange(1, 7);
  const MassFunction m = random_mass(n);
  const Combination got = combine(m, MassFunction::vacuous(n));
  expect_same(got.mass, m);
  RC_ASSERT(got.conflict == 0.0);
}

// Bayesian prior (+) Bayesian likelihood: the posterior of Bayes' rule, p(x) q(x) / sum p q, and
// K = 1 - sum p q.
RC_GTEST_PROP(Evidence, BayesianMassesReduceToBayesRule, ()) {
  const int n = *rc::gen::inRange(1, 7);
  std::vector<double> prior(n), likelihood(n);
  for (int x = 0; x < n; ++x) {
    prior[x] = *rc::gen::inRange(1, 1001) / 1000.0;
    likelihood[x] = *rc::gen::inRange(1, 1001) / 1000.0;
  }
  const double prior_sum = std::accumulate(prior.begin(), prior.end(), 0.0);
  const double likelihood_sum = std::accumulate(likelihood.begin(), likelihood.end(), 0.0);
  for (int x = 0; x < n; ++x) {
    prior[x] /= prior_sum;
    likelihood[x] /= likelihood_sum;
  }
  const Combination got =
      combine(MassFunction::bayesian(prior), MassFunction::bayesian(likelihood));
  double evidence = 0;
  for (int x = 0; x < n; ++x) evidence += prior[x] * likelihood[x];
  for (int x = 0; x < n; ++x)
    RC_ASSERT(std::abs(got.mass.mass(FocalSet::of(n, {x})) - prior[x] * likelihood[x] / evidence) <=
              kTolerance);
  RC_ASSERT(std::abs(got.conflict - (1 - evidence)) <= kTolerance);
}

// A Bayesian prior combined with any mass function m is Bayesian, proportional to p(x) Pl_m({x}).
RC_GTEST_PROP(Evidence, BayesianPriorTimesPlausibility, ()) {
  const int n = *rc::gen::inRange(1, 7);
  std::vector<double> prior(n, 1.0 / n);
  const MassFunction m = random_mass(n);
  const Combination got = combine(MassFunction::bayesian(prior), m);
  double total = 0;
  for (int x = 0; x < n; ++x) total += prior[x] * m.plausibility(FocalSet::of(n, {x}));
  for (int x = 0; x < n; ++x)
    RC_ASSERT(std::abs(got.mass.mass(FocalSet::of(n, {x})) -
                       prior[x] * m.plausibility(FocalSet::of(n, {x})) / total) <= kTolerance);
}

RC_GTEST_PROP(Evidence, CoarseningUndoesRefinement, ()) {
  const int n = *rc::gen::inRange(1, 5);
  const MassFunction m = random_mass(n);
  // Coarse hypothesis i becomes 1-3 fine ones, numbered consecutively.
  std::vector<int> widths(n);
  int fine = 0;
  for (int& width : widths) fine += width = *rc::gen::inRange(1, 4);
  std::vector<FocalSet> refining;
  for (int i = 0, next = 0; i < n; ++i) {
    FocalSet image(fine);
    for (int k = 0; k < widths[i]; ++k) image.insert(next++);
    refining.push_back(image);
  }
  const MassFunction refined = refine(m, refining);
  refined.debug_check();
  expect_same(coarsen(refined, refining), m);
  // Belief in a coarse set is belief in its image.
  for (unsigned set = 1; set < (1U << n); ++set) {
    FocalSet image(fine);
    for (int i = 0; i < n; ++i)
      if (set & (1U << i)) image = image | refining[i];
    RC_ASSERT(std::abs(refined.belief(image) - m.belief(set_of(set, n))) <= kTolerance);
  }
}

RC_GTEST_PROP(Evidence, AmbiguityIsThePignisticEntropy, ()) {
  const int n = *rc::gen::inRange(1, 7);
  const MassFunction m = random_mass(n);
  const Dense table = dense(m);
  double entropy = 0, nonspecificity = 0;
  for (int x = 0; x < n; ++x)
    if (const double p = brute_pignistic(table, x); p > 0) entropy -= p * std::log2(p);
  for (unsigned b = 1; b < table.size(); ++b)
    nonspecificity += table[b] * std::log2(std::popcount(b));
  RC_ASSERT(std::abs(m.ambiguity() - entropy) <= 1e-12);
  RC_ASSERT(std::abs(m.nonspecificity() - nonspecificity) <= 1e-12);
  RC_ASSERT(m.ambiguity() <= std::log2(n) + 1e-12);
}

// ---- fixed cases ----

TEST(Evidence, HeaderExampleCombinesTwoSimpleSupports) {
  const Frame frame({"block", "cube", "peg"});
  const MassFunction a = MassFunction::simple_support(frame.set({"block", "cube"}), 0.8);
  const MassFunction b = MassFunction::simple_support(frame.set({"cube", "peg"}), 0.6);
  const Combination both = combine(a, b);
  EXPECT_NEAR(both.mass.belief(frame.set({"cube"})), 0.48, 1e-15);
  EXPECT_NEAR(both.mass.mass(frame.set({"block", "cube"})), 0.32, 1e-15);
  EXPECT_NEAR(both.mass.mass(frame.whole()), 0.08, 1e-15);
  EXPECT_EQ(both.conflict, 0.0);
}

// Zadeh's example: two experts nearly sure of different causes; Dempster gives the third all
// the belief, with K = 0.9999.
TEST(Evidence, ZadehsExampleKeepsTheConflictDigits) {
  const Frame frame({"meningitis", "tumour", "concussion"});
  const auto m1 = MassFunction::from_elements(
      3, {{frame.set({"meningitis"}), 0.99}, {frame.set({"tumour"}), 0.01}});
  const auto m2 = MassFunction::from_elements(
      3, {{frame.set({"concussion"}), 0.99}, {frame.set({"tumour"}), 0.01}});
  const Combination both = combine(m1, m2);
  EXPECT_NEAR(both.conflict, 0.9999, 1e-15);
  EXPECT_DOUBLE_EQ(both.mass.mass(frame.set({"tumour"})), 1.0);
}

TEST(Evidence, TotalConflictIsAnErrorNotNan) {
  const Frame frame({"a", "b"});
  EXPECT_THROW_MESSAGE(combine(MassFunction::simple_support(frame.set({"a"}), 1.0),
                               MassFunction::simple_support(frame.set({"b"}), 1.0)),
                       "total conflict (K = 1)");
}

TEST(Evidence, VacuousAmbiguityIsLog2OfTheFrame) {
  const MassFunction vacuous = MassFunction::vacuous(64);
  EXPECT_NEAR(vacuous.ambiguity(), 6.0, 1e-12);
  EXPECT_NEAR(vacuous.nonspecificity(), 6.0, 1e-12);
  const MassFunction certain = MassFunction::simple_support(FocalSet::of(64, {63}), 1.0);
  EXPECT_EQ(certain.ambiguity(), 0.0);
  EXPECT_EQ(certain.nonspecificity(), 0.0);
}

// Frames across word boundaries (64, 65, 130 hypotheses): complement, order and combination.
TEST(Evidence, FramesAcrossWordBoundaries) {
  for (const int n : {63, 64, 65, 128, 130}) {
    const FocalSet high = FocalSet::of(n, {0, n - 1});
    EXPECT_EQ(high.complement().count(), n - 2);
    EXPECT_EQ((high.complement() | high), FocalSet::whole(n));
    EXPECT_TRUE((high.complement() & high).empty());
    EXPECT_EQ(high.members(), (std::vector<int>{0, n - 1}));
    const Combination both = combine(MassFunction::simple_support(high, 0.5),
                                     MassFunction::simple_support(FocalSet::of(n, {n - 1}), 0.5));
    EXPECT_NEAR(both.mass.mass(FocalSet::of(n, {n - 1})), 0.5, 1e-15);
    EXPECT_NEAR(both.mass.belief(high), 0.75, 1e-15);
  }
}

TEST(Evidence, OrderIsByCountThenMembers) {
  EXPECT_LT(FocalSet::of(4, {3}), FocalSet::of(4, {0, 1}));
  EXPECT_LT(FocalSet::of(4, {0, 1}), FocalSet::of(4, {0, 2}));
  EXPECT_LT(FocalSet::of(4, {0, 3}), FocalSet::of(4, {1, 2}));
  EXPECT_FALSE(FocalSet::of(4, {1, 2}) < FocalSet::of(4, {1, 2}));
}

TEST(Evidence, BadAssignmentsSayWhatIsWrong) {
  EXPECT_THROW_MESSAGE(Frame({"a", "a"}), "'a' is listed twice");
  EXPECT_THROW_MESSAGE(MassFunction::from_elements(2, {{FocalSet::of(2, {0}), 0.5}}),
                       "must sum to 1, got 0.5");
  EXPECT_THROW_MESSAGE(MassFunction::from_elements(2, {{FocalSet(2), 1.0}}),
                       "the empty set cannot carry mass");
  EXPECT_THROW_MESSAGE(MassFunction::simple_support(FocalSet::of(2, {0}), 1.5),
                       "must be in [0, 1], got 1.5");
  EXPECT_THROW_MESSAGE(combine(MassFunction::vacuous(2), MassFunction::vacuous(3)),
                       "frames of different sizes (2 and 3");
  EXPECT_THROW_MESSAGE(refine(MassFunction::vacuous(2),
                              std::vector<FocalSet>{FocalSet::of(3, {0, 1}), FocalSet::of(3, {1})}),
                       "shares fine hypotheses");
  EXPECT_THROW_MESSAGE(refine(MassFunction::vacuous(2),
                              std::vector<FocalSet>{FocalSet::of(3, {0}), FocalSet::of(3, {1})}),
                       "are not the image of any coarse hypothesis");
}

// ---- the JSON forms ----

TEST(EvidenceJson, CombinesTheFilesSources) {
  const EvidenceInput input = parse_evidence_json(R"({"frame": ["a", "b", "c"], "sources": [
      [{"set": ["a", "b"], "mass": 0.8}, {"set": ["a", "b", "c"], "mass": 0.2}],
      [{"set": ["b"], "mass": 0.5}, {"set": ["c"], "mass": 0.5}]]})",
                                                  "inline.json");
  const auto out = evidence_json(input.frame, combine(input.sources, input.frame.size()));
  // Products: {b} 0.4, {} 0.4 (conflict), {b} 0.1, {c} 0.1 -> K = 0.4, {b} 5/6, {c} 1/6.
  EXPECT_NEAR(out["conflict"].get<double>(), 0.4, 1e-15);
  EXPECT_NEAR(out["belief"]["b"].get<double>(), 5.0 / 6, 1e-15);
  EXPECT_NEAR(out["plausibility"]["c"].get<double>(), 1.0 / 6, 1e-15);
  EXPECT_NEAR(out["pignistic"]["a"].get<double>(), 0.0, 1e-15);
  ASSERT_EQ(out["masses"].size(), 2U);
  EXPECT_EQ(out["masses"][0]["set"], nlohmann::ordered_json::array({"b"}));
  const double ambiguity = -(5.0 / 6 * std::log2(5.0 / 6) + 1.0 / 6 * std::log2(1.0 / 6));
  EXPECT_NEAR(out["ambiguity"].get<double>(), ambiguity, 1e-15);
}

TEST(EvidenceJson, MistakesNameTheirPlace) {
  EXPECT_THROW_MESSAGE(parse_evidence_json("{\"frame\": [\"a\"],\n \"sources\": [}", "f.json"),
                       "f.json:2:14: JSON syntax error");
  EXPECT_THROW_MESSAGE(
      parse_evidence_json(R"({"frame": ["a"], "sources": [[{"set": ["b"], "mass": 1}]]})", "f"),
      "f: sources[0][0].set[0]: 'b' is not in the frame");
  EXPECT_THROW_MESSAGE(
      parse_evidence_json(R"({"frame": ["a"], "sources": [[{"set": ["a"], "mass": "1"}]]})", "f"),
      "f: sources[0][0].mass: must be a number in [0, 1], got \"1\"");
  EXPECT_THROW_MESSAGE(
      parse_evidence_json(
          R"({"frame": ["a", "b"], "sources": [[{"set": ["a"], "mass": 0.5}, {"set": ["a"], "mass": 0.5}]]})",
          "f"),
      "f: sources[0][1].set: this set is listed twice");
  EXPECT_THROW_MESSAGE(
      parse_evidence_json(R"({"frame": ["a", "b"], "sources": [[{"set": ["a"], "mass": 0.7}]]})",
                          "f"),
      "f: sources[0]: the masses of a source must sum to 1, got 0.7");
  EXPECT_THROW_MESSAGE(parse_evidence_json(R"({"frame": [], "sources": []})", "f"),
                       "f: frame: expected a non-empty list of names");
  EXPECT_THROW_MESSAGE(parse_evidence_json(R"({"frame": ["a"], "source": []})", "f"),
                       "f: source: unknown key (known: frame, sources)");
}

}  // namespace
}  // namespace spar::sensing
