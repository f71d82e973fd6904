#include "spar/qr/planner.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

namespace spar::qr {
namespace {

// Index of a direction in per-control [+, -] pairs.
int direction_slot(Sign direction) { return direction == Sign::kPlus ? 0 : 1; }
double direction_factor(Sign direction) { return direction == Sign::kPlus ? 1.0 : -1.0; }

// Preference ranks of step 9c, best first. "No change possible" needs no rank: such a cause fails
// when tried and the next one is tried.
enum Rank : int {
  kMustChange = 0,
  kUnmarked = 1,
  kResistChange = 2,
  kSteadyMostLikely = 3,
  kCycleBack = 4,
};

}  // namespace

std::string to_string(Status status) {
  switch (status) {
    case Status::kContinue:
      return "continue";
    case Status::kSuccess:
      return "success";
    case Status::kNoDirectionLeft:
      return "no direction left";
    case Status::kBudgetExhausted:
      return "trial budget exhausted";
  }
  return "?";
}

bool Limit::visible_from(const std::vector<double>& point,
                         const std::vector<ControlSpec>& controls) const {
  for (std::size_t k = 0; k < controls.size(); ++k) {
    const double half = controls[k].resolution / 2;
    switch (visibility[k]) {
      case Visibility::kEverywhere:
        break;
      case Visibility::kAtMost:
        if (point[k] > anchor[k] + half) return false;
        break;
      case Visibility::kAtLeast:
        if (point[k] < anchor[k] - half) return false;
        break;
      case Visibility::kSameValue:
        if (std::abs(point[k] - anchor[k]) >= half) return false;
        break;
    }
  }
  return true;
}

bool Limit::excludes(const std::vector<double>& point,
                     const std::vector<ControlSpec>& controls) const {
  const double half = controls[control].resolution / 2;
  const bool beyond =
      side == Side::kLower ? point[control] < bound + half : point[control] > bound - half;
  return beyond && visible_from(point, controls);
}

const Limit* ExecutionHistory::excluding_limit(const std::vector<double>& point) const {
  for (const Limit& limit : limits_) {
    if (limit.excludes(point, controls_)) return &limit;
  }
  return nullptr;
}

void ExecutionHistory::retract_guessed_limit(int trial) {
  std::erase_if(limits_,
                [trial](const Limit& limit) { return limit.guessed && limit.trial == trial; });
}

bool ExecutionHistory::within_physical_limits(const std::vector<double>& point) const {
  if (point.size() != controls_.size()) return false;
  for (std::size_t k = 0; k < controls_.size(); ++k) {
    const double slack = 1e-9 * controls_[k].resolution;
    if (point[k] < controls_[k].minimum - slack || point[k] > controls_[k].maximum + slack) {
      return false;
    }
  }
  return true;
}

ExecutionHistory::Range ExecutionHistory::contextual_range(const std::vector<double>& point,
                                                           int control, Sign direction) const {
  const ControlSpec& spec = controls_.at(control);
  const double slack = 1e-9 * spec.resolution;
  std::vector<double> probe = point;
  Range range;
  // The grid has at most (maximum - minimum) / resolution + 1 values, so the walk is bounded.
  for (int k = 1;; ++k) {
    const double value = point[control] + direction_factor(direction) * k * spec.resolution;
    if (value > spec.maximum + slack || value < spec.minimum - slack) {
      range.end = value;
      return range;
    }
    probe[control] = value;
    if (const Limit* limit = excluding_limit(probe)) {
      range.blocker = *limit;
      range.end = value;
      return range;
    }
    range.values.push_back(value);
  }
}

// What one trial's planning reads (steps 3-8): the marks per node, the contextual ranges per
// control, and the most recent planned change per node.
struct Planner::TrialContext {
  std::vector<bool> must_change;  // per node
  std::vector<bool> resist;       // per node, for the thread being planned
  std::vector<bool> cycle_back;   // per node
  std::vector<std::array<ExecutionHistory::Range, 2>> ranges;  // per control, [+, -]
  // Per node: its change in the most recent plan that changed it (+ or -), or 0. Ties between
  // directions continue it: the history's qualitative vector points towards the goal region.
  std::vector<Sign> last_change;
  // Per node: that change rested on a guess, so continuing it is a guess too.
  std::vector<bool> last_change_guessed;
};

// One thread's planning state. The marks and ranges are shared (pointer to the trial's context);
// the decisions are copied on each tentative step so that a failed branch leaves no trace.
struct Planner::Search {
  const TrialContext* context{nullptr};
  std::vector<Sign> planned;   // planned change per node (0 where undecided)
  std::vector<bool> decided;   // per node
  std::vector<int> path;       // nodes from the result down to the control
  std::optional<int> control;  // the one control this trial changes
  bool guessed{false};         // some direction on the path was an unbroken tie

