// Repair: which range-scans and squeezes phase 2 splices in before a failing step (seed 001,
// "Satisfying Uncertainty-Reduction Goals": sensing where the uncertainty is too large), chosen as
// a SET by a search, not one greedy insertion at a time.
//
// Candidates for the failing step at k, in SPAR's order (repair_candidates):
//   for an insertion, a range-scan of the fixed object at the latest point before the step where
//   the gripper is empty and the object rests where the step finds it, then at the same point a
//   camera verification of it (a sense step with `sensor: camera`) by each fixed camera with a
//   residual that sees it well enough there (planner/vision.hpp's verifying_cameras, the other
//   objects where they rest drawn in front): the kCamerasPerObject that see the most of its edges
//   (ties: file order), most first;
//   a range-scan and a camera verification of the handled object likewise before its pickup;
//   a squeeze just before that pickup with each other grasp the robot reaches there (up to
//   `squeeze_grasps`; kMaxCandidates in all): it re-centres the object across those fingers. A
//   squeeze is a grasp and release in place, so it passes the pickup's collision check
//   (WorldModel::check_grasp, the other objects where they rest before the pickup) and acts at
//   the IK branch that check takes (its joint errors are bounded there); a grasp whose check
//   fails gives no squeeze.
// The search (choose_repair) scores a set by re-propagating the plan with the set spliced in and
// deciding every original step from the earliest candidate position through the failing step:
//   Score = (original steps that fail, their preconditions not satisfied), lexicographic;
//   a set is admissible when every squeeze in it has its own preconditions satisfied.
// It evaluates admissible sets by size (at most one squeeze each: a second one re-centres again),
// in SPAR's order within a size, and keeps the set with the best score, the smallest among equals,
// the earliest in that order among those; the empty set (no repair) wins unless a set is strictly
// better. It stops once no set left can score strictly better than the one kept: at the first
// admissible set that leaves nothing unsatisfied, and, after the sets of size 1, when the kept one
// scores as well as the best a set can (below). The best a set can is known after the sets of
// size 1 or before the first set with a squeeze, whichever comes first; where it settles the
// step, only a set that settles it can be kept, so a set with a squeeze is scored only as far
// as whether it does (ScoreDepth::kSettles: its replay stops at the first precondition not
// satisfied; the three error-free seed instances each drop one to three squeezes this way). The
// kept set's subsets are scored in full (for `turned`). Which set is kept does not depend on how
// far the others were scored.
// Invariants (what makes the choice monotone and minimal):
//   - a kept set is strictly better than no repair: it turns some verdict (violated or undecided ->
//     satisfied) and fails no more steps; a bound that merely tightens is no reason to keep it;
//   - every proper subset of the kept set scores strictly worse (else it would have been kept), so
//     every inserted step turns some verdict: turned(e) = the preconditions satisfied with the set
//     but not without e;
//   - with smaller uncertainty every set's score is no worse (bounds are inclusion-monotone, and a
//     scan never loosens a component: it keeps what it does not know better, Propagation::sense),
//     so the kept set's score, hence the step's verdicts, can only improve;
//   - for the same reason a set scores no better than the set with every sensing candidate
//     (range-scan, camera verification) added, and is admissible only if that set is: the best
//     score any set can have is the best of the maximal sets (every sensing candidate, with no
//     squeeze or with one), which the search evaluates after the sets of size 1 when those leave
//     something unsatisfied, or before the first set with a squeeze (stopping at one that
//     satisfies everything), to know when to stop.
//     Where a bound's effort limit made a real score non-monotone, the kept set would still be a
//     repair whose verdicts are the sound ones, only perhaps not the best one (the property
//     Phase2RepairProperty.ShrinkingUncertaintyNeverMakesThePlanWorse watches for it end to end).
// Cost: at most 2^(sensing candidates, 2 + 2 kCamerasPerObject) x (1 + squeezes) - 1 sets, each one
// replay and decide of steps [earliest candidate, k] (a set scored only as far as whether it
// settles: up to the first step found unsettled, the failing step decided first), and the kept
// set's subsets completed; when no set settles the step and the best is a single candidate, only
// the sets of size 1 and the maximal sets (on_back's insertion: 11 of its 19). Finding a camera
// verification renders the scene once per camera with a residual.
//
// Example:
//   const RepairKinds kinds{.scan = scan, .look = -1, .squeeze = squeeze, .squeeze_grasps = 4};
//   const std::vector<RepairCandidate> candidates = repair_candidates(world, steps, k, kinds);
//   const RepairChoice choice =
//       choose_repair(candidates, baseline, [&](unsigned set, ScoreDepth depth) {
//         return score_of(splice(steps, k, candidates, set, kinds, 0), depth);  // replay, decide
//       });
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "spar/planner/uncertainty/builders.hpp"
#include "spar/planner/vision.hpp"
#include "spar/planner/world.hpp"

