// `spar qr match-strike`: the qualitative reasoning planner of seeds/000 striking a simulated
// match.
//
//   spar qr match-strike [--seed N] [--paper-world] [--start depth=8,angle=20,gap=20]
//                        [--budget 60] [--json] [--svg FILE]
//
// Prints the trial table (trial, controls, outcome, planned change, limits asserted), or with
// --json one object {"trials": [...], "summary": {...}}. The SVG of the search in the
// angle x digging-depth plane (the seed's Figure 8) is written only when --svg FILE is given.
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "spar/qr/match_strike.hpp"
#include "spar/reports/qr_svg.hpp"

namespace spar::cli {
namespace {

using qr::Limit;
using qr::Outcome;
using qr::Trial;

const char* const kControlNames[] = {"depth", "angle", "gap"};
const char* const kGoalNames[] = {"break_on_start", "break_on_strike", "ignition"};
// --budget's upper limit: the search converges in tens of trials; more is a typo, not a plan.
constexpr std::uint64_t kMaxTrials = 10'000;

std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string describe_outcome(const Outcome& outcome) {
  if (outcome[qr::kBreakOnStart].value_or(false)) return "broke on move to start";
  if (outcome[qr::kBreakOnStrike].value_or(false)) return "broke on strike";
  if (outcome[qr::kIgnition].value_or(false)) return "ignited";
  return "no ignition, no break";
}

std::string describe_limit(const qr::MatchStrikeModel& model, const Limit& limit) {
  std::string text = std::string(kControlNames[limit.control]) +
                     (limit.side == qr::Side::kLower ? " > " : " < ") + number(limit.bound);
  std::string where;
  for (std::size_t k = 0; k < model.controls.size(); ++k) {
    if (static_cast<int>(k) == limit.control) continue;
    const std::string anchor = number(limit.anchor[k]);
    switch (limit.visibility[k]) {
      case qr::Visibility::kEverywhere:
        continue;
      case qr::Visibility::kAtMost:
        where += std::string(where.empty() ? "" : ", ") + kControlNames[k] + "<=" + anchor;
        break;
      case qr::Visibility::kAtLeast:
        where += std::string(where.empty() ? "" : ", ") + kControlNames[k] + ">=" + anchor;
        break;
      case qr::Visibility::kSameValue:
        where += std::string(where.empty() ? "" : ", ") + kControlNames[k] + "=" + anchor;
        break;
    }
  }
  return where.empty() ? text : text + " where " + where;
}

nlohmann::json controls_json(const std::vector<double>& values) {
  nlohmann::json out;
  for (std::size_t k = 0; k < values.size(); ++k) out[kControlNames[k]] = values[k];
  return out;
}

nlohmann::json trial_json(const qr::MatchStrikeModel& model, const Trial& trial) {
  nlohmann::json out{{"trial", trial.number},
                     {"controls", controls_json(trial.controls)},
                     {"result", describe_outcome(trial.outcome)},
                     {"status", qr::to_string(trial.status)},
                     {"planning_us", trial.planning_microseconds}};
  for (std::size_t g = 0; g < trial.outcome.size(); ++g) {
    out["outcome"][kGoalNames[g]] =
        trial.outcome[g] ? nlohmann::json(*trial.outcome[g]) : nlohmann::json(nullptr);
  }
  if (trial.plan) {
    nlohmann::json path = nlohmann::json::array();
    for (int node : trial.plan->path) path.push_back(model.network.node(node).name);
    out["plan"] = {{"control", kControlNames[trial.plan->control]},
                   {"direction", std::string(1, qr::to_char(trial.plan->direction))},
                   {"from", trial.plan->from},
                   {"to", trial.plan->to},
                   {"for", kGoalNames[trial.plan->goal]},
                   {"path", path}};
  }
  out["limits_asserted"] = nlohmann::json::array();
  for (const Limit& limit : trial.limits_asserted) {
    out["limits_asserted"].push_back(describe_limit(model, limit));
  }
  if (!trial.limits_retracted.empty()) out["limits_retracted_from_trials"] = trial.limits_retracted;
  if (!trial.blocking.empty()) {
    out["blocking"] = nlohmann::json::array();
    for (const qr::Blocking& block : trial.blocking) {
      out["blocking"].push_back(
          {{"control", kControlNames[block.control]},
           {"direction", std::string(1, qr::to_char(block.direction))},
           {"at", block.at},
           {"by", block.limit_trial ? "limit from trial " + std::to_string(*block.limit_trial)
                                    : std::string("physical limit")}});
    }
  }
  return out;
}

void print_table(const qr::MatchStrikeModel& model, const qr::RunResult& run) {
  std::cout << std::left << std::setw(6) << "trial" << std::setw(8) << "depth" << std::setw(8)
            << "angle" << std::setw(6) << "gap" << std::setw(24) << "outcome" << std::setw(26)
            << "planned change"
            << "limits asserted\n";
  for (const Trial& trial : run.trials) {
    std::string change = "-";
    if (trial.plan) {
      change = std::string(kControlNames[trial.plan->control]) + " " +
               qr::to_char(trial.plan->direction) + " -> " + number(trial.plan->to) + " (" +
               (trial.plan->goal == qr::kIgnition ? "ignite" : "no break") + ")";
    }
    std::string limits;
    for (const Limit& limit : trial.limits_asserted) {
      limits += describe_limit(model, limit) + (limit.guessed ? " (guessed)" : "");
    }
    for (int retracted : trial.limits_retracted) {
      limits += "; retracted the guessed limit of trial " + std::to_string(retracted);
    }
    std::cout << std::setw(6) << trial.number << std::setw(8) << number(trial.controls[0])
              << std::setw(8) << number(trial.controls[1]) << std::setw(6)
              << number(trial.controls[2]) << std::setw(24) << describe_outcome(trial.outcome)
              << std::setw(26) << change << limits << '\n';
  }
  std::cout << "status: " << qr::to_string(run.status) << " after " << run.trials.size()
            << " trials\n";
  for (const qr::Blocking& block : run.trials.back().blocking) {
    std::cout << "  blocked: " << kControlNames[block.control] << ' '
              << qr::to_char(block.direction) << " at " << block.at << " by "
              << (block.limit_trial ? "the limit from trial " + std::to_string(*block.limit_trial)
                                    : std::string("the physical limit"))
              << '\n';
  }
}

}  // namespace

void add_qr_command(CLI::App& app) {
  auto* qr_command = app.add_subcommand("qr", "Qualitative reasoning planner (seeds/000)");
  qr_command->require_subcommand(1);
  auto* match = qr_command->add_subcommand(
      "match-strike", "Find match-striking control values by trial in a simulated world");
  struct Options {
    std::uint64_t seed{1};
    bool paper_world{false};
    std::string start{"depth=8,angle=20,gap=20"};
    int budget{60};
    bool json{false};
    std::string svg;
  };
  auto options = std::make_shared<Options>();
  add_count_option(*match, "--seed", options->seed,
                   "Seed of the simulated world's hidden parameters", 0, UINT64_MAX);
  match->add_flag("--paper-world", options->paper_world,
                  "Use the world shaped like the seed's run instead of a random one");
  match->add_option("--start", options->start, "Start controls, e.g. depth=8,angle=20,gap=20");
  add_count_option(*match, "--budget", options->budget, "Maximum number of trials", 1, kMaxTrials);
  match->add_flag("--json", options->json, "Print the trials and a summary as one JSON object");
  match->add_option("--svg", options->svg,
                    "Write the search in the angle x depth plane to this SVG file");
  match->callback([options] {
    const std::vector<double> start = qr::parse_match_start(options->start);
    const qr::MatchStrikeModel model = qr::match_strike_model();
    qr::SimulatedWorld world = options->paper_world ? qr::SimulatedWorld::paper_like()
                                                    : qr::SimulatedWorld::random(options->seed);
    qr::Planner planner(model.network, model.controls, model.goals);
    const qr::RunResult run = qr::run_trials(planner, start, world.as_function(), options->budget);
    if (!options->svg.empty()) {
      write_file(options->svg, "the SVG",
                 [&](std::ostream& file) { file << reports::match_strike_svg(model, run); });
    }
    if (!options->json) {
      print_table(model, run);
      if (!options->svg.empty()) std::cout << "search drawn in " << options->svg << '\n';
      return;
    }
    nlohmann::json out;
    out["trials"] = nlohmann::json::array();
    for (const Trial& trial : run.trials) out["trials"].push_back(trial_json(model, trial));
    const qr::WorldParameters& hidden = world.parameters();
    out["summary"] = {{"success", run.status == qr::Status::kSuccess},
                      {"status", qr::to_string(run.status)},
                      {"trials", run.trials.size()},
                      {"final", controls_json(run.trials.back().controls)},
                      {"world",
                       {{"landmark_deg", hidden.landmark_degrees()},
                        {"breaking_moment_Nmm", hidden.breaking_moment},
                        {"ignition_heat_W", hidden.ignition_heat},
                        {"variation", hidden.variation}}}};
    std::cout << out.dump(2) << '\n';
  });
}

}  // namespace spar::cli
