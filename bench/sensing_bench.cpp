// sensing (issue 26): the sensor planner's three costs.
//
//   evidence   Dempster's rule folded over S sources on a frame of n hypotheses: spar's sparse
//              bitset focal sets against a dense peer over all 2^n subsets that combines one
//              source at a time as a dense implementation does: the fast Möbius transform of
//              both to commonalities, their pointwise product, the transform back, normalised
//              (O(n 2^n) per source, Kennes 1992). Same run, same sources; the results are
//              compared (the
//              dense one rounds visibly at high conflict) and the run fails on a gross mismatch.
//              The dense peer runs up to n = 20 (8 MiB per table); spar alone up to n = 64 and S =
//              100. Sources are the shape sensing produces: 1-3 focal sets of 1-3 hypotheses each
//              (mostly holding one common hypothesis), plus the whole frame (so no combination
//              conflicts totally).
//   aspects    compute_aspects on a non-convex rectilinear "skyline" of about 20k triangles (the
//              view sphere: 1280 directions, 128 x 128 samples each), against the target
//              of 2 s; and the exact arrangement of a convex 32-gon prism.
//   selection  closed-loop sense planning on the seed's block resting in any of its stable
//              poses (the frame: one hypothesis each), its position and yaw anywhere within the
//              seed's +-0.11 in and +-5.5 deg, a wrist range scanner (spar's default: 1 mm,
//              0.01 rad, 95% found) at the viewpoint classes of selection.hpp (icosphere level 2,
//              standoff 0.5 m, all reachable). After each operation the simulated measurement
//              (noise, misses) is weighed into the belief; stop when its ambiguity is below the
//              threshold (0.3 bits) or after 6 operations. Three ways of choosing the next
//              operation from the current belief, in the same run on the same trials (truth,
//              pose error and noise seeded per trial): spar's minimax ambiguity
//              (select_operations from the current belief, its first choice; when its stopping
//              rule leaves none, the candidate of least maximum ambiguity), the peer greedy by
//              coverage (the unused viewpoint whose predicted view holds the most feature
//              prominence, summed over the hypotheses: "look where you see the most"), and the
//              peer random (an unused viewpoint, uniformly). Reported: operations to the
//              threshold (mean over the trials that reach it), how many reach it, how often the
//              truth then leads, and the time per selection (and per candidate).
//
//   sensing_bench [--quick]
// Prints one line per measurement and `ratio evidence_n<N> dense_over_sparse <x>`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/timing.hpp"
#include "spar/common/units.hpp"
#include "spar/geometry/builtin_objects.hpp"
#include "spar/geometry/mesh.hpp"
#include "spar/geometry/object.hpp"
#include "spar/geometry/stable_poses.hpp"
#include "spar/sensing/aspects.hpp"
#include "spar/sensing/evidence.hpp"
#include "spar/sensing/selection.hpp"

