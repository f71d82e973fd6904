// qr: the qualitative reasoning planner (seeds/000) against a random baseline on simulated matches.
//
// Over N simulated worlds (seeds 0..N-1, hidden landmark, breaking moment, ignition heat and
// match-to-match variation drawn per seed), from the seed's start (depth 8 mm, angle 20 deg,
// gap 20 mm) and from random starts, it counts the trials to success of
//   qr            the planner (qualitative network + numeric execution history with limits),
//   random        the baseline: each trial changes ONE control, chosen at random, to a value drawn
//                 uniformly on that control's grid within the same physical limits,
//   random-step   a second baseline: one random control, random direction, the planner's step size.
// Both baselines run on the same worlds in the same process, with the same trial budget. Runs that
// exhaust the budget count as "budget + 1" trials in the medians (they never succeeded).
//
//   qr_bench [--quick] [--worlds N]
// Prints `ratio qr_trials random_baseline <baseline median / qr median>` and a table.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "spar/qr/match_strike.hpp"

namespace {

using spar::qr::ControlSpec;
using spar::qr::Outcome;

constexpr int kBudget = 200;

struct Summary {
  int runs{0};
  int successes{0};
  std::vector<int> trials;  // per run; kBudget + 1 when unsuccessful
  double planning_microseconds{0};
  int planned_trials{0};
  double worst_planning_microseconds{0};

  [[nodiscard]] double median() const {
    std::vector<int> sorted = trials;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t n = sorted.size();
    return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  }
  [[nodiscard]] int percentile(double p) const {
    std::vector<int> sorted = trials;
    std::sort(sorted.begin(), sorted.end());
    return sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(p * sorted.size()))];
  }
};

bool succeeded(const Outcome& outcome) { return outcome == Outcome{false, false, true}; }

std::vector<double> random_start(std::uint64_t seed, const std::vector<ControlSpec>& controls) {
  std::mt19937_64 draw(seed * 7 + 1);
  std::vector<double> start;
  for (const ControlSpec& spec : controls) {
    const int steps = static_cast<int>(std::round((spec.maximum - spec.minimum) / spec.resolution));
    start.push_back(spec.minimum +
                    spec.resolution * std::uniform_int_distribution<int>(0, steps)(draw));
  }
  return start;
}

void run_planner(std::uint64_t seed, const std::vector<double>& start, Summary& summary) {
  const spar::qr::MatchStrikeModel model = spar::qr::match_strike_model();
  spar::qr::Planner planner(model.network, model.controls, model.goals);
  spar::qr::SimulatedWorld world = spar::qr::SimulatedWorld::random(seed);
  const spar::qr::RunResult run =
      spar::qr::run_trials(planner, start, world.as_function(), kBudget);
  ++summary.runs;
  const bool success = run.status == spar::qr::Status::kSuccess;
  summary.successes += success;
  summary.trials.push_back(success ? static_cast<int>(run.trials.size()) : kBudget + 1);
  for (const spar::qr::Trial& trial : run.trials) {
    summary.planning_microseconds += trial.planning_microseconds;
    summary.worst_planning_microseconds =
        std::max(summary.worst_planning_microseconds, trial.planning_microseconds);
    ++summary.planned_trials;
  }
}

// One random control per trial; `stepwise` moves it one step up or down, otherwise it draws a
// new value uniformly on the grid. Both stay within the physical limits.
void run_random(std::uint64_t seed, const std::vector<double>& start, bool stepwise,
                Summary& summary) {
  const std::vector<ControlSpec> controls = spar::qr::match_strike_model().controls;
  spar::qr::SimulatedWorld world = spar::qr::SimulatedWorld::random(seed);
  std::mt19937_64 draw(seed + 0x5bd1e995ULL);
  std::vector<double> point = start;
  ++summary.runs;
  for (int trial = 1; trial <= kBudget; ++trial) {
    if (succeeded(world.execute(point))) {
      ++summary.successes;
      summary.trials.push_back(trial);
      return;
    }
    const auto started = std::chrono::steady_clock::now();
    const int c =
        std::uniform_int_distribution<int>(0, static_cast<int>(controls.size()) - 1)(draw);
    const ControlSpec& spec = controls[c];
    if (stepwise) {
      const double step = std::bernoulli_distribution(0.5)(draw) ? spec.step : -spec.step;
      point[c] = std::clamp(point[c] + step, spec.minimum, spec.maximum);
    } else {
      const int steps =
          static_cast<int>(std::round((spec.maximum - spec.minimum) / spec.resolution));
      double value = point[c];
      while (value == point[c]) {
        value = spec.minimum + spec.resolution * std::uniform_int_distribution<int>(0, steps)(draw);
      }
      point[c] = value;
    }
    const double microseconds =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - started)
            .count();
    summary.planning_microseconds += microseconds;
    summary.worst_planning_microseconds =
        std::max(summary.worst_planning_microseconds, microseconds);
    ++summary.planned_trials;
  }
  summary.trials.push_back(kBudget + 1);
}

void print_row(const char* start, const char* method, const Summary& s) {
  std::printf("| %-12s | %-12s | %5.1f %% (%d/%d) | %6.1f | %4d | %4d | %8.2f | %8.2f |\n", start,
              method, 100.0 * s.successes / s.runs, s.successes, s.runs, s.median(),
              s.percentile(0.9), s.percentile(1.0), s.planning_microseconds / s.planned_trials,
              s.worst_planning_microseconds);
}

}  // namespace

int main(int argc, char** argv) {
  int worlds = 200;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      worlds = 50;
    } else if (std::strcmp(argv[i], "--worlds") == 0 && i + 1 < argc) {
      worlds = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: qr_bench [--quick] [--worlds N]\n");
      return 2;
    }
  }
  const std::vector<ControlSpec> controls = spar::qr::match_strike_model().controls;
  Summary seed_qr, seed_random, seed_step, any_qr, any_random, any_step;
  for (int w = 0; w < worlds; ++w) {
    const auto seed = static_cast<std::uint64_t>(w);
    run_planner(seed, spar::qr::kSeedStart, seed_qr);
    run_random(seed, spar::qr::kSeedStart, false, seed_random);
    run_random(seed, spar::qr::kSeedStart, true, seed_step);
    const std::vector<double> start = random_start(seed, controls);
    run_planner(seed, start, any_qr);
    run_random(seed, start, false, any_random);
    run_random(seed, start, true, any_step);
  }
  std::printf("qr_bench: %d simulated worlds, trial budget %d (unsuccessful runs count %d)\n\n",
              worlds, kBudget, kBudget + 1);
  std::printf(
      "| start        | method       | success            | median |  p90 |  max | us/trial | "
      "worst us |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  print_row("seed's", "qr", seed_qr);
  print_row("seed's", "random", seed_random);
  print_row("seed's", "random-step", seed_step);
  print_row("random", "qr", any_qr);
  print_row("random", "random", any_random);
  print_row("random", "random-step", any_step);
  std::printf("\nratio qr_trials random_baseline %.2f\n", seed_random.median() / seed_qr.median());
  std::printf("ratio qr_trials_random_start random_baseline %.2f\n",
              any_random.median() / any_qr.median());
  std::printf("ratio qr_trials random_step_baseline %.2f\n", seed_step.median() / seed_qr.median());
  const bool met = seed_qr.successes >= 0.95 * seed_qr.runs && seed_qr.median() <= 8 &&
                   seed_random.median() >= 2 * seed_qr.median();
  std::printf("targets (>= 95%% success, median <= 8, >= 2x fewer than random): %s\n",
              met ? "met" : "MISSED");
  return 0;
}
