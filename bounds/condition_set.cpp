#include "spar/bounds/condition_set.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>

#include "spar/bounds/internal/checks.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::bounds {
namespace {

std::vector<symbolic::Expr> expressions_of(const std::vector<Inequality>& inequalities) {
  std::vector<symbolic::Expr> expressions;
  expressions.reserve(inequalities.size());
  for (const Inequality& inequality : inequalities) expressions.push_back(inequality.expression);
  return expressions;
}

// Throws BoundsError for the first malformed inequality or variable list (a variable not listed
// is found by the compile: compiled()); returns them unchanged.
const std::vector<Inequality>& validated(const std::vector<Inequality>& inequalities,
                                         std::span<const symbolic::Expr> variables) {
  for (std::size_t i = 0; i < variables.size(); ++i) {
    internal::check_variable(variables[i], variables.first(i));
  }
  for (const Inequality& inequality : inequalities) {
    const std::string what = "inequality '" + inequality.name + "'";
    if (inequality.expression.is_null()) throw BoundsError(what + " has no expression");
    if (!std::isfinite(inequality.threshold)) {
      throw BoundsError(what + ": the threshold must be a finite number");
    }
  }
  return inequalities;
}

// Per inequality, the index of the first inequality with the same expression.
std::vector<std::size_t> first_with_expression(const std::vector<Inequality>& inequalities) {
  std::unordered_map<std::uint32_t, std::size_t> first_by_node;  // one pool: ids are unique
  std::vector<std::size_t> first;
  for (std::size_t i = 0; i < inequalities.size(); ++i)
    first.push_back(first_by_node.try_emplace(inequalities[i].expression.id(), i).first->second);
  return first;
}

// One tape of the inequalities' expressions (output i: inequalities[i]).
symbolic::Tape compiled(const std::vector<Inequality>& inequalities,
                        std::span<const symbolic::Expr> variables) {
  return internal::compile_checked(expressions_of(inequalities), variables, [&](std::size_t i) {
    return "inequality '" + inequalities[i].name + "'";
  });
}

}  // namespace

struct ConditionSet::Impl {
  Impl(std::vector<Inequality> inequalities_in, std::vector<symbolic::Expr> variables_in)
      : inequalities(validated(inequalities_in, variables_in)),
        variables(std::move(variables_in)),
        tape(compiled(inequalities, variables)),
        evaluator(tape),
        problems(inequalities.size()),
        first_with(first_with_expression(inequalities)) {}

  std::vector<Inequality> inequalities;
  std::vector<symbolic::Expr> variables;
  symbolic::Tape tape;                          // output i is inequalities[i].expression
  symbolic::TapeEvaluator<Interval> evaluator;  // on tape
  // problems[first_with[i]] bounds inequality i's expression, built on first escalation (two
  // sides of one clearance escalate one problem: its results do not depend on earlier calls).
  std::vector<std::unique_ptr<BoundProblem>> problems;
  std::vector<std::size_t> first_with;               // the first inequality with i's expression
  std::vector<Interval> natural, at_centre, centre;  // scratch

