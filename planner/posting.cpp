#include "spar/planner/posting.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <queue>

#include "spar/common/deadline.hpp"
#include "spar/planner/error.hpp"

namespace spar::planner {
namespace {

constexpr int kInitialStep = 0;
constexpr int kFinishStep = 1;

// An atom with its arguments resolved to terms of one partial plan.
struct GroundAtom {
  std::string predicate;
  std::vector<Term> args;
};

// An operational goal on the stack: `atom` must hold just before `consumer`; when `after` >= 0 the
// establishing step must also come after that step (re-establishment past a clobberer).
struct OpenGoal {
  GroundAtom atom;
  int consumer{0};
  int after{-1};
};

struct Threat {
  std::size_t link{0};
  int clobberer{0};
};

struct PartialPlan {
  PlanFamily plan;
  std::vector<OpenGoal> open;  // the operational goal stack: back() is the top
  std::vector<Threat> threats;
  // Where steps put objects down (the position variables of putdowns): two of them of different
  // objects never share a place (a place holds one object at a time).
  std::vector<int> destinations;
  int actions{0};
  int grasp_names{0};     // grasp_1, grasp_2, ... in order of creation (SPAR's naming)
  int position_names{0};  // pos_1, pos_2, ...
};

// The open partial plans, best first: fewest actions plus open goals, the newest first among
// equals (the sequence number). The plans sit in a store whose slots are reused as they are taken.
class Agenda {
 public:
  [[nodiscard]] bool empty() const { return queue_.empty(); }
  // Adds `node`; `sequence` orders it among equals (a count of the plans generated).
  void push(PartialPlan&& node, std::size_t sequence) {
    const int priority = node.actions + static_cast<int>(node.open.size());
    std::size_t slot;
    if (free_slots_.empty()) {
      slot = store_.size();
      store_.push_back(std::move(node));
    } else {
      slot = free_slots_.back();
      free_slots_.pop_back();
      store_[slot] = std::move(node);
    }
    queue_.push({priority, sequence, slot});
  }
  [[nodiscard]] PartialPlan& best() { return store_[queue_.top().index]; }
  [[nodiscard]] PartialPlan take_best() {
    const std::size_t slot = queue_.top().index;
    queue_.pop();
    free_slots_.push_back(slot);
    return std::move(store_[slot]);
  }

 private:
  struct Entry {
    int priority;
    std::size_t sequence;
    std::size_t index;
    bool operator<(const Entry& other) const {  // std::priority_queue pops the largest
      if (priority != other.priority) return priority > other.priority;
      return sequence < other.sequence;  // newest first among equals
    }
  };
  std::vector<PartialPlan> store_;
  std::vector<std::size_t> free_slots_;
  std::priority_queue<Entry> queue_;
};

class Planner {
 public:
  Planner(const WorldModel& world, const Domain& domain, const PostingOptions& options)
      : world_(world), domain_(domain), options_(options) {}

  PlanFamily run();

 private:
  // --- the search's ends ---
  // Records the plan's causal links as operational goals satisfied (by which step).
  void add_satisfied_links(PlanFamily& plan) const;
  // Why the search found no plan: the relaxed obstacle or the last refusal, the refused complete
  // families, the network's budget.
  [[nodiscard]] std::string no_plan_reason(std::size_t refused,
                                           const std::string& first_refusal) const;

  // --- terms and atoms ---
  // Interns a constant of the domain (e.g. `empty`) and returns its index.
  int constant(PartialPlan& node, const std::string& name) const {
    auto& constants = node.plan.constants;
    const auto found = std::find(constants.begin(), constants.end(), name);
    if (found != constants.end()) return static_cast<int>(found - constants.begin());
    constants.push_back(name);
    return static_cast<int>(constants.size() - 1);
  }
  [[nodiscard]] bool possibly_equal(const PartialPlan& node, const Term& a, const Term& b) const;
  [[nodiscard]] bool possibly_unify(const PartialPlan& node, const GroundAtom& a,
                                    const GroundAtom& b) const;
  [[nodiscard]] bool unify(PartialPlan& node, const GroundAtom& a, const GroundAtom& b) const;
  [[nodiscard]] GroundAtom ground(const PartialPlan& node, const Atom& atom,
                                  const FamilyStep& step) const;
  [[nodiscard]] std::vector<GroundAtom> adds(const PartialPlan& node, int step) const;
  [[nodiscard]] std::vector<GroundAtom> deletes(const PartialPlan& node, int step) const;

  [[nodiscard]] cms::SearchBudget budget() const { return {options_.network_budget}; }
  // Whether a network operation kept its change; counts the refusals that were only the budget's
  // (the search then is incomplete, and says so when it finds no plan).
  [[nodiscard]] bool accepted(cms::Consistency result) const {
    if (result == cms::Consistency::kBudgetExhausted) ++budget_refusals_;
    return result == cms::Consistency::kConsistent;
  }
  // Posts the binary constraint whose allowed pairs are table[label of a][label of b].
  [[nodiscard]] bool post_table(cms::ConstraintNetwork& network, int a, int b,
                                const std::vector<std::vector<char>>& table) const {
    return accepted(network.post(
        a, b, [&](int la, int lb) { return table[la][lb] != 0; }, budget()));
  }

