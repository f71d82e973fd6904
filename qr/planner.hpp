// The qualitative reasoning planner with a numeric execution history (seeds/000, sections 4-5).
//
// The planner searches for control values by trial. After each trial the qualitative network says
// WHICH control to change and in WHICH direction (planning back from the results that must change
// to an ultimate cause), and the numeric execution history says HOW FAR: every failed trial asserts
// a limit along the control its plan changed, the limits visible from the current point bound the
// "contextual range" of the next value, and a direction whose range is empty has its likelihood
// potentials zeroed, forcing another direction or another control.
//
// The trial loop (record_and_plan). Steps 8-12 are the seed's; steps 1-7 were lost from the seed
// and are our reconstruction:
//   1. Record the trial (control values, observed results) on the history.
//   2. Evaluate: set the control nodes' numbers and the threshold nodes' observations, propagate
//      qualitative values forward and refine unknown causes backward.
//   3. If every goal result has its desired value, stop: success.
//   4. Mark must-change the goal results whose observed value is not the desired one.
//   5. Mark resist-change, per must-change thread: constants, and nodes that are causes of any
//      OTHER goal result (changing them disturbs a result that is fine or is handled elsewhere).
//   6. Derive the visible limits: for each control and direction, walk the control's grid from the
//      current value until a physical limit or a visible asserted limit (see ExecutionHistory).
//   7. Mark cycle-back the controls whose last planned change can no longer continue (its
//      direction is now blocked), so any change of theirs would go back.
//   8. Mark at-maximum / at-minimum the controls whose + / - range from step 6 is empty. Their
//      effect on intermediate nodes is "propagated" by the planning search itself: a change that
//      needs a blocked control has no way down to an ultimate cause.
//   9. Plan: for each must-change result in goal order, propagate the needed change towards
//      ultimate causes. At each node (9c) causes are tried by preference: must-change, unmarked,
//      resist-change, change-0-most-likely, cycle-back; a cause for which no change is possible
//      fails and the next is tried (backtracking realises the seed's "lowest: no change possible").
//      9d: the direction with the higher likelihood potential (potentials of blocked directions are
//      zero); ties go to continuing the node's last planned change, then (controls) to the longer
//      range. 9b (a thread ends where a cause already has a planned change) cannot arise here: one
//      thread is planned per trial, and the nodes it has decided lie on its own path, above.
//      9a: planning is complete once a change reaches a control; one control changes per trial,
//      so the numeric history can attribute each result to one dimension.
//      If no thread reaches a control and some blocking limits were asserted on a guess (a tie no
//      history broke, see Limit::guessed), those limits are retracted and steps 6-9 repeated;
//      each limit is retracted at most once, so this ends. Otherwise: no direction left.
//  10. Put the plan on the history and, since the trial failed, assert its limit: along the chosen
//      control, at the trial's value, on the side opposite to the change. The limit is visible from
//      points that are at least as bad for the thread's result in the other controls: from the
//      qualitative sensitivity of that result's cause to each control (helps when increased:
//      visible at values <= the trial's; hurts: >=; none: everywhere; undecided: same value only).
//  11. Choose the next value within the contextual range: the midpoint towards the nearest
//      asserted limit (bisection), or one `step` when only a physical limit bounds the range.
//  12. The caller executes the trial (run_trials does it for a world callback).
//
// Example:
//   Planner planner(network, controls, goals);
//   RunResult run = run_trials(planner, start, [&](const std::vector<double>& x) {
//     return world.execute(x); }, 40);
//   if (run.status == Status::kSuccess) use(run.trials.back().controls);
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "spar/qr/network.hpp"