  // The natural pass over `ranges`: every inequality's natural enclosure and its value at the box
  // centre (natural, at_centre); returns the centre.
  std::vector<double> natural_pass(std::span<const Interval> ranges) {
    internal::check_ranges(variables, ranges);
    std::vector<double> centre_point(ranges.size());
    centre.resize(ranges.size());
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      centre_point[i] = ranges[i].mid();
      centre[i] = Interval{centre_point[i]};
    }
    natural.resize(inequalities.size());
    at_centre.resize(inequalities.size());
    evaluator.evaluate(ranges, natural);
    evaluator.evaluate(centre, at_centre);
    return centre_point;
  }

  // Inequality k's result from the natural pass (ConditionCheck::bound's comment), without witness.
  ConditionCheck natural_check(std::size_t k, std::span<const double> centre_point) const {
    const Inequality& inequality = inequalities[k];
    ConditionCheck check;
    BoundResult& bound = check.bound;
    const Interval& enclosure = natural[k];
    const Interval& value_at_centre = at_centre[k];
    bound.lo = enclosure.lo;
    bound.hi = enclosure.hi;
    bound.possibly_undefined = enclosure.possibly_undefined;
    bound.status = BoundStatus::kEffortLimit;
    bound.evaluations = 1;
    bound.inner_lo = std::numeric_limits<double>::infinity();
    bound.inner_hi = -bound.inner_lo;
    // f(centre) lies in value_at_centre: an attained value, so the centre is both witnesses.
    if (!value_at_centre.is_empty() && !value_at_centre.possibly_undefined) {
      internal::offer_witness(bound, centre_point, value_at_centre);
    }
    order_inner_bounds(bound);
    check.verdict = enclosure.is_empty() ? Verdict::kUndecided : decide(inequality, bound);
    return check;
  }

  // Inequality k bounded over `ranges` with `options`, deciding it if `deciding`.
  BoundResult escalated(std::size_t k, std::span<const Interval> ranges, BoundOptions options,
                        bool deciding) {
    const Inequality& inequality = inequalities[k];
    std::unique_ptr<BoundProblem>& problem = problems[first_with[k]];
    if (!problem)  // on output k of the set's tape: compiled once
      problem.reset(new BoundProblem(inequality.expression, variables, tape.slice(k)));
    if (deciding) options.decide = DecisionTarget{inequality.relation, inequality.threshold};
    return problem->bound(ranges, options);
  }
};

ConditionSet::ConditionSet(std::vector<Inequality> inequalities,
                           std::vector<symbolic::Expr> variables)
    : impl_(std::make_unique<Impl>(std::move(inequalities), std::move(variables))) {}

ConditionSet::ConditionSet(ConditionSet&&) noexcept = default;
ConditionSet& ConditionSet::operator=(ConditionSet&&) noexcept = default;
ConditionSet::~ConditionSet() = default;

const std::vector<Inequality>& ConditionSet::inequalities() const { return impl_->inequalities; }
const std::vector<symbolic::Expr>& ConditionSet::variables() const { return impl_->variables; }

std::vector<ConditionCheck> ConditionSet::check(std::span<const Interval> ranges,
                                                const BoundOptions& full, Escalation escalation) {
  Impl& set = *impl_;
  const std::vector<double> centre_point = set.natural_pass(ranges);
  std::vector<ConditionCheck> checks;
  for (std::size_t k = 0; k < set.inequalities.size(); ++k) {
    const Inequality& inequality = set.inequalities[k];
    ConditionCheck& check = checks.emplace_back(set.natural_check(k, centre_point));
    const bool escalate =
        check.verdict == Verdict::kUndecided ||
        (check.verdict == Verdict::kViolated && escalation == Escalation::kNotSatisfied);
    if (escalate) {
      check.bound = set.escalated(k, ranges, full, escalation == Escalation::kDecide);
      check.verdict = decide(inequality, check.bound);
      check.escalated = true;
    }
    check.witness = witness(inequality, check.bound);
  }
  return checks;
}

std::optional<std::vector<ConditionCheck>> ConditionSet::decide_all(
    std::span<const Interval> ranges, const BoundOptions& quick, const BoundOptions& full,
    std::size_t give_up_after) {
  Impl& set = *impl_;
  const std::vector<double> centre_point = set.natural_pass(ranges);
  std::vector<ConditionCheck> checks;
  std::size_t not_satisfied = 0;
  for (std::size_t k = 0; k < set.inequalities.size(); ++k) {
    not_satisfied +=
        checks.emplace_back(set.natural_check(k, centre_point)).verdict == Verdict::kViolated;
    if (not_satisfied >= give_up_after) return std::nullopt;
  }
  for (std::size_t k = 0; k < checks.size(); ++k) {
    const Inequality& inequality = set.inequalities[k];
    ConditionCheck& check = checks[k];
    if (check.verdict == Verdict::kUndecided) {
      check.bound = set.escalated(k, ranges, quick, true);
      check.verdict = decide(inequality, check.bound);
      check.escalated = true;
    }
    if (check.verdict == Verdict::kUndecided) {
      check.bound = set.escalated(k, ranges, full, true);
      check.verdict = decide(inequality, check.bound);
      check.full = true;
    }
    check.witness = witness(inequality, check.bound);
    if (check.escalated && check.verdict != Verdict::kSatisfied && ++not_satisfied >= give_up_after)
      return std::nullopt;
  }
  return checks;
}

}  // namespace spar::bounds
