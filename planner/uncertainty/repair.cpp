#include "spar/planner/uncertainty/repair.hpp"

#include <algorithm>
#include <bit>
#include <optional>

namespace spar::planner {
namespace {

// held[i]: the object held just before steps[i], or -1 (gripper empty).
std::vector<int> held_before(const std::vector<Phase2Step>& steps) {
  std::vector<int> held(steps.size() + 1, -1);
  for (std::size_t i = 0; i < steps.size(); ++i) {
    held[i + 1] = held[i];
    if (steps[i].effect == Effect::kGrasp) held[i + 1] = steps[i].object;
    if (steps[i].effect == Effect::kRelease || steps[i].effect == Effect::kInsert) held[i + 1] = -1;
  }
  return held;
}

// Where the objects are just before steps[until] (the effects of the steps before it replayed on
// the initial world, as instances.hpp's apply_step does for instance steps).
WorldState state_before(const WorldModel& world, const std::vector<Phase2Step>& steps, int until) {
  WorldState state = world.initial_state();
  for (int i = 0; i < until; ++i) {
    const Phase2Step& step = steps[i];
    if (step.effect == Effect::kRelease || step.effect == Effect::kInsert)
      state.move(step.object, step.object_pose);
    if (step.effect == Effect::kInsert) state.carrier[step.object] = step.fixed_object;
  }
  return state;
}

// The objects of `state` other than `object` and not assembled into another (resting_occluders).
VisionOccluders occluders_in(const WorldState& state, int object) {
  VisionOccluders occluders;
  for (int o = 0; o < static_cast<int>(state.poses.size()); ++o)
    if (o != object && state.carrier[o] < 0) occluders.objects.emplace_back(o, state.poses[o]);
  return occluders;
}

bool moves(const Phase2Step& step, int object) {
  return step.object == object && moves_object(step.effect);
}

// At most one squeeze: a second one re-centres the object again and cannot add anything.
bool valid_set(const std::vector<RepairCandidate>& candidates, unsigned set) {
  int squeezes = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i)
    squeezes += (set >> i & 1u) && candidates[i].effect == Effect::kReduce;
  return squeezes <= 1;
}

// The sets of `size` candidates out of n, in lexicographic order of their indices (SPAR's order).
std::vector<unsigned> sets_of_size(std::size_t n, int size) {
  std::vector<unsigned> sets;
  for (unsigned set = 1; set < (1u << n); ++set)
    if (std::popcount(set) == size) sets.push_back(set);
  // Lexicographic by the sorted index list: compare the lowest differing index.
  std::sort(sets.begin(), sets.end(), [](unsigned a, unsigned b) {
    const unsigned differ = a ^ b;
    const unsigned lowest = differ & -differ;
    return (a & lowest) != 0;
  });
  return sets;
}

// Per candidate of `kept` (in candidate order): the preconditions it turns, satisfied with the
// kept set and not without that candidate. `score_of(set)` gives a set's full score; every
// subset of the kept set was scored by the search, so it only completes partial ones.
template <class ScoreOf>
std::vector<std::vector<PreconditionRef>> turned_by_each(std::size_t candidates, unsigned kept,
                                                         const RepairScore& kept_score,
                                                         ScoreOf&& score_of) {
  std::vector<std::vector<PreconditionRef>> out;
  for (std::size_t i = 0; i < candidates; ++i) {
    if (!(kept >> i & 1u)) continue;
    const RepairScore& without = score_of(kept & ~(1u << i));
    std::vector<PreconditionRef> turned;
    for (const auto& [ref, satisfied] : kept_score.satisfied) {
      const auto before = without.satisfied.find(ref);
      if (satisfied && (before == without.satisfied.end() || !before->second))
        turned.push_back(ref);
    }
    out.push_back(std::move(turned));
  }
  return out;
}

}  // namespace

const char* repair_kind(const RepairCandidate& candidate) {
  if (candidate.effect == Effect::kReduce) return "squeeze";
  return candidate.camera >= 0 ? "camera-verify" : "range-scan";
}

int action_of(const RepairCandidate& candidate, const RepairKinds& kinds) {
  if (candidate.effect == Effect::kReduce) return kinds.squeeze;
  return candidate.camera >= 0 ? kinds.look : kinds.scan;
}

VisionOccluders resting_occluders(const WorldModel& world, const std::vector<Phase2Step>& steps,
                                  int until, int object) {
  return occluders_in(state_before(world, steps, until), object);
}

int scan_position(const std::vector<Phase2Step>& steps, int until, int object) {
  const std::vector<int> held = held_before(steps);
  for (int i = until; i >= 0; --i) {
    if (i < until && moves(steps[i], object)) return -1;
    if (held[i] == -1) return i;
  }
  return -1;
}