  // --- refinements ---
  int add_variable(PartialPlan& node, ParameterType type, int object, std::string name) const;
  [[nodiscard]] bool post_geometric(PartialPlan& node, const FamilyStep& step,
                                    const GeometricPrecondition& geometric) const;
  [[nodiscard]] bool separate_places(PartialPlan& node, int step, int variable) const;
  // Once assemble(h, f) has run, f carries h and they move as one: every step ordered after it
  // that takes f must use a grasp that clears h (GoalWorld::grasp_clears_assembled) and a
  // position where f with h rests on the table (GoalWorld::rests_assembled); every step ordered
  // before it, a position where f rests by itself (not one where only the pair rests:
  // PositionLabel::joined_goal; a step not yet ordered either way is left to the plan instance's
  // WorldModel::check_rest). False when that empties a domain.
  [[nodiscard]] bool subassemblies_move_as_one(PartialPlan& node) const;
  // Whether a step handling `object` (and `partner`, the fixed object of an insertion, or -1)
  // must keep clear of `other` where it starts: not a fixed object (the world's tables already
  // avoid those), not one of them or what starts assembled into them (those move with them; the
  // plan instance's check sees where they are).
  [[nodiscard]] bool may_meet(int object, int other, int partner) const;
  // Keeps step `step`'s configurations clear of `other` resting where it starts, where
  // conflicts[la][lb] says the labels la of `a` and lb of `b` would hit it (b = -1: a unary table
  // conflicts[la][0]): by a constraint when a consistent labeling survives it, else by moving
  // `other` away first (an open goal at(other, v) before the step, v a fresh placement).
  [[nodiscard]] bool clear_of_start(PartialPlan& node, int step, int a, int b, int other,
                                    const WorldModel::Table& conflicts) const;
  [[nodiscard]] bool add_link(PartialPlan& node, int producer, const OpenGoal& goal) const;
  void find_threats_to_link(PartialPlan& node, std::size_t link) const;
  void find_threats_by_step(PartialPlan& node, int step) const;
  [[nodiscard]] bool is_threat(const PartialPlan& node, const Threat& threat) const;
  // Refinements establishing the open goal node.open[goal_index].
  void establish(const PartialPlan& node, std::size_t goal_index,
                 std::vector<PartialPlan>& children) const;
  // How many steps already in the plan could establish `goal` (each a possible refinement).
  // Whether `atom` of `producer` is already consumed: linked to another step that deletes it,
  // while `consumer` deletes it too. Both cannot use it (whichever runs second would find it gone
  // with no step re-adding it in between, or that step would be its producer), so such a producer
  // is no candidate: one release serves one pickup's gripper(empty).
  [[nodiscard]] bool consumed(const PartialPlan& node, int producer, const GroundAtom& atom,
                              int consumer) const;
  // The steps already in the plan that could establish `goal`, each with the add-list atom that
  // matches it (each pair a possible refinement).
  [[nodiscard]] std::vector<std::pair<int, GroundAtom>> existing_establishers(
      const PartialPlan& node, const OpenGoal& goal) const;
  // The open goal to work on (see choose_goal's comment).
  [[nodiscard]] std::size_t choose_goal(const PartialPlan& node) const;
  [[nodiscard]] std::optional<PartialPlan> establish_by_new_step(const PartialPlan& node,
                                                                 const OpenGoal& goal,
                                                                 std::size_t action,
                                                                 const Atom& add) const;
  // establish_by_new_step's bindings of the new step's parameters, false when they cannot be
  // made: those of the matching add atom to the goal's terms, then the typed ones (fresh
  // variables, or the bound ones checked).
  [[nodiscard]] bool bind_to_goal(const PartialPlan& child, FamilyStep& step,
                                  const ActionTemplate& action, const Atom& add,
                                  const OpenGoal& goal) const;
  [[nodiscard]] bool bind_typed_parameters(PartialPlan& child, FamilyStep& step,
                                           const ActionTemplate& action) const;
  void resolve(const PartialPlan& node, const Threat& threat,
               std::vector<PartialPlan>& children) const;
  // The start of the search; nullopt when an at goal's place has no position of its object.
  [[nodiscard]] std::optional<PartialPlan> initial_plan() const;

