#include "spar/planner/instances.hpp"

#include <algorithm>

#include "spar/planner/error.hpp"

namespace spar::planner {

InstanceEnumerator::InstanceEnumerator(const PlanFamily& family, const WorldModel& world,
                                       const Domain& domain, std::size_t max_examined, bool measure)
    : family_(family),
      world_(world),
      domain_(domain),
      labelings_(family.network),
      max_examined_(max_examined),
      measure_(measure) {
  if (family.status != PostingStatus::kPlanned)
    throw PlanError("no plan instances: the plan family is not complete (" +
                    std::string(to_string(family.status)) + ")");
}

std::optional<PlanInstance> InstanceEnumerator::next() {
  while (true) {
    if (orders_) {
      if (examined_ >= max_examined_) return std::nullopt;
      if (std::optional<std::vector<int>> order = orders_->next()) {
        std::vector<int> actions;
        for (const int step : *order)
          if (family_.steps[step].action >= 0) actions.push_back(step);
        PlanInstance instance = build(*labeling_, actions);
        ++examined_;
        if (std::optional<std::string> conflict =
                check_collisions(instance, world_, domain_, measure_)) {
          if (refused_++ == 0) first_conflict_ = std::move(*conflict);
          continue;
        }
        instance.index = count_++;
        return instance;
      }
    }
    labeling_ = labelings_.next();
    if (!labeling_) return std::nullopt;
    orders_.emplace(family_.ordering);
  }
}

PlanInstance InstanceEnumerator::build(const std::vector<int>& labeling,
                                       const std::vector<int>& order) const {
  PlanInstance instance;
  instance.labeling = labeling;
  instance.order = order;
  const auto label = [&](const Term& term) {
    return labeling[family_.network.representative(term.index)];
  };
  for (const int id : order) {
    const FamilyStep& family_step = family_.steps[id];
    const ActionTemplate& action = domain_.actions[family_step.action];
    InstanceStep step;
    step.step = id;
    step.action = family_step.action;
    step.action_name = action.name;
    int position_object = -1;
    for (std::size_t p = 0; p < action.parameters.size(); ++p) {
      const Parameter& parameter = action.parameters[p];
      const Term& term = family_step.args[p];
      const int owner = parameter.type == ParameterType::kObject
                            ? -1
                            : family_step.args[action.parameter_index(parameter.of)].index;
      if (parameter.type == ParameterType::kGrasp && step.grasp < 0) {
        step.object = owner;
        step.grasp = label(term);
      } else if ((parameter.type == ParameterType::kPosition ||
                  parameter.type == ParameterType::kPlacement) &&
                 step.position < 0) {
        position_object = owner;
        step.position = label(term);
      }
    }
    if (step.object < 0) step.object = position_object;
    if (step.position >= 0) {
      const PositionLabel& where = world_.object(position_object).positions[step.position];
      if (position_object == step.object) {
        step.object_pose = where.pose;
        step.stable_pose = where.stable_pose;
      } else {  // an assembly: the position is the fixed object's, the held one goes to T_f Ta
        const GoalWorld* goal = world_.goal(step.object, position_object);
        if (goal == nullptr)
          throw PlanError("internal: step " + std::to_string(id) + " joins objects no goal names");
        const auto& assembled =
            std::get<AssembledGoal>(world_.scenario().goals[goal - world_.goals().data()]);
        step.fixed_object = position_object;
        step.fixed_pose = where.pose;
        step.held_pose = where.pose * assembled.relative;
        step.object_pose = step.held_pose;
      }
    }
    if (step.grasp >= 0) {
      step.gripper_pose =
          step.object_pose * world_.object(step.object).grasps[step.grasp].gripper_in_object;
      // The branch comes from check_collisions (the collision-checked one), never from reach().
      step.reach.tilt = tilt_from_down(step.gripper_pose);
    }
    instance.steps.push_back(std::move(step));
  }
  return instance;
}

namespace {

bool has_at(const std::vector<Atom>& atoms) {
  return std::any_of(atoms.begin(), atoms.end(),
                     [](const Atom& atom) { return atom.predicate == "at"; });
}

}  // namespace

void apply_step(WorldState& state, const InstanceStep& step, const Domain& domain) {
  if (step.grasp < 0) return;  // sensing: nothing moves
  const ActionTemplate& action = domain.actions[step.action];
  if (step.is_assembly()) {
    state.move(step.object, step.held_pose);
    state.carrier[step.object] = step.fixed_object;
    state.held = -1;
  } else if (has_at(action.add)) {  // a release: the object rests where the step puts it
    state.move(step.object, step.object_pose);
    state.held = -1;
  } else if (has_at(action.del)) {  // a grasp that lifts the object
    state.held = step.object;
  }
}

std::optional<std::string> check_collisions(PlanInstance& instance, const WorldModel& world,
                                            const Domain& domain, bool measure) {
  WorldState state = world.initial_state();
  for (InstanceStep& step : instance.steps) {
    if (step.grasp < 0) continue;
    const std::vector<int> group = state.moving_with(step.object);
    step.carried.assign(group.begin() + 1, group.end());
    if (step.is_assembly()) {
      const GoalWorld* goal = world.goal(step.object, step.fixed_object);
      step.collision = world.check_insertion(state, static_cast<int>(goal - world.goals().data()),
                                             step.grasp, step.fixed_pose, measure);
    } else {
      step.collision = world.check_grasp(state, step.object, step.grasp, step.object_pose, measure);
    }
    // The step uses the first IK branch clear of everything where it is (the table-only choice
    // of build() may hit an object), and no other: none when no branch is clear.
    step.reach.solution = step.collision.arm;
    step.reach.reachable = step.reach.solution.has_value();
    const int positioned = step.is_assembly() ? step.fixed_object : step.object;
    const auto refused = [&](const std::string& why) {
      return domain.actions[step.action].name + "(" + world.scenario().objects[step.object].name +
             ", " + world.object(step.object).grasps[step.grasp].label + ", " +
             world.object(positioned).positions[step.position].name + "): " + why;
    };
    if (!step.collision.clear) return refused(step.collision.conflict);
    apply_step(state, step, domain);
    // Released, what the step put down (or inserted into) must stand as one body.
    if (state.held < 0)
      if (std::optional<std::string> topples = world.check_rest(state, positioned))
        return refused(*topples);
  }
  return std::nullopt;
}

InstanceList enumerate_instances(const PlanFamily& family, const WorldModel& world,
                                 const Domain& domain, std::size_t limit) {
  InstanceList list;
  InstanceEnumerator enumerator(family, world, domain);
  while (std::optional<PlanInstance> instance = enumerator.next()) {
    if (list.instances.size() == limit) {
      list.limit_reached = true;
      break;
    }
    list.instances.push_back(std::move(*instance));
  }
  return list;
}

}  // namespace spar::planner