namespace spar::qr {

// A control parameter's numeric side. Invariant: minimum < maximum, resolution > 0, step >=
// resolution. Values move on the grid value + k * resolution; two values closer than a resolution
// are the same trial.
struct ControlSpec {
  int node{-1};
  double minimum{0};
  double maximum{0};
  double resolution{1};
  double step{1};
  std::string unit;
};

// A goal: threshold node `node` should end up true (`desired`) or false.
struct Goal {
  int node{-1};
  bool desired{true};
};

// The observed results of one trial, one entry per goal (empty = not observed, e.g. the strike
// never happened because the match broke before).
using Outcome = std::vector<std::optional<bool>>;

enum class Side : std::uint8_t {
  kLower,  // values must be greater than the bound
  kUpper,  // values must be less than the bound
};

// How an asserted limit is visible along another control (see step 10 above).
enum class Visibility : std::uint8_t { kEverywhere, kAtMost, kAtLeast, kSameValue };

// A limit asserted by a failed trial. Invariant: visibility.size() == number of controls and the
// entry of `control` itself is kEverywhere.
struct Limit {
  int control{0};  // index into the planner's controls
  double bound{0};
  Side side{Side::kLower};
  int goal{0};   // index of the goal whose failure asserted it
  int trial{0};  // 1-based trial number
  std::vector<double> anchor;
  std::vector<Visibility> visibility;
  // The plan's direction was a guess: somewhere on its path two directions had equal likelihood
  // potentials and no earlier change broke the tie. Such a limit may be wrong; it is retracted
  // (once) when it would leave no direction (step 9).
  bool guessed{false};

  [[nodiscard]] bool visible_from(const std::vector<double>& point,
                                  const std::vector<ControlSpec>& controls) const;
  // Visible from the point and the point lies on the excluded side (or on the bound).
  [[nodiscard]] bool excludes(const std::vector<double>& point,
                              const std::vector<ControlSpec>& controls) const;
};

// What the search changed after a trial (the qualitative plan).
struct PlannedChange {
  int control{0};  // index into the controls
  Sign direction{Sign::kPlus};
  int goal{0};                     // the must-change result whose thread reached the control
  std::vector<int> path;           // nodes from that result down to the control
  std::vector<Sign> node_changes;  // forward propagation of the change over every node
  double from{0};
  double to{0};
  bool guessed{false};  // the direction rests on an unbroken tie (see Limit::guessed)
};

// Why a control cannot move in a direction: a physical limit or an asserted limit (trial number).
struct Blocking {
  int control{0};
  Sign direction{Sign::kPlus};
  std::optional<int> limit_trial;  // empty: the physical limit
  double at{0};                    // the bound that blocks
};

enum class Status : std::uint8_t { kContinue, kSuccess, kNoDirectionLeft, kBudgetExhausted };
[[nodiscard]] std::string to_string(Status status);

// Node marks of steps 4-8 for one trial (for reports and tests).
struct Marks {
  std::vector<int> must_change;  // goal indices
  std::vector<int> cycle_back;   // control indices
  std::vector<int> at_maximum;   // control indices
  std::vector<int> at_minimum;   // control indices
};

struct Trial {
  int number{0};  // 1-based
  std::vector<double> controls;
  Outcome outcome;
  Status status{Status::kContinue};
  Marks marks;
  std::optional<PlannedChange> plan;  // empty on success or when no direction is left
  std::vector<Limit> limits_asserted;
  std::vector<Blocking> blocking;     // filled when no direction is left
  std::vector<int> limits_retracted;  // trials whose guessed limits this trial retracted
  double planning_microseconds{0};
};

// The numeric execution history: trials and the limits they asserted.
class ExecutionHistory {
 public:
  explicit ExecutionHistory(std::vector<ControlSpec> controls) : controls_(std::move(controls)) {}

  // The values the control may take moving from `point` in `direction`, nearest first: grid
  // values inside the physical range that no asserted limit excludes, up to the first excluded
  // one. `blocker` is that excluding limit (empty when the physical limit ended the range).
  struct Range {
    std::vector<double> values;
    std::optional<Limit> blocker;
    double end{0};  // the first value that is not allowed (the physical bound or the limit's value)
  };
  [[nodiscard]] Range contextual_range(const std::vector<double>& point, int control,
                                       Sign direction) const;
  // The first asserted limit excluding the point, if any.
  [[nodiscard]] const Limit* excluding_limit(const std::vector<double>& point) const;
  [[nodiscard]] bool within_physical_limits(const std::vector<double>& point) const;

  void add_trial(Trial trial) { trials_.push_back(std::move(trial)); }
  void assert_limit(Limit limit) { limits_.push_back(std::move(limit)); }
  // Removes the guessed limit asserted by trial `trial`, if any.
  void retract_guessed_limit(int trial);
  [[nodiscard]] const std::vector<Trial>& trials() const { return trials_; }
  [[nodiscard]] const std::vector<Limit>& limits() const { return limits_; }
  [[nodiscard]] const std::vector<ControlSpec>& controls() const { return controls_; }