int grasp_position(const std::vector<Phase2Step>& steps, int until, int object) {
  for (int i = until; i >= 0; --i)
    if (steps[i].effect == Effect::kGrasp && steps[i].object == object) return i;
  return -1;
}

std::vector<RepairCandidate> repair_candidates(const WorldModel& world,
                                               const std::vector<Phase2Step>& steps, int k,
                                               const RepairKinds& kinds) {
  const Phase2Step& failing = steps[k];
  const bool insertion = failing.effect == Effect::kInsert;
  const int pickup_at = insertion ? grasp_position(steps, k, failing.object)
                                  : (failing.effect == Effect::kGrasp ? k : -1);
  std::vector<RepairCandidate> out;
  // A range-scan and a camera verification of `object` where it rests before steps[until].
  const auto sense = [&](int object, int until) {
    const int at = until >= 0 ? scan_position(steps, until, object) : -1;
    if (at < 0) return;
    if (kinds.scan >= 0) out.push_back({Effect::kSense, object, -1, at});
    if (kinds.look < 0) return;
    const WorldState state = state_before(world, steps, at);
    std::vector<CameraVerification> cameras = verifying_cameras(
        world.scenario(), object, state.poses[object], occluders_in(state, object));
    std::stable_sort(cameras.begin(), cameras.end(), [](const auto& a, const auto& b) {
      return a.check.edges.size() > b.check.edges.size();
    });
    if (cameras.size() > kCamerasPerObject) cameras.resize(kCamerasPerObject);
    for (const CameraVerification& camera : cameras)
      out.push_back({.object = object, .position = at, .camera = camera.camera});
  };
  if (insertion) sense(failing.fixed_object, k);
  sense(failing.object, pickup_at);
  // A squeeze uses another grasp than the pickup's (with the same one its preconditions would be
  // the failing pickup's own), one the robot reaches where the object lies and whose grasp and
  // release there clear everything (the IK branch that check takes is the squeeze's arm).
  if (kinds.squeeze >= 0 && pickup_at >= 0 && steps[pickup_at].position >= 0) {
    const Phase2Step& pickup = steps[pickup_at];
    const ObjectWorld& object = world.object(pickup.object);
    std::optional<WorldState> before;  // computed for the first reachable grasp
    int added = 0;
    for (int g = 0; g < static_cast<int>(object.grasps.size()) && added < kinds.squeeze_grasps &&
                    static_cast<int>(out.size()) < kMaxCandidates;
         ++g) {
      if (g == pickup.grasp || !object.reachable[g][pickup.position]) continue;
      if (!before) before = state_before(world, steps, pickup_at);
      StepCheck check =
          world.check_grasp(*before, pickup.object, g, pickup.object_pose, /*measure=*/false);
      if (!check.clear || !check.arm) continue;
      out.push_back({Effect::kReduce, pickup.object, g, pickup_at, std::move(check.arm)});
      ++added;
    }
  }
  return out;
}

SplicedPlan splice(const std::vector<Phase2Step>& steps, int k,
                   const std::vector<RepairCandidate>& candidates, unsigned set,
                   const RepairKinds& kinds, int repair_id) {
  SplicedPlan out{.steps = steps, .failing = k, .inserted = {}};
  // Later positions first, so earlier ones stay valid; at one position, in candidate order.
  std::vector<int> order;
  for (int i = 0; i < static_cast<int>(candidates.size()); ++i)
    if (set >> i & 1u) order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return candidates[a].position > candidates[b].position; });
  std::vector<int> rank(candidates.size(), -1);
  for (std::size_t r = 0, i = 0; i < candidates.size(); ++i)
    if (set >> i & 1u) rank[i] = static_cast<int>(r++);
  // Labels of the inserted steps (Phase2Step::label): past every instance step's, one block of
  // kMaxCandidates per failing instance step, so the same candidate gets the same label in every
  // set tried and no two candidates of one plan share one.
  int instance_steps = 0;
  for (const Phase2Step& s : steps) instance_steps = std::max(instance_steps, s.instance_step + 1);
  const int first_label = instance_steps + 1 + std::max(steps[k].instance_step, 0) * kMaxCandidates;
  int shift_total = 0;
  for (const int i : order) {
    const RepairCandidate& c = candidates[i];
    Phase2Step step;
    if (c.effect == Effect::kReduce) {
      step = steps[c.position];  // the pickup it precedes: same object, position, pose
      step.grasp = c.grasp;
      step.arm = c.arm;
    } else {
      step.object = c.object;
      step.camera = c.camera;
    }
    step.action = action_of(c, kinds);
    step.effect = c.effect;
    step.instance_step = -1;
    step.repair = repair_id + rank[i];
    step.label = first_label + i;
    // Candidates at the same position keep candidate order: insert after the ones already there.
    int at = c.position;
    for (const int j : order) {
      if (j == i) break;
      if (candidates[j].position == c.position) ++at;
    }
    out.steps.insert(out.steps.begin() + at, step);
    ++shift_total;
  }
  out.failing = k + shift_total;
  // Final positions of the inserted steps.
  out.inserted.assign(order.size(), -1);
  for (std::size_t p = 0; p < out.steps.size(); ++p)
    if (out.steps[p].instance_step < 0 && out.steps[p].repair >= repair_id &&
        out.steps[p].repair < repair_id + static_cast<int>(order.size()))
      out.inserted[out.steps[p].repair - repair_id] = static_cast<int>(p);
  return out;
}