namespace {

using spar::bench::load_average;
using spar::bench::time_median;
using spar::sensing::combine;
using spar::sensing::FocalElement;
using spar::sensing::FocalSet;
using spar::sensing::MassFunction;

// S random sources over n hypotheses (fixed seed), mostly agreeing as sensed evidence does: each
// focal set holds a common "true" hypothesis with probability 0.7.
std::vector<MassFunction> sources(int n, int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> hypothesis(0, n - 1), sets(1, 3), size(1, 3);
  std::uniform_real_distribution<double> weight(0.05, 1.0), chance(0.0, 1.0);
  const int truth = hypothesis(random);
  std::vector<MassFunction> out;
  for (int s = 0; s < count; ++s) {
    std::vector<FocalElement> elements;
    double total = 0;
    const int k = sets(random);
    for (int e = 0; e < k; ++e) {
      FocalSet set(n);
      if (chance(random) < 0.7) set.insert(truth);
      for (int m = size(random); m > 0; --m) set.insert(hypothesis(random));
      const double w = weight(random);
      elements.push_back({set, w});
      total += w;
    }
    const double open = weight(random);  // mass on the whole frame
    elements.push_back({FocalSet::whole(n), open});
    total += open;
    for (FocalElement& element : elements) element.mass /= total;
    out.push_back(MassFunction::from_elements(n, std::move(elements)));
  }
  return out;
}

// The dense peer: tables over all 2^n subsets (bit i of the index = hypothesis i).
std::vector<double> dense_of(const MassFunction& m) {
  std::vector<double> table(std::size_t{1} << m.frame_size(), 0.0);
  for (const FocalElement& element : m.elements()) {
    std::size_t index = 0;
    for (const int x : element.set.members()) index |= std::size_t{1} << x;
    table[index] = element.mass;
  }
  return table;
}

// m -> commonality q(A) = sum_{B ⊇ A} m(B), in place (superset zeta transform).
void to_commonality(std::vector<double>& table, int n) {
  for (int bit = 0; bit < n; ++bit)
    for (std::size_t a = 0; a < table.size(); ++a)
      if (!(a & (std::size_t{1} << bit))) table[a] += table[a | (std::size_t{1} << bit)];
}

// The inverse (superset Möbius transform).
void to_mass(std::vector<double>& table, int n) {
  for (int bit = 0; bit < n; ++bit)
    for (std::size_t a = 0; a < table.size(); ++a)
      if (!(a & (std::size_t{1} << bit))) table[a] -= table[a | (std::size_t{1} << bit)];
}

// Dempster's rule, dense, one source at a time as a dense implementation combines: both to
// commonalities, their product, back to masses, normalised off the empty set.
std::vector<double> dense_combine(const std::vector<MassFunction>& all, int n) {
  std::vector<double> combined(std::size_t{1} << n, 0.0);
  combined.back() = 1.0;  // vacuous
  for (const MassFunction& m : all) {
    std::vector<double> q = dense_of(m);
    to_commonality(q, n);
    to_commonality(combined, n);
    for (std::size_t a = 0; a < q.size(); ++a) combined[a] *= q[a];
    to_mass(combined, n);
    const double agreeing = 1 - combined[0];
    combined[0] = 0;
    for (double& mass : combined) mass /= agreeing;
  }
  return combined;
}

void evidence(bool quick) {
  const int count = quick ? 20 : 100;
  for (const int n : {8, 12, 16, 20, 32, 64}) {
    const std::vector<MassFunction> all = sources(n, count, 20261123U + n);
    MassFunction sparse = MassFunction::vacuous(n);
    const int repeats = quick ? 3 : 5;
    const double sparse_seconds = time_median(repeats, [&] { sparse = combine(all, n).mass; });
    std::printf("evidence n=%d sources=%d sparse %.6f s (%zu focal sets, conflict %.4f)\n", n,
                count, sparse_seconds, sparse.elements().size(), combine(all, n).conflict);
    if (n > 20 || (quick && n > 16)) continue;
    std::vector<double> dense;
    const double dense_seconds =
        time_median(n >= 20 ? 1 : repeats, [&] { dense = dense_combine(all, n); });
    // Same answer, or the comparison means nothing.
    const std::vector<double> expected = dense_of(sparse);
    double worst = 0;
    for (std::size_t a = 0; a < dense.size(); ++a)
      worst = std::max(worst, std::abs(dense[a] - expected[a]));
    // The dense peer's alternating Möbius sums lose digits when the conflict is high (spar's
    // sparse fold has no subtraction: it matched exact rational arithmetic on these sources to
    // 1e-41); only a gross difference is a mismatch.
    if (worst > 1e-3) throw std::runtime_error("dense and sparse Dempster disagree");
    std::printf("evidence n=%d sources=%d dense %.6f s (max |difference| %.1e)\n", n, count,
                dense_seconds, worst);
    std::printf("ratio evidence_n%d dense_over_sparse %.1f\n", n, dense_seconds / sparse_seconds);
  }
}

// A rectilinear skyline on a `side` x `side` grid: column (i, j) is 1 + f(i) + g(j) cells tall,
// f and g in {0, 1, 2}: a sum of a row and a column term, so no two columns touch only along an
// edge (the mesh stays manifold).
spar::geometry::ObjectModel skyline(int side) {
  std::mt19937 random(17);
  std::uniform_int_distribution<int> level(0, 2);
  std::vector<int> f(side), g(side);
  for (int& value : f) value = level(random);
  for (int& value : g) value = level(random);
  std::vector<double> xs, ys, zs;
  for (int i = 0; i <= side; ++i) xs.push_back(0.01 * i);
  ys = xs;
  for (int k = 0; k <= 5; ++k) zs.push_back(0.01 * k);
  spar::geometry::RectilinearSolid solid(xs, ys, zs);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 1 + f[i] + g[j]; k < 5; ++k) solid.set_filled(i, j, k, false);
  return spar::geometry::ObjectModel("skyline", solid.to_mesh("<skyline>"));
}

void aspects(bool quick) {
  const spar::geometry::ObjectModel city = skyline(quick ? 24 : 52);
  spar::sensing::AspectSet result;
  // Wall time (what a user waits) and this process's CPU time (what the machine's load does not
  // inflate).
  const std::clock_t cpu_start = std::clock();
  const int repeats = quick ? 1 : 3;
  const double seconds =
      time_median(repeats, [&] { result = spar::sensing::compute_aspects(city); });
  const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / repeats;
  std::printf(
      "aspects skyline %zu triangles %zu faces: %zu aspects over %zu directions, %.3f s "
      "wall, %.3f s cpu (target < 2 s)\n",
      city.mesh().triangles.size(), city.faces().size(), result.aspects.size(), result.cells.size(),
      seconds, cpu);
  const spar::geometry::ObjectModel prism(
      "prism", spar::geometry::make_prism(spar::geometry::regular_polygon(1.0, 32), 1.0));
  const double exact_seconds =
      time_median(3, [&] { result = spar::sensing::compute_aspects(prism); });
  std::printf("aspects prism-32 (%zu faces, exact arrangement): %zu aspects, %.3f s\n",
              prism.faces().size(), result.aspects.size(), exact_seconds);
}

