// Phase 1 of SPAR: operational and geometric planning by constraint posting (seed 001, "Planning in
// Spar", "Goal Satisfaction"; survey seed 003 section 2), producing a plan family.
//
// A partial plan holds steps (step 0 is the initial state, whose add list is the initial world:
// at(o, initial position) for every object and gripper(empty); step 1 is the finish, whose
// operational preconditions are the scenario's goals), an ordering graph, a geometric binary
// constraint network over the plan variables, causal links (producer, consumer, atom), the pending
// operational goals (a stack) and the threats to the links.
//
// Refinement, in SPAR's order:
//   * threats first: a step C whose delete list may unify with the atom of a link P -> S and that
//     may fall between them is resolved by promotion prior_to(S, C), then demotion prior_to(C, P),
//     then re-establishment (a ground atom only: the link is dropped and the goal reopened, to be
//     established after C by an existing or a new step);
//   * then the operational goal on top of the stack: establish it by a step already in the plan
//     (the initial state included), constrained to precede the consumer (prior_to) and with the
//     atoms unified (codesignation in the constraint network), else by a new step from a template
//     whose add list has the predicate. A new step gets fresh plan variables (network nodes with
//     their initial label sets), pushes its operational preconditions, posts its geometric
//     preconditions as constraints (member, in_position_class, reachable, mate_reachable) and
//     checks the satisfied goals it may undo (threats on existing links).
//   Geometric constraints are posted when the step that carries them is added; codesignation then
//   narrows them as operational goals are established. A post that makes the network inconsistent
//   kills that branch (the network of every other branch is untouched: branches are copies), which
//   is SPAR's backtracking (the seed's goal_2/goal_4 example: the block is not initially in a
//   mating pose, so establishing at(block, pos) by the initial state fails and putdown(block,
//   pos_1) is added). Two objects may not be put down at the same place.
// Search: best-first on (steps + open goals) (UCPOP's S+OC), ties to the newest partial plan, so
// it dives like depth-first search on plateaus, trying each flaw's refinements in SPAR's order; the
// open goal worked on is the one with the fewest ways to establish it (least-cost flaw first: a
// forced goal at once, gripper(empty), which any release can give, last). A producer's atom that
// a step deleting it already consumes serves no other such step (one release, one pickup). It is
// complete up to the budget: it stops at max_nodes expanded partial plans or when every partial
// plan left would need more than max_steps actions, and says which.
//
// Example:
//   const WorldModel world(load_scenario("examples/peg_block_face_down.yaml"));
//   const PlanFamily family = post_plan(world, builtin_domain());
//   if (family.status == PostingStatus::kPlanned)
//     for (const FamilyStep& step : family.steps) std::cout << family.describe(step) << '\n';
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "spar/planner/cms/constraint_network.hpp"
#include "spar/planner/cms/ordering_graph.hpp"
#include "spar/planner/domain.hpp"
#include "spar/planner/world.hpp"

namespace spar::planner {

// An argument of a step: an object (index into the scenario's objects), a plan variable (a node of
// the constraint network) or a constant of the domain (e.g. `empty`).
struct Term {
  enum class Kind { kObject, kVariable, kConstant };
  Kind kind{Kind::kObject};
  int index{0};  // object index, variable id, or index into PlanFamily::constants
  friend bool operator==(const Term&, const Term&) = default;
};

struct FamilyStep {
  int id{0};               // node of the ordering graph
  int action{-1};          // index into Domain::actions; -1 for the initial state and the finish
  std::vector<Term> args;  // one per template parameter, in the template's order
};

// A plan variable: a node of the constraint network.
struct PlanVariable {
  std::string name;  // grasp_1, pos_2, initial_block
  ParameterType type{ParameterType::kGrasp};
  int object{0};  // whose grasps / positions its labels are
};

struct CausalLink {
  int producer{0};
  int consumer{0};
  std::string predicate;
  std::vector<Term> args;
};

// A goal as SPAR's goal stacks hold it, kept once satisfied (for reports): its level, its
// condition, the step before which it must hold, and how it was satisfied.
struct SatisfiedGoal {
  enum class Level { kOperational, kGeometric };
  Level level{Level::kOperational};
  std::string condition;  // e.g. "holding(peg, grasp_1)" or "reachable(grasp_1, pos_2)"
  int step{0};
  std::string how;  // "step 3", "initial state", "new step 4", "constraint posted"
};

enum class PostingStatus {
  kPlanned,    // every operational and geometric goal is satisfied
  kNoPlan,     // the search space is exhausted: no plan within max_steps actions
  kNodeLimit,  // stopped after max_nodes expanded partial plans
};
[[nodiscard]] const char* to_string(PostingStatus status);

struct PlanFamily;

struct PostingOptions {
  std::size_t max_nodes{200'000};  // partial plans expanded
  int max_steps{64};               // actions in one plan (the initial state and finish excluded)
  // Network search budget per post (nodes of the backtracking consistency search).
  std::size_t network_budget{100'000};
  // Asked of every complete plan family (status already kPlanned): nullopt accepts it, a text
  // refuses it and says why, and the search goes on (plan() refuses a family none of whose
  // instances is collision-free). Empty: every complete family is accepted.
  std::function<std::optional<std::string>(const PlanFamily&)> accept{};
};

struct PostingStats {
  std::size_t expanded{0};   // partial plans taken from the queue
  std::size_t generated{0};  // partial plans created (refinements)
  std::size_t refused{0};    // complete families PostingOptions::accept refused
  double seconds{0.0};
};

struct PlanFamily {
  PostingStatus status{PostingStatus::kNoPlan};
  std::string reason;             // why there is no plan (empty when planned)
  std::vector<FamilyStep> steps;  // [0] initial state, [1] finish, then actions in order added
  std::vector<std::string> constants;
  std::vector<PlanVariable> variables;  // indexed by network variable id
  cms::OrderingGraph ordering;
  cms::ConstraintNetwork network;
  std::vector<CausalLink> links;
  std::vector<SatisfiedGoal> satisfied;
  PostingStats stats;

  // "pickup(peg, grasp_1, pos_2)", "initial state", "finish".
  [[nodiscard]] std::string describe(const FamilyStep& step, const WorldModel& world,
                                     const Domain& domain) const;
  [[nodiscard]] std::string term_name(const Term& term, const WorldModel& world) const;
};

[[nodiscard]] PlanFamily post_plan(const WorldModel& world, const Domain& domain,
                                   const PostingOptions& options = {});

}  // namespace spar::planner
