#include "spar/planner/uncertainty/deciding.hpp"

#include <algorithm>
#include <bit>

#include "spar/bounds/condition_set.hpp"
#include "spar/planner/error.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/tape.hpp"

namespace spar::planner {

std::vector<VariableId> variables_of(std::span<const symbolic::Expr> expressions,
                                     const UncertaintySpace& space) {
  std::vector<VariableId> ids;
  for (const symbolic::Expr v : symbolic::variables_met(expressions)) {
    const std::optional<VariableId> id = space.id_of(v);
    if (!id) throw PlanError("internal: variable " + v.name() + " is not in the uncertainty space");
    ids.push_back(*id);
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::string printed_expression(const PreconditionResult& result) {
  constexpr double kMaxPrintedTree = 1e7;
  if (symbolic::tree_size(result.inequality.expression) > kMaxPrintedTree) return "";
  return symbolic::to_string(result.inequality.expression, kMaxPrintedTree);
}

std::vector<bounds::Interval> natural_enclosures(std::span<const symbolic::Expr> expressions,
                                                 const UncertaintySpace& space) {
  const std::vector<VariableId> ids = variables_of(expressions, space);
  std::vector<symbolic::Expr> inputs;
  for (const VariableId id : ids) inputs.push_back(space.symbol(id));
  const symbolic::Tape tape = symbolic::Tape::compile(expressions, inputs);
  symbolic::TapeEvaluator<bounds::Interval> evaluator(tape);
  const std::vector<bounds::Interval> box = space.ranges(ids);
  std::vector<bounds::Interval> out(expressions.size());
  evaluator.evaluate(box, out);
  return out;
}

namespace {
std::vector<symbolic::Expr> expressions_of(const std::vector<Precondition>& preconditions) {
  std::vector<symbolic::Expr> expressions;
  for (const Precondition& p : preconditions) expressions.push_back(p.inequality.expression);
  return expressions;
}
}  // namespace

CompiledStep::CompiledStep(const std::vector<Precondition>& preconditions,
                           const UncertaintySpace& space)
    : CompiledStep(preconditions, space, variables_of(expressions_of(preconditions), space)) {}

CompiledStep::CompiledStep(const std::vector<Precondition>& preconditions,
                           const UncertaintySpace& space, std::vector<VariableId> ids)
    : preconditions_(preconditions), ids_(std::move(ids)) {
  if (preconditions_.empty()) return;
  std::vector<bounds::Inequality> inequalities;
  for (const Precondition& p : preconditions_) inequalities.push_back(p.inequality);
  std::vector<symbolic::Expr> symbols;  // in box order
  for (const VariableId id : ids_) symbols.push_back(space.symbol(id));
  set_.emplace(std::move(inequalities), std::move(symbols));
}

std::optional<std::vector<PreconditionResult>> CompiledStep::decide(
    const UncertaintySpace& space, const bounds::BoundOptions& quick,
    const bounds::BoundOptions& full, std::size_t give_up_after) {
  std::vector<PreconditionResult> results;
  if (preconditions_.empty()) return results;
  const std::vector<bounds::Interval> box = space.ranges(ids_);
  std::optional<std::vector<bounds::ConditionCheck>> checks =
      set_->decide_all(box, quick, full, give_up_after);
  if (!checks) return std::nullopt;
  for (std::size_t i = 0; i < preconditions_.size(); ++i) {
    bounds::ConditionCheck& check = (*checks)[i];
    PreconditionResult result;
    result.kind = preconditions_[i].kind;
    result.inequality = preconditions_[i].inequality;
    result.length = preconditions_[i].length;
    result.verdict = check.verdict;
    result.bound = std::move(check.bound);
    result.witness = std::move(check.witness);
    result.decided_by = check.full        ? DecidedBy::kFullBound
                        : check.escalated ? DecidedBy::kQuickBound
                                          : DecidedBy::kNaturalPass;
    result.box = box;
    result.variables = ids_;
    results.push_back(std::move(result));
  }
  return results;
}

bool CompiledStep::all_hold(const UncertaintySpace& space, const bounds::BoundOptions& quick,
                            const bounds::BoundOptions& full) {
  return decide(space, quick, full, 1).has_value();
}

std::vector<PreconditionResult> decide(const std::vector<Precondition>& preconditions,
                                       const UncertaintySpace& space,
                                       const bounds::BoundOptions& quick,
                                       const bounds::BoundOptions& full) {
  return *CompiledStep(preconditions, space).decide(space, quick, full);
}

namespace {

// The words that determine decide()'s answer for one step (see DecisionCache), and the step's
// variables. A variable enters by its symbol and range, in the order of its id, not by the id: a
// replay with a step spliced in earlier allocates more variables before it, which shifts the ids
// of the same symbols without changing what deciding computes (the tape's inputs are the symbols
// in that order). Doubles enter by their bits, so -0.0 and 0.0 differ: at worst a miss, never a
// wrong hit.
std::vector<std::uint64_t> step_key(const std::vector<Precondition>& preconditions,
                                    const UncertaintySpace& space, std::vector<VariableId>& ids) {
  std::vector<std::uint64_t> key;
  for (const Precondition& p : preconditions) {
    key.push_back(p.inequality.expression.id());
    key.push_back(static_cast<std::uint64_t>(p.inequality.relation));
    key.push_back(std::bit_cast<std::uint64_t>(p.inequality.threshold));
    key.push_back(static_cast<std::uint64_t>(p.kind) << 1 | (p.length ? 1u : 0u));
  }
  ids = variables_of(expressions_of(preconditions), space);
  for (const VariableId id : ids) {
    const bounds::Interval range = space.range(id);
    key.push_back(space.symbol(id).id());
    key.push_back(std::bit_cast<std::uint64_t>(range.lo));
    key.push_back(std::bit_cast<std::uint64_t>(range.hi));
  }
  return key;
}

}  // namespace

std::vector<PreconditionResult> DecisionCache::decide(
    const std::vector<Precondition>& preconditions, const UncertaintySpace& space, Need need) {
  return *decide_giving_up(preconditions, space, need, std::numeric_limits<std::size_t>::max());
}

std::optional<std::vector<PreconditionResult>> DecisionCache::decide_if_all_hold(
    const std::vector<Precondition>& preconditions, const UncertaintySpace& space) {
  return decide_giving_up(preconditions, space, Need::kVerdicts, 1);
}

std::optional<std::vector<PreconditionResult>> DecisionCache::decide_giving_up(
    const std::vector<Precondition>& preconditions, const UncertaintySpace& space, Need need,
    std::size_t give_up_after) {
  std::vector<VariableId> ids;
  std::vector<std::uint64_t> key = step_key(preconditions, space, ids);
  if (const auto found = entries_.find(key);
      found != entries_.end() && (found->second.exact || need == Need::kVerdicts)) {
    ++hits_;
    const std::size_t unsatisfied = static_cast<std::size_t>(
        std::ranges::count_if(found->second.results, [](const PreconditionResult& result) {
          return result.verdict != bounds::Verdict::kSatisfied;
        }));
    if (unsatisfied >= give_up_after) return std::nullopt;
    // The same symbols in the same order, so only their ids in this space differ.
    std::vector<PreconditionResult> results = found->second.results;
    for (PreconditionResult& result : results) result.variables = ids;
    return results;
  }
  ++misses_;
  bounds::BoundOptions quick = quick_, full = full_;
  quick.stop_at_witness = full.stop_at_witness = need == Need::kVerdicts;
  std::optional<std::vector<PreconditionResult>> decided =
      CompiledStep(preconditions, space, std::move(ids)).decide(space, quick, full, give_up_after);
  if (!decided) return std::nullopt;
  Entry entry{*decided};
  for (const PreconditionResult& result : entry.results)
    entry.exact = entry.exact && !result.bound.stopped_at_witness;
  entries_.insert_or_assign(std::move(key), std::move(entry));
  return decided;
}

}  // namespace spar::planner