 private:
  std::vector<ControlSpec> controls_;
  std::vector<Trial> trials_;
  std::vector<Limit> limits_;
};

class Planner {
 public:
  // Goals are listed in priority order (the first must-change goal is planned for first).
  // Throws QrError when a control or goal does not name a control / threshold node.
  Planner(Network network, std::vector<ControlSpec> controls, std::vector<Goal> goals);

  // Steps 1-11 for a trial just executed at `controls` with `outcome`. Returns the recorded
  // trial: its status, marks, plan (with the next values in plan->to) and asserted limit.
  const Trial& record_and_plan(const std::vector<double>& controls, const Outcome& outcome);

  [[nodiscard]] const ExecutionHistory& history() const { return history_; }
  [[nodiscard]] const Network& network() const { return network_; }
  [[nodiscard]] const std::vector<ControlSpec>& controls() const { return history_.controls(); }
  [[nodiscard]] const std::vector<Goal>& goals() const { return goals_; }

 private:
  struct TrialContext;  // what one trial's planning reads (planner.cpp)
  struct Search;        // planning state of one thread of a trial (planner.cpp)

  // record_and_plan's steps, in the paper's numbering. 2-4: sets the controls and observations,
  // propagates, marks the must-change results; true on success.
  bool evaluate(const std::vector<double>& point, const Outcome& outcome, Trial& trial,
                TrialContext& context);
  // Per node, its change in the most recent plan that changed it (the history's direction).
  void remember_last_changes(TrialContext& context) const;
  // 6-8: the contextual ranges per control, the at-maximum / at-minimum and cycle-back marks.
  void set_ranges(const std::vector<double>& point,
                  const std::optional<PlannedChange>& previous_plan, Trial& trial,
                  TrialContext& context) const;
  // 9 and 5: a plan for the first must-change goal that has one (its index in planned_goal).
  [[nodiscard]] std::optional<Search> plan_threads(const Trial& trial, TrialContext& context,
                                                   int& planned_goal) const;
  // No direction: retracts the guessed limits that block one; false when there are none.
  bool retract_blocking_guesses(const TrialContext& context, Trial& trial);
  // What blocks each direction of each control, when no plan is left.
  void record_blocking(const TrialContext& context, Trial& trial) const;
  // 10-11: the planned change, its next value and the limit this failed trial asserts.
  void adopt_plan(const std::vector<double>& point, const Search& plan, int planned_goal,
                  const TrialContext& context, Trial& trial);
  // 9c-9e: plans `desired` for `node` by changing its causes in turn, recursively, on copies of
  // `search`; true when a control's change achieves it.
  [[nodiscard]] bool plan_node(Search& search, int node, Sign desired, int depth) const;
  // A control node: `desired` if no other control is planned and no limit blocks it.
  [[nodiscard]] bool plan_control(Search& search, int node, Sign desired) const;
  struct CauseChoice;  // a cause to change, its preference rank and potentials (planner.cpp)
  // 9c: the undecided causes of `node`, by preference (rank, then the likelier change).
  [[nodiscard]] std::vector<CauseChoice> ranked_causes(const Search& search, int node,
                                                       Sign desired) const;
  // 9d: the order to try a cause's two changes in, the likelier first.
  [[nodiscard]] std::array<Sign, 2> direction_order(const TrialContext& context,
                                                    const CauseChoice& choice) const;
  [[nodiscard]] std::vector<Visibility> limit_visibility(int goal, int control) const;

  Network network_;
  std::vector<Goal> goals_;
  ExecutionHistory history_;
  std::vector<int> control_of_node_;  // node id -> control index, or -1
};

struct RunResult {
  Status status{Status::kContinue};
  std::vector<Trial> trials;
};

// Executes trials from `start` until success, no direction left, or `budget` trials.
using World = std::function<Outcome(const std::vector<double>& controls)>;
RunResult run_trials(Planner& planner, const std::vector<double>& start, const World& world,
                     int budget);

}  // namespace spar::qr
