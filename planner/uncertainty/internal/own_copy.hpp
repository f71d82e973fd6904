// A precondition's expression and variables copied into a pool of their own (symbolic::
// copy_into), so that work on them may run on another thread (pools are not thread-safe): the
// copy compiles to the same tape, so its bounds and samples are the original's. Made on the
// thread that owns the analysis' pool (copying reads it).
#pragma once

#include <memory>
#include <vector>

#include "spar/planner/uncertainty/analysis.hpp"
#include "spar/symbolic/operations.hpp"

namespace spar::planner::internal {

struct OwnCopy {
  std::unique_ptr<symbolic::ExprPool> pool;
  symbolic::Expr f;                    // the precondition's expression
  std::vector<symbolic::Expr> inputs;  // its variables, in PreconditionResult::variables order
};

[[nodiscard]] inline OwnCopy own_copy(const InstanceAnalysis& analysis,
                                      const PreconditionResult& result) {
  OwnCopy copy{std::make_unique<symbolic::ExprPool>(), {}, {}};
  std::vector<symbolic::Expr> roots{result.inequality.expression};
  for (const VariableId id : result.variables) roots.push_back(analysis.symbols.at(id.index));
  const std::vector<symbolic::Expr> copies = symbolic::copy_into(*copy.pool, roots);
  copy.f = copies.front();
  copy.inputs.assign(copies.begin() + 1, copies.end());
  return copy;
}

}  // namespace spar::planner::internal