  [[nodiscard]] bool open(int control_index, Sign direction) const {
    return !context->ranges[control_index][direction_slot(direction)].values.empty();
  }
};

Planner::Planner(Network network, std::vector<ControlSpec> controls, std::vector<Goal> goals)
    : network_(std::move(network)), goals_(std::move(goals)), history_(std::move(controls)) {
  control_of_node_.assign(network_.size(), -1);
  for (std::size_t c = 0; c < history_.controls().size(); ++c) {
    const ControlSpec& spec = history_.controls()[c];
    if (spec.node < 0 || spec.node >= network_.size() ||
        network_.node(spec.node).kind != NodeKind::kControl) {
      throw QrError("control spec #" + std::to_string(c) + " does not name a control node");
    }
    if (!(spec.minimum < spec.maximum) || !(spec.resolution > 0) || spec.step < spec.resolution) {
      throw QrError("control '" + network_.node(spec.node).name +
                    "' needs minimum < maximum, resolution > 0 and step >= resolution");
    }
    control_of_node_[spec.node] = static_cast<int>(c);
  }
  for (const Goal& goal : goals_) {
    if (goal.node < 0 || goal.node >= network_.size() ||
        network_.node(goal.node).kind != NodeKind::kThreshold) {
      throw QrError("every goal must name a threshold node");
    }
  }
}

bool Planner::plan_control(Search& search, int id, Sign desired) const {
  const int control = control_of_node_[id];
  if (control < 0 || (search.control && *search.control != control)) return false;
  if (!search.open(control, desired)) return false;
  search.decided[id] = true;
  search.planned[id] = desired;
  search.path.push_back(id);
  search.control = control;
  return true;
}

struct Planner::CauseChoice {
  int cause;
  int rank;
  Potentials potentials;
};

std::vector<Planner::CauseChoice> Planner::ranked_causes(const Search& search, int id,
                                                         Sign desired) const {
  const Node& node = network_.node(id);
  const TrialContext& context = *search.context;
  std::vector<CauseChoice> candidates;
  for (std::size_t position = 0; position < node.causes.size(); ++position) {
    const int cause = node.causes[position];
    if (search.decided[cause]) continue;
    Potentials potentials =
        network_.cause_change_potentials(id, static_cast<int>(position), desired, search.planned);
    int rank = kUnmarked;
    if (context.must_change[cause]) {
      rank = kMustChange;
    } else if (context.cycle_back[cause]) {
      rank = kCycleBack;
    } else if (potentials[index(Sign::kZero)] >
               std::max(potentials[index(Sign::kPlus)], potentials[index(Sign::kMinus)])) {
      rank = kSteadyMostLikely;
    } else if (context.resist[cause]) {
      rank = kResistChange;
    }
    // Section 5: limits zero out the potentials of changes that would cross them.
    if (const int control = control_of_node_[cause]; control >= 0) {
      for (Sign direction : {Sign::kPlus, Sign::kMinus}) {
        if (!search.open(control, direction)) potentials[index(direction)] = 0;
      }
    }
    candidates.push_back({cause, rank, potentials});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const CauseChoice& a, const CauseChoice& b) {
                     if (a.rank != b.rank) return a.rank < b.rank;
                     return std::max(a.potentials[0], a.potentials[2]) >
                            std::max(b.potentials[0], b.potentials[2]);
                   });
  return candidates;
}