  const WorldModel& world_;
  const Domain& domain_;
  const PostingOptions& options_;
  const WorldState start_state_{world_.initial_state()};
  mutable std::size_t budget_refusals_{0};
  // The last constraint that refused a refinement, for the no-plan reason.
  mutable std::string last_refusal_;
};

bool Planner::possibly_equal(const PartialPlan& node, const Term& a, const Term& b) const {
  if (a.kind != b.kind) return false;
  if (a.kind != Term::Kind::kVariable) return a.index == b.index;
  const PlanVariable& va = node.plan.variables[a.index];
  const PlanVariable& vb = node.plan.variables[b.index];
  const bool grasp_a = va.type == ParameterType::kGrasp, grasp_b = vb.type == ParameterType::kGrasp;
  if (grasp_a != grasp_b || va.object != vb.object) return false;
  const cms::ConstraintNetwork& network = node.plan.network;
  if (network.representative(a.index) == network.representative(b.index)) return true;
  for (const int label : network.labels(a.index))
    if (network.has_label(b.index, label)) return true;
  return false;
}

bool Planner::possibly_unify(const PartialPlan& node, const GroundAtom& a,
                             const GroundAtom& b) const {
  if (a.predicate != b.predicate || a.args.size() != b.args.size()) return false;
  for (std::size_t i = 0; i < a.args.size(); ++i)
    if (!possibly_equal(node, a.args[i], b.args[i])) return false;
  return true;
}

bool Planner::unify(PartialPlan& node, const GroundAtom& a, const GroundAtom& b) const {
  if (!possibly_unify(node, a, b)) return false;
  for (std::size_t i = 0; i < a.args.size(); ++i)
    if (a.args[i].kind == Term::Kind::kVariable &&
        !accepted(node.plan.network.unify(a.args[i].index, b.args[i].index, budget())))
      return false;
  return true;
}

GroundAtom Planner::ground(const PartialPlan& node, const Atom& atom,
                           const FamilyStep& step) const {
  const ActionTemplate& action = domain_.actions[step.action];
  GroundAtom ground{.predicate = atom.predicate, .args = {}};
  for (const std::string& arg : atom.args) {
    const int parameter = action.parameter_index(arg);
    if (parameter >= 0) {
      ground.args.push_back(step.args[parameter]);
    } else {
      const auto& constants = node.plan.constants;
      const auto found = std::find(constants.begin(), constants.end(), arg);
      // Constants are interned when a step is added, so every one of a step's atoms is there.
      ground.args.push_back({Term::Kind::kConstant, static_cast<int>(found - constants.begin())});
    }
  }
  return ground;
}

std::vector<GroundAtom> Planner::adds(const PartialPlan& node, int step) const {
  std::vector<GroundAtom> atoms;
  if (step == kInitialStep) {
    const int empty = static_cast<int>(
        std::find(node.plan.constants.begin(), node.plan.constants.end(), "empty") -
        node.plan.constants.begin());
    atoms.push_back({"gripper", {{Term::Kind::kConstant, empty}}});
    for (std::size_t o = 0; o < world_.object_count(); ++o)
      atoms.push_back({"at",
                       {{Term::Kind::kObject, static_cast<int>(o)},
                        {Term::Kind::kVariable, static_cast<int>(o)}}});  // initial_<o> is var o
    // Assemblies the initial world already has (goals that hold from the start).
    for (const GoalWorld& goal : world_.goals())
      if (goal.kind == GoalWorld::Kind::kAssembled && goal.initially_true)
        atoms.push_back(
            {"assembled", {{Term::Kind::kObject, goal.held}, {Term::Kind::kObject, goal.fixed}}});
    return atoms;
  }
  if (step == kFinishStep) return atoms;
  const FamilyStep& family_step = node.plan.steps[step];
  for (const Atom& atom : domain_.actions[family_step.action].add)
    atoms.push_back(ground(node, atom, family_step));
  return atoms;
}

std::vector<GroundAtom> Planner::deletes(const PartialPlan& node, int step) const {
  std::vector<GroundAtom> atoms;
  if (step == kInitialStep || step == kFinishStep) return atoms;
  const FamilyStep& family_step = node.plan.steps[step];
  for (const Atom& atom : domain_.actions[family_step.action].del)
    atoms.push_back(ground(node, atom, family_step));
  return atoms;
}

int Planner::add_variable(PartialPlan& node, ParameterType type, int object,
                          std::string name) const {
  const ObjectWorld& labels = world_.object(object);
  const int domain_size = static_cast<int>(type == ParameterType::kGrasp ? labels.grasps.size()
                                                                         : labels.positions.size());
  std::vector<int> initial;
  for (int label = type == ParameterType::kPlacement ? 1 : 0; label < domain_size; ++label)
    initial.push_back(label);
  const int id = node.plan.network.add_variable(name, domain_size, initial);
  node.plan.variables.push_back({std::move(name), type, object});
  return id;
}

bool Planner::post_geometric(PartialPlan& node, const FamilyStep& step,
                             const GeometricPrecondition& geometric) const {
  const ActionTemplate& action = domain_.actions[step.action];
  const auto variable = [&](std::size_t i) {
    return step.args[action.parameter_index(geometric.args[i])].index;
  };
  const auto object_of = [&](int var) { return node.plan.variables[var].object; };
  // The assembled goal this step serves: the one whose held and fixed objects are both arguments.
  const auto goal_tables = [&]() -> const GoalWorld* {
    for (const GoalWorld& tables : world_.goals()) {
      bool held = false, fixed = false;
      for (const Term& term : step.args)
        if (term.kind == Term::Kind::kObject) {
          held |= term.index == tables.held;
          fixed |= term.index == tables.fixed;
        }
      if (held && fixed) return &tables;
    }
    return nullptr;
  };
  cms::ConstraintNetwork& network = node.plan.network;
  bool ok = false;
  switch (geometric.kind) {
    case GeometricConstraintKind::kReachable: {
      const int grasp = variable(0), position = variable(1), object = object_of(grasp);
      ok = post_table(network, grasp, position, world_.object(object).reachable);
      for (std::size_t other = 0; ok && other < world_.object_count(); ++other)
        if (may_meet(object, static_cast<int>(other), -1))
          ok = clear_of_start(node, step.id, grasp, position, static_cast<int>(other),
                              world_.initial_conflicts(object, static_cast<int>(other)));
      break;
    }
    case GeometricConstraintKind::kMateReachable: {
      const GoalWorld* tables = goal_tables();
      ok = tables != nullptr &&
           post_table(network, variable(0), variable(1), tables->mate_reachable);
      const int goal = ok ? static_cast<int>(tables - world_.goals().data()) : -1;
      for (std::size_t other = 0; ok && other < world_.object_count(); ++other)
        if (may_meet(tables->held, static_cast<int>(other), tables->fixed))
          ok = clear_of_start(node, step.id, variable(0), variable(1), static_cast<int>(other),
                              world_.insertion_conflicts(goal, static_cast<int>(other)));
      break;
    }
    case GeometricConstraintKind::kMemberMatingFree:
    case GeometricConstraintKind::kMatingPoses: {
      const GoalWorld* tables = goal_tables();
      if (tables == nullptr) return false;
      const std::vector<char>& members = geometric.kind == GeometricConstraintKind::kMatingPoses
                                             ? tables->mating_pose
                                             : tables->grasp_leaves_mating_free;
      std::vector<int> labels;
      for (std::size_t label = 0; label < members.size(); ++label)
        if (members[label]) labels.push_back(static_cast<int>(label));
      ok = accepted(network.restrict(variable(0), labels, budget()));
      break;
    }
  }
  std::string condition = geometric.str();
  for (std::size_t i = 0; i < geometric.args.size(); ++i) {
    const std::string& from = geometric.args[i];
    const std::string& to = node.plan.variables[variable(i)].name;
    condition.replace(condition.find(from), from.size(), to);
  }
  if (!ok) {
    last_refusal_ = node.plan.describe(step, world_, domain_) + ": " + condition +
                    " leaves no consistent labels (collisions included)";
    return false;
  }
  node.plan.satisfied.push_back(
      {SatisfiedGoal::Level::kGeometric, condition, step.id, "constraint posted"});
  return true;
}

bool Planner::separate_places(PartialPlan& node, int step, int variable) const {
  const int mine = node.plan.variables[variable].object;
  for (const int other : node.destinations) {
    const int theirs = node.plan.variables[other].object;
    if (theirs == mine) continue;
    // Over the whole plan, as if both stayed: one place per object, bodies apart.
    const WorldModel::Table& conflicts = world_.placement_conflicts(mine, theirs);
    if (!accepted(node.plan.network.post(
            variable, other, [&](int la, int lb) { return conflicts[la][lb] == 0; }, budget())))
      return false;
  }
  node.destinations.push_back(variable);
  // Where other objects start: the destination must avoid them, or they must leave first.
  for (std::size_t other = 0; other < world_.object_count(); ++other)
    if (may_meet(mine, static_cast<int>(other), -1)) {
      const WorldModel::Table& conflicts =
          world_.placement_conflicts(mine, static_cast<int>(other));
      WorldModel::Table unary(conflicts.size(), std::vector<char>(1, 0));
      for (std::size_t label = 0; label < conflicts.size(); ++label)
        unary[label][0] = conflicts[label][0];
      if (!clear_of_start(node, step, variable, -1, static_cast<int>(other), unary)) return false;
    }
  return true;
}

bool Planner::subassemblies_move_as_one(PartialPlan& node) const {
  // Every join of h into f: its goal's tables and the step that makes it (none when it holds
  // from the start: then every step comes after it).
  std::vector<std::pair<const GoalWorld*, const FamilyStep*>> joins;
  for (const GoalWorld& goal : world_.goals())
    if (goal.kind == GoalWorld::Kind::kAssembled && goal.initially_true)
      joins.emplace_back(&goal, nullptr);
  for (const FamilyStep& assembly : node.plan.steps) {
    if (assembly.action < 0) continue;
    const ActionTemplate& action = domain_.actions[assembly.action];
    const auto adds = std::find_if(action.add.begin(), action.add.end(),
                                   [](const Atom& atom) { return atom.predicate == "assembled"; });
    if (adds == action.add.end() || adds->args.size() != 2) continue;
    if (const GoalWorld* goal =
            world_.goal(assembly.args[action.parameter_index(adds->args[0])].index,
                        assembly.args[action.parameter_index(adds->args[1])].index))
      joins.emplace_back(goal, &assembly);
  }
  for (const auto& [goal, assembly] : joins) {
    const int held = goal->held, fixed = goal->fixed;
    const auto allowed = [](const std::vector<char>& table) {
      std::vector<int> labels;
      for (std::size_t l = 0; l < table.size(); ++l)
        if (table[l]) labels.push_back(static_cast<int>(l));
      return labels;
    };
    const std::vector<int> clear = allowed(goal->grasp_clears_assembled);
    const std::vector<int> resting = allowed(goal->rests_assembled);
    // Before the join f rests by itself: not where only the pair does.
    const int goal_index = static_cast<int>(goal - world_.goals().data());
    std::vector<char> rests_alone;
    for (const PositionLabel& position : world_.object(fixed).positions)
      rests_alone.push_back(position.joined_goal != goal_index);
    const std::vector<int> alone = allowed(rests_alone);
    const std::string& fixed_name = world_.scenario().objects[fixed].name;
    const std::string& held_name = world_.scenario().objects[held].name;
    for (const FamilyStep& later : node.plan.steps) {
      if (later.action < 0) continue;
      const bool after = assembly == nullptr || node.plan.ordering.precedes(assembly->id, later.id);
      const bool before =
          assembly != nullptr && node.plan.ordering.precedes(later.id, assembly->id);
      if (!after && !before) continue;
      const ActionTemplate& taking = domain_.actions[later.action];
      for (std::size_t p = 0; p < taking.parameters.size(); ++p) {
        const Parameter& parameter = taking.parameters[p];
        if (parameter.type == ParameterType::kObject ||
            later.args[taking.parameter_index(parameter.of)].index != fixed)
          continue;
        const bool grasp = parameter.type == ParameterType::kGrasp;
        if (grasp && !after) continue;
        const std::vector<int>& kept = grasp ? clear : after ? resting : alone;
        const int variable = later.args[p].index;
        cms::ConstraintNetwork& network = node.plan.network;
        bool narrower = false;
        for (const int label : network.labels(variable))
          narrower |= std::find(kept.begin(), kept.end(), label) == kept.end();
        if (narrower && (kept.empty() || !accepted(network.restrict(variable, kept, budget())))) {
          last_refusal_ =
              node.plan.describe(later, world_, domain_) +
              (assembly != nullptr ? (after ? " after " : " before ") +
                                         node.plan.describe(*assembly, world_, domain_)
                                   : std::string()) +
              ": " +
              (grasp   ? "no grasp of " + fixed_name + " clears " + held_name + " assembled into it"
               : after ? "no position left for " + fixed_name +
                             " where it rests on the table with " + held_name + " assembled into it"
                       : "no position left for " + fixed_name +
                             " where it rests on the table by itself");
          return false;
        }
      }
    }
  }
  return true;
}

bool Planner::may_meet(int object, int other, int partner) const {
  if (world_.scenario().objects[other].fixed) return false;
  const auto in_group = [&](int of) {
    const std::vector<int> group = start_state_.moving_with(of);
    return std::find(group.begin(), group.end(), other) != group.end();
  };
  return !in_group(object) && (partner < 0 || !in_group(partner));
}

bool Planner::clear_of_start(PartialPlan& node, int step, int a, int b, int other,
                             const WorldModel::Table& conflicts) const {
  cms::ConstraintNetwork& network = node.plan.network;
  bool any = false;
  for (const int la : network.labels(a))
    for (const int lb : b < 0 ? std::vector<int>{0} : network.labels(b)) any |= conflicts[la][lb];
  if (!any) return true;
  cms::ConstraintNetwork constrained = network;
  const cms::Consistency kept =
      b < 0 ? [&] {
        std::vector<int> free;
        for (const int la : network.labels(a))
          if (!conflicts[la][0]) free.push_back(la);
        return free.empty() ? cms::Consistency::kInconsistent
                            : constrained.restrict(a, free, budget());
      }()
            : constrained.post(a, b, [&](int la, int lb) { return conflicts[la][lb] == 0; },
                               budget());
  if (accepted(kept)) {
    network = std::move(constrained);
    return true;
  }
  // Nothing avoids it: `other` moves away before the step.
  const int away = add_variable(node, ParameterType::kPlacement, other,
                                "away_" + world_.scenario().objects[other].name + "_" +
                                    std::to_string(++node.position_names));
  node.open.push_back(
      {{"at", {{Term::Kind::kObject, other}, {Term::Kind::kVariable, away}}}, step, -1});
  return true;
}

bool Planner::add_link(PartialPlan& node, int producer, const OpenGoal& goal) const {
  if (!node.plan.ordering.add_before(producer, goal.consumer)) return false;
  if (goal.after >= 0 && !node.plan.ordering.add_before(goal.after, producer)) return false;
  node.plan.links.push_back({producer, goal.consumer, goal.atom.predicate, goal.atom.args});
  find_threats_to_link(node, node.plan.links.size() - 1);
  return true;
}

bool Planner::is_threat(const PartialPlan& node, const Threat& threat) const {
  const CausalLink& link = node.plan.links[threat.link];
  if (threat.clobberer == link.producer || threat.clobberer == link.consumer) return false;
  if (!node.plan.ordering.possibly_between(threat.clobberer, link.producer, link.consumer))
    return false;
  const GroundAtom atom{link.predicate, link.args};
  for (const GroundAtom& removed : deletes(node, threat.clobberer))
    if (possibly_unify(node, removed, atom)) return true;
  return false;
}

void Planner::find_threats_to_link(PartialPlan& node, std::size_t link) const {
  for (int step = 0; step < static_cast<int>(node.plan.steps.size()); ++step)
    if (is_threat(node, {link, step})) node.threats.push_back({link, step});
}

void Planner::find_threats_by_step(PartialPlan& node, int step) const {
  for (std::size_t link = 0; link < node.plan.links.size(); ++link)
    if (is_threat(node, {link, step})) node.threats.push_back({link, step});
}

bool Planner::bind_to_goal(const PartialPlan& child, FamilyStep& step, const ActionTemplate& action,
                           const Atom& add, const OpenGoal& goal) const {
  for (std::size_t i = 0; i < add.args.size(); ++i) {
    const int parameter = action.parameter_index(add.args[i]);
    const Term& term = goal.atom.args[i];
    if (parameter < 0) {
      if (term.kind != Term::Kind::kConstant || child.plan.constants[term.index] != add.args[i])
        return false;
      continue;
    }
    const Parameter& declared = action.parameters[parameter];
    const bool wants_object = declared.type == ParameterType::kObject;
    if (wants_object != (term.kind == Term::Kind::kObject)) return false;
    if (!wants_object && (declared.type == ParameterType::kGrasp) !=
                             (child.plan.variables[term.index].type == ParameterType::kGrasp))
      return false;
    if (step.args[parameter].index >= 0 && !(step.args[parameter] == term)) return false;
    step.args[parameter] = term;
  }
  // Every object parameter must now be bound.
  for (std::size_t p = 0; p < action.parameters.size(); ++p)
    if (action.parameters[p].type == ParameterType::kObject && step.args[p].index < 0) return false;
  return true;
}

bool Planner::bind_typed_parameters(PartialPlan& child, FamilyStep& step,
                                    const ActionTemplate& action) const {
  for (std::size_t p = 0; p < action.parameters.size(); ++p) {
    const Parameter& declared = action.parameters[p];
    if (declared.type == ParameterType::kObject) continue;
    const int object = step.args[action.parameter_index(declared.of)].index;
    // A fixed object has no grasps: no step may take hold of it.
    if (declared.type == ParameterType::kGrasp && world_.object(object).grasps.empty())
      return false;
    if (step.args[p].index >= 0) {
      PlanVariable& bound = child.plan.variables[step.args[p].index];
      if (bound.object != object) return false;
      if (declared.type == ParameterType::kPlacement) {
        std::vector<int> placements;
        for (int label = 1; label < static_cast<int>(world_.object(object).positions.size());
             ++label)
          placements.push_back(label);
        if (!accepted(child.plan.network.restrict(step.args[p].index, placements, budget())))
          return false;
      }
      continue;
    }
    const bool grasp = declared.type == ParameterType::kGrasp;
    int& counter = grasp ? child.grasp_names : child.position_names;
    const std::string name = (grasp ? "grasp_" : "pos_") + std::to_string(++counter);
    step.args[p] = {Term::Kind::kVariable, add_variable(child, declared.type, object, name)};
  }
  return true;
}

std::optional<PartialPlan> Planner::establish_by_new_step(const PartialPlan& node,
                                                          const OpenGoal& goal,
                                                          std::size_t action_index,
                                                          const Atom& add) const {
  const ActionTemplate& action = domain_.actions[action_index];
  if (node.actions + 1 > options_.max_steps) return std::nullopt;
  PartialPlan child = node;
  FamilyStep step{
      .id = child.plan.ordering.add_step(), .action = static_cast<int>(action_index), .args = {}};
  step.args.resize(action.parameters.size(), {Term::Kind::kObject, -1});
  for (const std::vector<Atom>* atoms : {&action.operational, &action.add, &action.del})
    for (const Atom& atom : *atoms)
      for (const std::string& arg : atom.args)
        if (action.parameter_index(arg) < 0) constant(child, arg);
  if (!bind_to_goal(child, step, action, add, goal) || !bind_typed_parameters(child, step, action))
    return std::nullopt;
  child.plan.steps.push_back(step);
  child.actions += 1;
  auto& ordering = child.plan.ordering;
  if (!ordering.add_before(kInitialStep, step.id) || !ordering.add_before(step.id, kFinishStep))
    return std::nullopt;
  for (std::size_t p = 0; p < action.parameters.size(); ++p)
    if (action.parameters[p].type == ParameterType::kPlacement &&
        !separate_places(child, step.id, step.args[p].index))
      return std::nullopt;
  for (const GeometricPrecondition& geometric : action.geometric)
    if (!post_geometric(child, step, geometric)) return std::nullopt;
  if (!add_link(child, step.id, goal)) return std::nullopt;
  find_threats_by_step(child, step.id);
  // Push the new step's operational preconditions so that the first one is on top.
  for (auto atom = action.operational.rbegin(); atom != action.operational.rend(); ++atom)
    child.open.push_back({ground(child, *atom, step), step.id, -1});
  return child;
}

bool Planner::consumed(const PartialPlan& node, int producer, const GroundAtom& atom,
                       int consumer) const {
  const auto deletes_atom = [&](int step) {
    for (const GroundAtom& removed : deletes(node, step))
      if (possibly_unify(node, removed, atom)) return true;
    return false;
  };
  if (!deletes_atom(consumer)) return false;
  for (const CausalLink& link : node.plan.links)
    if (link.producer == producer && link.consumer != consumer &&
        possibly_unify(node, {link.predicate, link.args}, atom) && deletes_atom(link.consumer))
      return true;
  return false;
}

std::vector<std::pair<int, GroundAtom>> Planner::existing_establishers(const PartialPlan& node,
                                                                       const OpenGoal& goal) const {
  std::vector<std::pair<int, GroundAtom>> candidates;
  for (int step = 0; step < static_cast<int>(node.plan.steps.size()); ++step) {
    if (step == goal.consumer || step == kFinishStep ||
        !node.plan.ordering.possibly_before(step, goal.consumer))
      continue;
    if (goal.after >= 0 &&
        (step == goal.after || !node.plan.ordering.possibly_before(goal.after, step)))
      continue;
    for (GroundAtom& atom : adds(node, step))
      if (possibly_unify(node, atom, goal.atom) && !consumed(node, step, atom, goal.consumer))
        candidates.emplace_back(step, std::move(atom));
  }
  return candidates;
}

std::size_t Planner::choose_goal(const PartialPlan& node) const {
  // Least-cost flaw first (Joslin & Pollack; ZLIFO's forced goals are its special case): the goal
  // with the fewest ways to establish it (existing steps plus templates), the newest among equals.
  // Goals any release can establish (gripper(empty)) thus wait until the steps are known.
  std::size_t best = node.open.size() - 1;
  int fewest = std::numeric_limits<int>::max();
  for (std::size_t i = node.open.size(); i-- > 0;) {
    const OpenGoal& goal = node.open[i];
    int ways = static_cast<int>(existing_establishers(node, goal).size());
    for (const ActionTemplate& action : domain_.actions)
      if (action.kind == ActionKind::kManipulation)
        for (const Atom& add : action.add)
          ways += add.predicate == goal.atom.predicate && add.args.size() == goal.atom.args.size();
    if (ways < fewest) {
      fewest = ways;
      best = i;
      if (ways <= 1) break;
    }
  }
  return best;
}

void Planner::establish(const PartialPlan& node, std::size_t goal_index,
                        std::vector<PartialPlan>& children) const {
  const OpenGoal goal = node.open[goal_index];
  const auto without_goal = [&] {
    PartialPlan child = node;
    child.open.erase(child.open.begin() + static_cast<std::ptrdiff_t>(goal_index));
    return child;
  };
  // By a step already in the plan (the initial state first), constrained to precede the consumer.
  for (const auto& [step, atom] : existing_establishers(node, goal)) {
    PartialPlan child = without_goal();
    if (!unify(child, atom, goal.atom) || !add_link(child, step, goal)) continue;
    children.push_back(std::move(child));
  }
  // By a new step from every manipulation template whose add list has the predicate.
  for (std::size_t a = 0; a < domain_.actions.size(); ++a) {
    const ActionTemplate& action = domain_.actions[a];
    if (action.kind != ActionKind::kManipulation) continue;
    for (const Atom& add : action.add) {
      if (add.predicate != goal.atom.predicate || add.args.size() != goal.atom.args.size())
        continue;
      if (std::optional<PartialPlan> child = establish_by_new_step(without_goal(), goal, a, add))
        children.push_back(std::move(*child));
    }
  }
}

void Planner::resolve(const PartialPlan& node, const Threat& threat,
                      std::vector<PartialPlan>& children) const {
  const CausalLink link = node.plan.links[threat.link];
  const auto without_threat = [&] {
    PartialPlan child = node;
    child.threats.erase(std::find_if(
        child.threats.begin(), child.threats.end(),
        [&](const Threat& t) { return t.link == threat.link && t.clobberer == threat.clobberer; }));
    return child;
  };
  // Promotion: the clobberer after the consumer.
  if (PartialPlan child = without_threat();
      child.plan.ordering.add_before(link.consumer, threat.clobberer))
    children.push_back(std::move(child));
  // Demotion: the clobberer before the producer.
  if (PartialPlan child = without_threat();
      child.plan.ordering.add_before(threat.clobberer, link.producer))
    children.push_back(std::move(child));
  // Re-establishment (ground atoms only: dropping a link cannot undo a codesignation).
  const bool ground = std::none_of(link.args.begin(), link.args.end(), [](const Term& term) {
    return term.kind == Term::Kind::kVariable;
  });
  if (ground) {
    PartialPlan child = without_threat();
    if (child.plan.ordering.add_before(threat.clobberer, link.consumer)) {
      child.plan.links.erase(child.plan.links.begin() + static_cast<std::ptrdiff_t>(threat.link));
      std::erase_if(child.threats, [&](const Threat& t) { return t.link == threat.link; });
      for (Threat& t : child.threats)
        if (t.link > threat.link) --t.link;
      child.open.push_back({{link.predicate, link.args}, link.consumer, threat.clobberer});
      children.push_back(std::move(child));
    }
  }
}

std::optional<PartialPlan> Planner::initial_plan() const {
  PartialPlan node;
  PlanFamily& plan = node.plan;
  constant(node, "empty");
  for (std::size_t o = 0; o < world_.object_count(); ++o) {
    const std::string name = "initial_" + world_.scenario().objects[o].name;
    add_variable(node, ParameterType::kPosition, static_cast<int>(o), name);
    if (plan.network.restrict(static_cast<int>(o), {0}, budget()) != cms::Consistency::kConsistent)
      throw PlanError("internal: cannot pin the initial position of " + name);
  }
  plan.steps.push_back({.id = plan.ordering.add_step(), .action = -1, .args = {}});  // initial
  plan.steps.push_back({.id = plan.ordering.add_step(), .action = -1, .args = {}});  // finish
  plan.ordering.add_before(kInitialStep, kFinishStep);
  for (const GoalWorld& goal : world_.goals()) {
    if (goal.kind == GoalWorld::Kind::kAssembled) {
      node.open.push_back(
          {{"assembled", {{Term::Kind::kObject, goal.held}, {Term::Kind::kObject, goal.fixed}}},
           kFinishStep,
           -1});
      continue;
    }
    // at(object, place): at(object, pos) for a position variable limited to the place's labels.
    const std::string& place = world_.scenario().places[goal.place].name;
    const int variable =
        add_variable(node, ParameterType::kPosition, goal.held,
                     "at_" + place + "_" + world_.scenario().objects[goal.held].name);
    if (goal.at_place.empty() ||
        plan.network.restrict(variable, goal.at_place, budget()) != cms::Consistency::kConsistent)
      return std::nullopt;  // no position of the object at the place
    node.open.push_back(
        {{"at", {{Term::Kind::kObject, goal.held}, {Term::Kind::kVariable, variable}}},
         kFinishStep,
         -1});
  }
  std::reverse(node.open.begin(), node.open.end());  // the first goal on top
  return node;
}

void Planner::add_satisfied_links(PlanFamily& plan) const {
  for (const CausalLink& link : plan.links) {
    std::string condition = link.predicate + "(";
    for (std::size_t i = 0; i < link.args.size(); ++i)
      condition += (i ? ", " : "") + plan.term_name(link.args[i], world_);
    plan.satisfied.push_back({SatisfiedGoal::Level::kOperational, condition + ")", link.consumer,
                              link.producer != kInitialStep
                                  ? "step " + std::to_string(link.producer)
                              : link.consumer == kFinishStep ? std::string("already satisfied")
                                                             : std::string("initial state")});
  }
}

std::string Planner::no_plan_reason(std::size_t refused, const std::string& first_refusal) const {
  std::string reason = "no plan with at most " + std::to_string(options_.max_steps) +
                       " actions reaches the goals (every refinement was inconsistent)";
  if (const std::optional<std::string> obstacle = world_.relaxed_obstacle())
    reason += ": " + *obstacle;
  else if (!last_refusal_.empty())
    reason +=
        "; each goal is reachable alone, but not together: the last refusal was " + last_refusal_;
  if (refused > 0)
    reason += "; " + std::to_string(refused) +
              " complete plan families were refused, the first because " + first_refusal;
  if (budget_refusals_ > 0)
    reason += "; " + std::to_string(budget_refusals_) +
              " constraint posts ran out of the network's search budget (network_budget), so "
              "this is not a proof that none exists";
  return reason;
}

PlanFamily Planner::run() {
  const auto start = std::chrono::steady_clock::now();
  Agenda agenda;
  PostingStats stats;
  if (std::optional<PartialPlan> start_plan = initial_plan())
    agenda.push(std::move(*start_plan), stats.generated++);
  const auto finish = [&](PlanFamily plan, PostingStatus status, std::string reason) {
    plan.status = status;
    plan.reason = std::move(reason);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    plan.stats = stats;
    return plan;
  };
  std::vector<PartialPlan> children;
  std::string first_refusal;  // why the first complete family was refused
  while (!agenda.empty()) {
    check_deadline();  // a batch's --time-limit (common/deadline.hpp); cheap without one
    if (stats.expanded >= options_.max_nodes)
      return finish(
          std::move(agenda.best().plan), PostingStatus::kNodeLimit,
          "stopped after " + std::to_string(options_.max_nodes) +
              " partial plans (max_nodes) without a complete plan" +
              (stats.refused == 0 ? std::string()
                                  : "; " + std::to_string(stats.refused) +
                                        " complete plan families were refused, the first because " +
                                        first_refusal));
    PartialPlan node = agenda.take_best();
    ++stats.expanded;
    std::erase_if(node.threats, [&](const Threat& t) { return !is_threat(node, t); });
    children.clear();
    if (!subassemblies_move_as_one(node)) continue;
    if (!node.threats.empty()) {
      resolve(node, node.threats.front(), children);
    } else if (!node.open.empty()) {
      establish(node, choose_goal(node), children);
    } else {
      if (options_.accept) {
        node.plan.status = PostingStatus::kPlanned;
        if (std::optional<std::string> refusal = options_.accept(node.plan)) {
          if (stats.refused++ == 0) first_refusal = std::move(*refusal);
          continue;
        }
      }
      add_satisfied_links(node.plan);
      return finish(std::move(node.plan), PostingStatus::kPlanned, "");
    }
    // Pushed last-first: among equal priorities the newest is expanded first, so the first
    // refinement (SPAR's preferred: promotion before demotion before re-establishment, an
    // existing step before a new one) is tried first.
    for (auto child = children.rbegin(); child != children.rend(); ++child)
      agenda.push(std::move(*child), stats.generated++);
  }
  return finish(PlanFamily{}, PostingStatus::kNoPlan, no_plan_reason(stats.refused, first_refusal));
}

}  // namespace

const char* to_string(PostingStatus status) {
  switch (status) {
    case PostingStatus::kPlanned:
      return "planned";
    case PostingStatus::kNoPlan:
      return "no_plan";
    case PostingStatus::kNodeLimit:
      return "node_limit";
  }
  return "?";
}

std::string PlanFamily::term_name(const Term& term, const WorldModel& world) const {
  switch (term.kind) {
    case Term::Kind::kObject:
      return world.scenario().objects.at(term.index).name;
    case Term::Kind::kVariable:
      return variables.at(network.representative(term.index)).name;
    case Term::Kind::kConstant:
      return constants.at(term.index);
  }
  return "?";
}

std::string PlanFamily::describe(const FamilyStep& step, const WorldModel& world,
                                 const Domain& domain) const {
  if (step.action < 0) return step.id == kInitialStep ? "initial state" : "finish";
  std::string text = domain.actions[step.action].name + "(";
  for (std::size_t i = 0; i < step.args.size(); ++i)
    text += (i ? ", " : "") + term_name(step.args[i], world);
  return text + ")";
}

PlanFamily post_plan(const WorldModel& world, const Domain& domain, const PostingOptions& options) {
  if (world.goals().empty()) throw PlanError("the scenario has no goals: nothing to plan");
  return Planner(world, domain, options).run();
}

}  // namespace spar::planner