// ---- selection ----

namespace sensing = spar::sensing;

struct BlockProblem {
  spar::geometry::ObjectModel model = spar::geometry::make_builtin_object("block");
  sensing::ObjectFeatures features = sensing::object_features(model);
  sensing::AspectSet aspects = sensing::compute_aspects(model);
  std::vector<spar::geometry::StablePose> poses = spar::geometry::stable_poses(model);

  [[nodiscard]] sensing::HypothesisWorld world(std::size_t pose, const Eigen::Vector3d& offset,
                                               double yaw) const {
    sensing::HypothesisWorld out;
    out.label = poses[pose].label;
    out.target = out.scene.add("block", model, features,
                               Eigen::Translation3d(offset) *
                                   Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                   poses[pose].object_to_world);
    out.aspects = &aspects;
    return out;
  }
};

enum class Strategy { kMinimax, kCoverage, kRandom };
const char* name_of(Strategy strategy) {
  switch (strategy) {
    case Strategy::kMinimax:
      return "minimax";
    case Strategy::kCoverage:
      return "coverage";
    case Strategy::kRandom:
      return "random";
  }
  return "";
}

struct Outcome {
  int trials{0}, reached{0}, truth_leads{0}, operations_to_threshold{0};
  int fallbacks{0};  // minimax: selections past select_operations' stopping rule
  std::vector<double> selection_seconds;
};

// The block's stable-pose hypotheses seen by the wrist range scanner: the selection problem, its
// candidate viewpoints, what each hypothesis predicts from each, and each viewpoint's coverage.
class SelectionBench {
 public:
  SelectionBench() {
    for (std::size_t p = 0; p < block_.poses.size(); ++p)
      problem_.hypotheses.push_back(block_.world(p, Eigen::Vector3d::Zero(), 0));
    problem_.sensors = {sensing::default_range_scanner()};
    problem_.tolerances = {sensing::match_tolerances(
        problem_.sensors[0], kOffsetLimit, kOffsetLimit, kOffsetLimit, kYawLimit, 0.074, 0.5)};
    problem_.prior = sensing::MassFunction::vacuous(hypotheses());
    options_.max_operations = 1;
    viewpoints_ = sensing::candidate_viewpoints(problem_, options_);
    for (const sensing::Viewpoint& viewpoint : viewpoints_) {
      expected_.push_back(sensing::expectations(problem_, 0, viewpoint.sensor_pose));
      double prominence = 0;
      for (const sensing::Expectation& e : expected_.back())
        for (const sensing::SensedFace& face : e.faces) prominence += face.prominence;
      coverage_.push_back(prominence);
    }
  }

  [[nodiscard]] int hypotheses() const { return static_cast<int>(problem_.hypotheses.size()); }
  [[nodiscard]] std::size_t viewpoints() const { return viewpoints_.size(); }
  [[nodiscard]] double threshold() const { return options_.ambiguity_threshold; }

  // One closed-loop trial: the truth (trial mod the hypotheses) at a random pose error, operations
  // chosen by `strategy` until the ambiguity is below the threshold or `max_operations` ran. The
  // same truth, pose error, noise and random choices for every strategy.
  void trial(Strategy strategy, int trial, int max_operations, Outcome& outcome) {
    std::mt19937_64 random(20261203U + static_cast<unsigned>(trial));
    std::uniform_real_distribution<double> offset(-kOffsetLimit, kOffsetLimit),
        yaw(-kYawLimit, kYawLimit);
    const int truth = trial % hypotheses();
    const sensing::HypothesisWorld actual = block_.world(
        static_cast<std::size_t>(truth), {offset(random), offset(random), 0}, yaw(random));
    std::mt19937_64 chooser(7U + static_cast<unsigned>(trial));
    sensing::MassFunction belief = problem_.prior;
    std::vector<char> used(viewpoints_.size(), 0);
    int operations = 0;
    const sensing::SensorModel& scanner = problem_.sensors[0];
    while (belief.ambiguity() >= threshold() && operations < max_operations) {
      const auto start = std::chrono::steady_clock::now();
      const int chosen = choose(strategy, belief, used, chooser, outcome);
      outcome.selection_seconds.push_back(spar::bench::seconds_since(start));
      if (chosen < 0) break;  // nothing left that helps
      const auto c = static_cast<std::size_t>(chosen);
      used[c] = 1;
      const sensing::Observation measured =
          sensing::measure(actual.scene, scanner, viewpoints_[c].sensor_pose, random);
      belief =
          sensing::weigh_evidence(measured, expected_[c], problem_.tolerances[0], scanner, belief)
              .combined;
      ++operations;
    }
    problem_.prior = sensing::MassFunction::vacuous(hypotheses());
    ++outcome.trials;
    const std::vector<double> betp = belief.pignistic();
    const bool leads = std::max_element(betp.begin(), betp.end()) - betp.begin() == truth;
    if (belief.ambiguity() < threshold()) {
      ++outcome.reached;
      outcome.operations_to_threshold += operations;
      if (leads) ++outcome.truth_leads;
    }
  }