std::array<Sign, 2> Planner::direction_order(const TrialContext& context,
                                             const CauseChoice& choice) const {
  std::array<Sign, 2> directions{Sign::kPlus, Sign::kMinus};
  const double plus = choice.potentials[index(Sign::kPlus)];
  const double minus = choice.potentials[index(Sign::kMinus)];
  bool minus_first = minus > plus;
  if (plus == minus) {
    const Sign last = context.last_change[choice.cause];
    minus_first = last == Sign::kMinus;
    if (const int control = control_of_node_[choice.cause]; control >= 0 && last == Sign::kZero) {
      const auto& ranges = context.ranges[control];
      minus_first = ranges[1].values.size() > ranges[0].values.size();
    }
  }
  if (minus_first) std::swap(directions[0], directions[1]);
  return directions;
}

bool Planner::plan_node(Search& search, int id, Sign desired, int depth) const {
  // Each level moves to a cause, whose index is smaller: depth never exceeds the network size.
  if (depth > network_.size()) return false;
  if (search.decided[id]) return search.planned[id] == desired;
  const Node& node = network_.node(id);
  if (node.kind == NodeKind::kConstant) return false;
  if (node.kind == NodeKind::kControl) return plan_control(search, id, desired);
  const TrialContext& context = *search.context;
  // 9c: the causes by preference.
  for (const CauseChoice& candidate : ranked_causes(search, id, desired)) {
    // 9d: the direction with the higher likelihood potential first; equal ones are a guess
    // unless the last change decided them.
    const double plus = candidate.potentials[index(Sign::kPlus)];
    const bool guess = plus == candidate.potentials[index(Sign::kMinus)] &&
                       (context.last_change[candidate.cause] == Sign::kZero ||
                        context.last_change_guessed[candidate.cause]);
    for (Sign direction : direction_order(context, candidate)) {
      if (candidate.potentials[index(direction)] <= 0) continue;
      // 9e: make the change on a copy and propagate it towards the ultimate causes.
      Search attempt = search;
      attempt.decided[id] = true;
      attempt.planned[id] = desired;
      attempt.path.push_back(id);
      attempt.guessed = attempt.guessed || guess;
      if (plan_node(attempt, candidate.cause, direction, depth + 1)) {
        search = std::move(attempt);
        return true;
      }
    }
  }
  return false;
}

std::vector<Visibility> Planner::limit_visibility(int goal, int control) const {
  const std::vector<ControlSpec>& controls = history_.controls();
  const int cause = network_.node(goals_[goal].node).causes.front();
  const Sign helps = goals_[goal].desired ? Sign::kPlus : Sign::kMinus;
  std::vector<Visibility> visibility(controls.size(), Visibility::kEverywhere);
  for (std::size_t k = 0; k < controls.size(); ++k) {
    if (static_cast<int>(k) == control) continue;
    const Sign effect = network_.propagate_changes({{controls[k].node, Sign::kPlus}})[cause];
    if (effect == Sign::kZero) {
      visibility[k] = Visibility::kEverywhere;
    } else if (effect == helps) {
      visibility[k] = Visibility::kAtMost;  // lower values of k are at least as bad
    } else if (effect == negate(helps)) {
      visibility[k] = Visibility::kAtLeast;
    } else {
      visibility[k] = Visibility::kSameValue;
    }
  }
  return visibility;
}

bool Planner::evaluate(const std::vector<double>& point, const Outcome& outcome, Trial& trial,
                       TrialContext& context) {
  const std::vector<ControlSpec>& controls = history_.controls();
  for (std::size_t c = 0; c < controls.size(); ++c)
    network_.set_control_value(controls[c].node, point[c]);
  for (std::size_t g = 0; g < goals_.size(); ++g)
    network_.observe_threshold(goals_[g].node, outcome[g]);
  network_.propagate_values();
  context.must_change.assign(network_.size(), false);
  bool success = true;
  for (std::size_t g = 0; g < goals_.size(); ++g) {
    if (outcome[g] != std::optional<bool>(goals_[g].desired)) success = false;
    if (outcome[g] && *outcome[g] != goals_[g].desired) {
      trial.marks.must_change.push_back(static_cast<int>(g));
      context.must_change[goals_[g].node] = true;
    }
  }
  return success;
}

