// Every record of the FPBench corpus: [lo, hi] contains the attained reference extremes (checked
// against a rigorous enclosure of f at the reference witnesses), the two records whose true range
// is unbounded are reported unbounded, and every bounded record converges to 0.1%.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "spar/bounds/bound.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds {
namespace {

using symbolic::Expr;

Relation relation_of(const std::string& text) {
  if (text == "<") return Relation::kLess;
  if (text == "<=") return Relation::kLessEqual;
  if (text == ">") return Relation::kGreater;
  return Relation::kGreaterEqual;
}

// Upper end of a rigorous enclosure of f at a point (the true f(point) is <= it), and lower end.
Interval at_point(Expr f, const Box& box, const nlohmann::json& point) {
  const symbolic::Tape tape = symbolic::Tape::compile(std::array{f}, box.variables);
  symbolic::TapeEvaluator<Interval> evaluator(tape);
  std::vector<Interval> x;
  for (Expr v : box.variables) x.emplace_back(point.at(v.name()).get<double>());
  Interval out[1];
  evaluator.evaluate(x, out);
  return out[0];
}

TEST(Corpus, EveryRecordIsSoundAndConverges) {
  std::ifstream in(std::string(SPAR_CORPUS_DIR) + "/fpbench.jsonl");
  ASSERT_TRUE(in) << "cannot open the corpus";
  std::string line;
  int bounded = 0, converged = 0, unbounded_records = 0;
  while (std::getline(in, line)) {
    const auto record = nlohmann::json::parse(line);
    const std::string name = record.at("name");
    symbolic::ExprPool pool;
    Box box;
    for (const auto& [var, range] : record.at("vars").items()) {
      box.add(pool.variable(var), range[0].get<double>(), range[1].get<double>());
    }
    const Expr f = symbolic::parse(pool, record.at("expr").get<std::string>());
    std::vector<Constraint> constraints;
    if (record.contains("constraints")) {
      for (const auto& c : record["constraints"]) {
        constraints.push_back({symbolic::parse(pool, c.at("g").get<std::string>()),
                               relation_of(c.at("rel").get<std::string>())});
      }
    }
    // Only the box budget may stop a bound here, never the clock, so the count cannot depend on
    // how loaded the machine running the tests is.
    const BoundResult r = bound(f, box, {.tolerance = 1e-3}, constraints);
    if (record.value("range_unbounded", false)) {
      ++unbounded_records;
      EXPECT_EQ(r.status, BoundStatus::kUnbounded) << name;
      EXPECT_TRUE(std::isinf(r.lo) || std::isinf(r.hi)) << name;
      continue;
    }
    ++bounded;
    const Interval at_min = at_point(f, box, record.at("ref_argmin"));
    const Interval at_max = at_point(f, box, record.at("ref_argmax"));
    EXPECT_LE(r.lo, at_min.hi) << name;
    EXPECT_GE(r.hi, at_max.lo) << name;
    EXPECT_LE(r.lo, r.inner_lo) << name;
    EXPECT_LE(r.inner_hi, r.hi) << name;
    if (r.status == BoundStatus::kConverged) {
      ++converged;
      EXPECT_LE(r.relative_gap(), 1e-3 * (1 + 1e-9)) << name;
    } else {
      std::cout << "not converged: " << name << " [" << r.lo << ", " << r.hi << "] inner ["
                << r.inner_lo << ", " << r.inner_hi << "] " << to_string(r.status) << '\n';
    }
  }
  EXPECT_EQ(unbounded_records, 2);
  std::cout << "converged " << converged << " of " << bounded << " bounded records\n";
  EXPECT_EQ(converged, bounded);
}

// instantaneousCurrent writes the amplitude V/sqrt(R² + (ωL)²) as sqrt(A² + B²) with V, R, ω, L
// repeated in A and B, times cos over ~30000 periods: bisection cannot tighten it within a
// small budget, SMP's rewrite (every variable once in the amplitude) bounds it at the root.
TEST(Corpus, SimplifiedRewriteBoundsInstantaneousCurrent) {
  std::ifstream in(std::string(SPAR_CORPUS_DIR) + "/fpbench.jsonl");
  ASSERT_TRUE(in) << "cannot open the corpus";
  std::string line;
  while (std::getline(in, line) && line.find("\"instantaneousCurrent\"") == std::string::npos) {
  }
  ASSERT_FALSE(line.empty());
  const auto record = nlohmann::json::parse(line);
  symbolic::ExprPool pool;
  Box box;
  for (const auto& [var, range] : record.at("vars").items()) {
    box.add(pool.variable(var), range[0].get<double>(), range[1].get<double>());
  }
  const Expr f = symbolic::parse(pool, record.at("expr").get<std::string>());
  const BoundOptions small{.max_box_evaluations = 2000};  // budget, not clock
  BoundOptions direct_only = small;
  direct_only.simplify = false;
  EXPECT_EQ(bound(f, box, direct_only).status, BoundStatus::kEffortLimit);
  const BoundResult r = bound(f, box, small);
  EXPECT_EQ(r.status, BoundStatus::kConverged);
  EXPECT_LE(r.lo, -11.9997631365);
  EXPECT_GE(r.hi, 11.9997631365);
  EXPECT_LT(r.hi, 11.9997631365 + 1e-3 * 24);
}

}  // namespace
}  // namespace spar::bounds