 private:
  static constexpr double kOffsetLimit = 0.11 * spar::units::kInch,
                          kYawLimit = 5.5 * spar::units::kDegree;

  // The viewpoint `strategy` takes next (-1: none left that helps).
  int choose(Strategy strategy, const sensing::MassFunction& belief, const std::vector<char>& used,
             std::mt19937_64& chooser, Outcome& outcome) {
    if (strategy == Strategy::kMinimax) {
      problem_.prior = belief;
      const sensing::Selection selection = sensing::select_operations(problem_, options_);
      if (!selection.sequence.empty()) {
        return index_of(
            selection.candidates[static_cast<std::size_t>(selection.sequence[0].candidate)]
                .viewpoint);
      }
      // No operation lowers the worst case below the current ambiguity (the unlikely
      // hypotheses' worst cases dominate once the belief leans): select_operations stops an
      // open-loop plan there; closed loop still takes the least maximum ambiguity.
      ++outcome.fallbacks;
      const auto least = std::min_element(
          selection.candidates.begin(), selection.candidates.end(),
          [](const sensing::CandidateOperation& a, const sensing::CandidateOperation& b) {
            return a.max_ambiguity < b.max_ambiguity;
          });
      return index_of(least->viewpoint);
    }
    std::vector<int> open;
    for (std::size_t c = 0; c < viewpoints_.size(); ++c)
      if (!used[c]) open.push_back(static_cast<int>(c));
    if (open.empty()) return -1;
    if (strategy == Strategy::kRandom)
      return open[std::uniform_int_distribution<std::size_t>(0, open.size() - 1)(chooser)];
    return *std::max_element(open.begin(), open.end(), [&](int a, int b) {
      return coverage_[static_cast<std::size_t>(a)] < coverage_[static_cast<std::size_t>(b)];
    });
  }

  int index_of(const sensing::Viewpoint& chosen) const {
    for (std::size_t c = 0; c < viewpoints_.size(); ++c)
      if (viewpoints_[c].label == chosen.label) return static_cast<int>(c);
    throw std::runtime_error("selection chose an unknown viewpoint " + chosen.label);
  }

  const BlockProblem block_;
  sensing::SelectionProblem problem_;
  sensing::SelectionOptions options_;
  std::vector<sensing::Viewpoint> viewpoints_;
  std::vector<std::vector<sensing::Expectation>> expected_;
  std::vector<double> coverage_;
};

void selection(bool quick) {
  SelectionBench bench;
  const int n = bench.hypotheses();
  const int per_hypothesis = quick ? 1 : 4;
  const int max_operations = 6;
  std::printf(
      "selection block: %d hypotheses (stable poses), %zu wrist viewpoint classes, %d "
      "trials per strategy, threshold %.1f bits, at most %d operations\n",
      n, bench.viewpoints(), n * per_hypothesis, bench.threshold(), max_operations);
  for (const Strategy strategy : {Strategy::kMinimax, Strategy::kCoverage, Strategy::kRandom}) {
    Outcome outcome;
    for (int trial = 0; trial < n * per_hypothesis; ++trial)
      bench.trial(strategy, trial, max_operations, outcome);
    const double per_selection = spar::bench::median(outcome.selection_seconds);
    std::printf(
        "selection %-8s reached the threshold in %d/%d trials, %.2f operations on average, "
        "truth leads in %d/%d of those; %.6f s per selection (median, %.6f s per candidate; "
        "%d past the stopping rule)\n",
        name_of(strategy), outcome.reached, outcome.trials,
        outcome.reached ? static_cast<double>(outcome.operations_to_threshold) / outcome.reached
                        : NAN,
        outcome.truth_leads, outcome.reached, per_selection,
        per_selection / static_cast<double>(bench.viewpoints()), outcome.fallbacks);
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each line as it is done
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::printf("sensing_bench%s, load average %s\n", quick ? " --quick" : "",
              load_average().c_str());
  evidence(quick);
  aspects(quick);
  selection(quick);
  return 0;
}