void Planner::remember_last_changes(TrialContext& context) const {
  context.last_change.assign(network_.size(), Sign::kZero);
  context.last_change_guessed.assign(network_.size(), false);
  for (auto earlier = history_.trials().rbegin(); earlier != history_.trials().rend(); ++earlier) {
    if (!earlier->plan) continue;
    for (int id = 0; id < network_.size(); ++id) {
      const Sign change = earlier->plan->node_changes[id];
      if (context.last_change[id] == Sign::kZero &&
          (change == Sign::kPlus || change == Sign::kMinus)) {
        context.last_change[id] = change;
        context.last_change_guessed[id] = earlier->plan->guessed;
      }
    }
  }
}

void Planner::set_ranges(const std::vector<double>& point,
                         const std::optional<PlannedChange>& previous_plan, Trial& trial,
                         TrialContext& context) const {
  const std::vector<ControlSpec>& controls = history_.controls();
  context.ranges.clear();
  context.cycle_back.assign(network_.size(), false);
  trial.marks.at_maximum.clear();
  trial.marks.at_minimum.clear();
  trial.marks.cycle_back.clear();
  for (std::size_t c = 0; c < controls.size(); ++c) {
    context.ranges.push_back({history_.contextual_range(point, static_cast<int>(c), Sign::kPlus),
                              history_.contextual_range(point, static_cast<int>(c), Sign::kMinus)});
    if (context.ranges[c][0].values.empty()) trial.marks.at_maximum.push_back(static_cast<int>(c));
    if (context.ranges[c][1].values.empty()) trial.marks.at_minimum.push_back(static_cast<int>(c));
    // 7. Cycle-back.
    if (previous_plan && previous_plan->control == static_cast<int>(c) &&
        context.ranges[c][direction_slot(previous_plan->direction)].values.empty()) {
      context.cycle_back[controls[c].node] = true;
      trial.marks.cycle_back.push_back(static_cast<int>(c));
    }
  }
}

std::optional<Planner::Search> Planner::plan_threads(const Trial& trial, TrialContext& context,
                                                     int& planned_goal) const {
  for (int g : trial.marks.must_change) {
    context.resist.assign(network_.size(), false);
    for (int id = 0; id < network_.size(); ++id) {
      bool resists = network_.node(id).kind == NodeKind::kConstant;
      for (std::size_t other = 0; other < goals_.size() && !resists; ++other)
        resists = static_cast<int>(other) != g && network_.is_ancestor(id, goals_[other].node);
      context.resist[id] = resists;
    }
    Search search{&context,
                  std::vector<Sign>(network_.size(), Sign::kZero),
                  std::vector<bool>(network_.size(), false),
                  {},
                  std::nullopt};
    const Sign needed = goals_[g].desired ? Sign::kPlus : Sign::kMinus;
    if (plan_node(search, goals_[g].node, needed, 0) && search.control) {
      planned_goal = g;
      return search;
    }
  }
  return std::nullopt;
}

bool Planner::retract_blocking_guesses(const TrialContext& context, Trial& trial) {
  std::vector<int> guessed;
  for (const auto& pair : context.ranges)
    for (const ExecutionHistory::Range& range : pair)
      if (range.values.empty() && range.blocker && range.blocker->guessed)
        guessed.push_back(range.blocker->trial);
  if (guessed.empty()) return false;
  std::sort(guessed.begin(), guessed.end());
  guessed.erase(std::unique(guessed.begin(), guessed.end()), guessed.end());
  for (int earlier : guessed) {
    history_.retract_guessed_limit(earlier);
    trial.limits_retracted.push_back(earlier);
  }
  return true;
}

void Planner::record_blocking(const TrialContext& context, Trial& trial) const {
  const std::vector<ControlSpec>& controls = history_.controls();
  for (std::size_t c = 0; c < controls.size(); ++c)
    for (Sign direction : {Sign::kPlus, Sign::kMinus}) {
      const ExecutionHistory::Range& range = context.ranges[c][direction_slot(direction)];
      if (!range.values.empty()) continue;
      trial.blocking.push_back(
          {static_cast<int>(c), direction,
           range.blocker ? std::optional<int>(range.blocker->trial) : std::nullopt,
           range.blocker ? range.blocker->bound
                         : (direction == Sign::kPlus ? controls[c].maximum : controls[c].minimum)});
    }
}

