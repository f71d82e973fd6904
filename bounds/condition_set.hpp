// ConditionSet: many inequalities over one ordered list of variables, decided over box after box.
//
// The inequalities' expressions are compiled once into ONE tape (shared subexpressions are computed
// once). check(ranges) then decides every inequality, cheapest first:
//   1. one natural interval evaluation of the tape over the box, and one at the box centre (the
//      centre's value is an attained inner value): an inequality this decides (satisfied by the
//      natural enclosure, or violated at the centre) costs nothing more;
//   2. only the undecided ones (and, with Escalation::kNotSatisfied, the violated ones too, to get
//      a tight bound and the worst witness) go to a BoundProblem (bound.hpp) with `full` options,
//      built on first need per expression (inequalities sharing one share it) on a slice of the
//      set's tape (Tape::slice: what compiling that expression alone gives, without compiling
//      it again) and kept for later boxes.
// decide_all(ranges, quick, full) is check() with Escalation::kDecide and `quick`, then the
// undecided ones again with `full` (phase 2's deciding), able to give up once enough are known
// not to be satisfied.
// Results are those of bound(): a BoundProblem's result does not depend on earlier calls, so
// check() over a box gives the same answer however many boxes were checked before.
// The expressions' pool must outlive the set. Not thread-safe.
//
// Example:
//   ConditionSet set({{"clear left", y1, Relation::kGreater, 0.0},
//                     {"clear right", y2, Relation::kLess, 0.0}}, variables);
//   for (const std::vector<Interval>& box : boxes)             // widening, sensing, ...
//     for (const ConditionCheck& c : set.check(box))
//       std::cout << to_string(c.verdict) << ' ' << c.bound.lo << ' ' << c.bound.hi << '\n';
#pragma once

#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "spar/bounds/bound.hpp"
#include "spar/bounds/inequality.hpp"
#include "spar/bounds/interval.hpp"
#include "spar/symbolic/expr.hpp"

namespace spar::bounds {

struct ConditionCheck {
  Verdict verdict{Verdict::kUndecided};
  // Escalated: the BoundProblem's result. Otherwise the natural pass: [lo, hi] is the natural
  // enclosure, argmin = argmax = the box centre (argmin_value = argmax_value = f's enclosure
  // there), status kEffortLimit (no tightening was tried), evaluations 1.
  BoundResult bound;
  std::vector<double> witness;  // witness(inequality, bound): the deciding (worst) point
  bool escalated{false};        // bound is the BoundProblem's
  bool full{false};             // decide(): escalated with the `full` budget after `quick`
};

// Which verdicts of the natural pass go on to a full bound.
enum class Escalation {
  kUndecided,     // only undecided ones (the cheapest: a violation at the centre is final)
  kNotSatisfied,  // undecided and violated ones (tight bounds and worst witnesses for reports)
  kDecide,        // only undecided ones, each bounded only until its verdict is known
                  // (BoundOptions::decide with its own relation and threshold)
};

class ConditionSet {
 public:
  // Throws BoundsError for an inequality without an expression or with a non-finite threshold, a
  // variable that is not a variable or repeats, or an expression using a variable not listed.
  ConditionSet(std::vector<Inequality> inequalities, std::vector<symbolic::Expr> variables);
  ConditionSet(ConditionSet&&) noexcept;
  ConditionSet& operator=(ConditionSet&&) noexcept;
  ~ConditionSet();

  [[nodiscard]] const std::vector<Inequality>& inequalities() const;
  [[nodiscard]] const std::vector<symbolic::Expr>& variables() const;

  // One check per inequality, in order. ranges[i] is the range of variables()[i]; throws
  // BoundsError for a wrong count or a NaN, infinite or empty range.
  [[nodiscard]] std::vector<ConditionCheck> check(std::span<const Interval> ranges,
                                                  const BoundOptions& full = {},
                                                  Escalation escalation = Escalation::kUndecided);

  // Deciding in two budgets: check(ranges, quick, Escalation::kDecide), then each inequality
  // still undecided decided again with `full` (ConditionCheck::full). It gives up, returning
  // nullopt, as soon as `give_up_after` inequalities are known not to be satisfied: the natural
  // pass's violations first, then the undecided ones in order (give_up_after = 1 asks whether
  // all are satisfied: a sensor scale's bisection). Without giving up, the checks equal deciding
  // each alone.
  [[nodiscard]] std::optional<std::vector<ConditionCheck>> decide_all(
      std::span<const Interval> ranges, const BoundOptions& quick, const BoundOptions& full,
      std::size_t give_up_after = std::numeric_limits<std::size_t>::max());

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spar::bounds