RepairChoice choose_repair(const std::vector<RepairCandidate>& candidates,
                           const RepairScore& baseline,
                           const std::function<RepairScore(unsigned, ScoreDepth)>& evaluate) {
  RepairChoice choice{.set = 0, .score = baseline, .turned = {}, .sets_tried = 0};
  std::map<unsigned, RepairScore> scores = {{0u, baseline}};
  const int n = static_cast<int>(candidates.size());
  // A set is tried once; a partial score is completed when a full one is needed.
  const auto score_of = [&](unsigned set, ScoreDepth depth) -> const RepairScore& {
    auto found = scores.find(set);
    if (found == scores.end()) {
      ++choice.sets_tried;
      found = scores.emplace(set, evaluate(set, depth)).first;
    } else if (found->second.partial && depth == ScoreDepth::kFull) {
      found->second = evaluate(set, depth);
    }
    return found->second;
  };
  const auto settles = [](const RepairScore& score) {
    return !score.partial && score.admissible && score.unsatisfied == 0;
  };
  unsigned sensing = 0;
  std::vector<int> squeezes;
  for (int i = 0; i < n; ++i)
    if (candidates[i].effect == Effect::kReduce)
      squeezes.push_back(i);
    else
      sensing |= 1u << i;
  // The best score any set can have: a set scores no better than the set with every sensing
  // candidate added (monotonicity, header comment), so the best is among the maximal sets, every
  // sensing candidate with no squeeze or with one. Evaluated once, when the sets of size 1 leave
  // something unsatisfied or before the first set with a squeeze; the evaluation stops at a
  // maximal set that satisfies everything.
  std::optional<RepairScore> best;
  const auto best_possible = [&]() -> const RepairScore& {
    if (best) return *best;
    best = choice.score;
    std::vector<unsigned> maximal;
    if (sensing != 0) maximal.push_back(sensing);
    for (const int i : squeezes) maximal.push_back(sensing | 1u << i);
    for (const unsigned set : maximal) {
      const RepairScore& score = score_of(set, ScoreDepth::kFull);
      if (score.admissible && score.better_than(*best)) best = score;
      if (best->unsatisfied == 0) break;
    }
    return *best;
  };
  // Where some set settles the step, only a set that settles can be kept: a set with a squeeze
  // is then scored only as far as whether it does (ScoreDepth::kSettles).
  const auto depth_of = [&](unsigned set) {
    return (set & ~sensing) != 0 && settles(best_possible()) ? ScoreDepth::kSettles
                                                             : ScoreDepth::kFull;
  };
  // The search ends once no set can score strictly better than the one kept (every subset of a
  // kept set, smaller, is already scored): at once when it leaves nothing unsatisfied, and after
  // the sets of size 1 as soon as it is as good as the best possible.
  const auto settled = [&](bool bounded) {
    return choice.score.unsatisfied == 0 || (bounded && !best_possible().better_than(choice.score));
  };
  for (int size = 1; size <= n && !settled(size > 1); ++size) {
    for (const unsigned set : sets_of_size(candidates.size(), size)) {
      if (!valid_set(candidates, set)) continue;
      const RepairScore& score = score_of(set, depth_of(set));
      if (!score.partial && score.admissible && score.better_than(choice.score)) {
        choice.set = set;
        choice.score = score;
        if (settled(size > 1)) break;
      }
    }
  }
  choice.turned = turned_by_each(
      candidates.size(), choice.set, choice.score,
      [&](unsigned set) -> const RepairScore& { return score_of(set, ScoreDepth::kFull); });
  return choice;
}

}  // namespace spar::planner