void Planner::adopt_plan(const std::vector<double>& point, const Search& plan, int planned_goal,
                         const TrialContext& context, Trial& trial) {
  const std::vector<ControlSpec>& controls = history_.controls();
  const int control = *plan.control;
  PlannedChange change;
  change.control = control;
  change.direction = plan.planned[controls[control].node];
  change.goal = planned_goal;
  change.path = plan.path;
  change.guessed = plan.guessed;
  change.node_changes = network_.propagate_changes({{controls[control].node, change.direction}});
  change.from = point[control];
  Limit limit{control,
              point[control],
              change.direction == Sign::kPlus ? Side::kLower : Side::kUpper,
              planned_goal,
              trial.number,
              point,
              limit_visibility(planned_goal, control),
              plan.guessed};
  // 11. The next value within the contextual range.
  const ExecutionHistory::Range& range = context.ranges[control][direction_slot(change.direction)];
  if (range.blocker) {
    const double target = (point[control] + range.end) / 2;
    change.to = *std::min_element(
        range.values.begin(), range.values.end(),
        [target](double a, double b) { return std::abs(a - target) < std::abs(b - target); });
  } else {
    const auto steps = static_cast<std::size_t>(
        std::max(1.0, std::round(controls[control].step / controls[control].resolution)));
    change.to = range.values[std::min(steps, range.values.size()) - 1];
  }
  history_.assert_limit(limit);
  trial.limits_asserted.push_back(std::move(limit));
  trial.plan = std::move(change);
}

const Trial& Planner::record_and_plan(const std::vector<double>& point, const Outcome& outcome) {
  const auto started = std::chrono::steady_clock::now();
  const std::vector<ControlSpec>& controls = history_.controls();
  if (point.size() != controls.size() || outcome.size() != goals_.size()) {
    throw QrError("a trial needs " + std::to_string(controls.size()) + " control values and " +
                  std::to_string(goals_.size()) + " results");
  }
  // 1. Record.
  Trial trial;
  trial.number = static_cast<int>(history_.trials().size()) + 1;
  trial.controls = point;
  trial.outcome = outcome;
  const auto finish = [&](Status status) -> const Trial& {
    trial.status = status;
    trial.planning_microseconds =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - started)
            .count();
    history_.add_trial(std::move(trial));
    return history_.trials().back();
  };
  // 2. Evaluate; 3-4. success, or the must-change results.
  TrialContext context;
  if (evaluate(point, outcome, trial, context)) return finish(Status::kSuccess);
  // 6, 8. Visible limits -> contextual ranges -> at-maximum / at-minimum.
  remember_last_changes(context);
  std::optional<PlannedChange> previous_plan;
  if (!history_.trials().empty()) previous_plan = history_.trials().back().plan;
  std::optional<Search> plan;
  int planned_goal = -1;
  while (true) {
    set_ranges(point, previous_plan, trial, context);
    // 9. Plan, thread by thread in goal order; 5. resist-change per thread.
    plan = plan_threads(trial, context, planned_goal);
    // No direction: retract the guessed limits that block, if any, and plan again. Each pass
    // removes at least one limit, so the loop ends.
    if (plan || !retract_blocking_guesses(context, trial)) break;
  }
  if (!plan) {
    record_blocking(context, trial);
    return finish(Status::kNoDirectionLeft);
  }
  // 10. The plan and the limit this failed trial asserts.
  adopt_plan(point, *plan, planned_goal, context, trial);
  return finish(Status::kContinue);
}

RunResult run_trials(Planner& planner, const std::vector<double>& start, const World& world,
                     int budget) {
  if (!planner.history().within_physical_limits(start)) {
    throw QrError("the start point lies outside the physical limits of the controls");
  }
  RunResult result;
  std::vector<double> point = start;
  for (int n = 0; n < budget; ++n) {
    const Trial& trial = planner.record_and_plan(point, world(point));
    result.trials.push_back(trial);
    if (trial.status != Status::kContinue) {
      result.status = trial.status;
      return result;
    }
    point[trial.plan->control] = trial.plan->to;
  }
  result.status = Status::kBudgetExhausted;
  return result;
}

}  // namespace spar::qr