namespace spar::planner {

// A precondition of an original (instance) step: its PlanInstance::steps index and its index
// among that step's preconditions.
struct PreconditionRef {
  int instance_step{-1};
  int index{-1};
  friend auto operator<=>(const PreconditionRef&, const PreconditionRef&) = default;
};

// A range-scan or camera verification (effect sense) or squeeze (effect reduce) to splice in
// before steps[position].
struct RepairCandidate {
  Effect effect{Effect::kSense};
  int object{-1};
  int grasp{-1};  // squeeze: the grasp it closes with
  int position{-1};
  std::optional<kinematics::JointSolution> arm{};  // squeeze: its collision-checked IK branch
  int camera{-1};  // camera verification: index into Scenario::cameras; -1: not one
};
// "range-scan", "camera-verify", "squeeze" (the built-in domain's names of the three)
[[nodiscard]] const char* repair_kind(const RepairCandidate& candidate);

// What the repair may splice in: the domain's actions (indices into Domain::actions, -1: none or
// not usable) and how many other grasps a squeeze may try.
struct RepairKinds {
  int scan{-1};     // a sense action with the range scanner; the scenario has one
  int look{-1};     // a sense action with `sensor: camera`; some fixed camera has a residual
  int squeeze{-1};  // a reduce action
  int squeeze_grasps{0};
};

// The domain action of `candidate` among `kinds` (scan, look or squeeze).
[[nodiscard]] int action_of(const RepairCandidate& candidate, const RepairKinds& kinds);

// The candidates for the failing steps[k] (see the header comment).
[[nodiscard]] std::vector<RepairCandidate> repair_candidates(const WorldModel& world,
                                                             const std::vector<Phase2Step>& steps,
                                                             int k, const RepairKinds& kinds);

// What may hide `object` from a camera just before steps[until], where the gripper is empty: the
// other objects where they rest (not those assembled into another: the planner no longer tracks
// them on their own, as vision_check's drawing).
[[nodiscard]] VisionOccluders resting_occluders(const WorldModel& world,
                                                const std::vector<Phase2Step>& steps, int until,
                                                int object);

// The most candidates one failing step can have (a set is a bit set of them).
inline constexpr int kMaxCandidates = 32;
// The most camera verifications of one object among them (two views fused measure what one
// cannot: an overhead camera x and y, a side camera the height).
inline constexpr std::size_t kCamerasPerObject = 2;

// `steps` with the candidates in `set` (bit i: candidates[i]) spliced in; inserted steps get
// action kinds.scan, kinds.look or kinds.squeeze, Phase2Step::repair = `repair_id` + their rank in
// the set and a label of their own that depends only on the failing step and i
// (Phase2Step::label).
struct SplicedPlan {
  std::vector<Phase2Step> steps;
  int failing{-1};            // where steps[k] is now
  std::vector<int> inserted;  // positions of the inserted steps, in candidate order
};
[[nodiscard]] SplicedPlan splice(const std::vector<Phase2Step>& steps, int k,
                                 const std::vector<RepairCandidate>& candidates, unsigned set,
                                 const RepairKinds& kinds, int repair_id);

// How far a set must be scored: in full, or only as far as whether it settles the step (every
// original precondition it decides satisfied, every inserted squeeze admissible).
enum class ScoreDepth { kFull, kSettles };

// How a plan with a repair set fares over the steps the search decides.
struct RepairScore {
  bool admissible{true};                      // every inserted squeeze's own preconditions hold
  int failed{0};                              // original steps with a precondition not satisfied
  int unsatisfied{0};                         // their preconditions not satisfied
  std::map<PreconditionRef, bool> satisfied;  // per original precondition decided
  // Scored with ScoreDepth::kSettles and found not to settle, from the first precondition not
  // satisfied on: failed = unsatisfied = 1, satisfied incomplete, admissible unknown (true).
  bool partial{false};
  [[nodiscard]] static RepairScore not_settling() {
    return {.failed = 1, .unsatisfied = 1, .satisfied = {}, .partial = true};
  }
  [[nodiscard]] bool better_than(const RepairScore& other) const {
    return std::pair(failed, unsatisfied) < std::pair(other.failed, other.unsatisfied);
  }
};

struct RepairChoice {
  unsigned set{0};  // bits of the kept candidates; 0: nothing helped
  RepairScore score;
  // Per kept candidate (in candidate order): the preconditions it turned.
  std::vector<std::vector<PreconditionRef>> turned;
  int sets_tried{0};
};

// The search of the header comment; `evaluate(set, depth)` scores a non-empty set (with
// ScoreDepth::kSettles it may return a partial score).
[[nodiscard]] RepairChoice choose_repair(
    const std::vector<RepairCandidate>& candidates, const RepairScore& baseline,
    const std::function<RepairScore(unsigned set, ScoreDepth depth)>& evaluate);

// The latest position <= until where a range-scan of `object` fits (the gripper is empty there
// and the object is not moved between there and `until`), or -1.
[[nodiscard]] int scan_position(const std::vector<Phase2Step>& steps, int until, int object);
// The last grasp of `object` at or before `until`, or -1.
[[nodiscard]] int grasp_position(const std::vector<Phase2Step>& steps, int until, int object);

}  // namespace spar::planner
