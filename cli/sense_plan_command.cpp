// `spar sense-plan SCENARIO [--json]`: for each object whose identity or stable pose the scenario
// leaves uncertain, the candidate sensing operations (sensor x reachable viewpoint class) with
// their predicted maximum ambiguity, and the operations chosen, least maximum ambiguity first,
// until it is below `sensing.ambiguity_threshold` (planner/sense_planning.hpp). Prints the
// Markdown of reports/sensing.hpp, or with --json the SensePlanRecord of reports/model.hpp.
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "cli/commands.hpp"
#include "spar/planner/scenario.hpp"
#include "spar/planner/sense_planning.hpp"
#include "spar/planner/world.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/sensing.hpp"

namespace spar::cli {
namespace {

struct SensePlanOptions {
  std::string scenario;
  bool json{false};
};

void run(const SensePlanOptions& options) {
  const planner::Scenario scenario = planner::load_scenario(options.scenario);
  const planner::WorldModel world(scenario);
  const reports::SensePlanRecord record =
      reports::build_sense_plan(scenario, planner::plan_sensing(scenario, world));
  if (options.json) {
    std::cout << reports::to_json(record).dump(2) << '\n';
    return;
  }
  if (record.objects.empty()) {
    std::cout << "sense-plan " << record.scenario
              << ": every object's identity and stable pose are certain; nothing to sense\n";
    return;
  }
  std::cout << "# Sense plan: " << record.scenario << '\n'
            << reports::sensing_markdown(record.objects);
}

}  // namespace

void add_sense_plan_command(CLI::App& app) {
  auto options = std::make_shared<SensePlanOptions>();
  CLI::App* command = app.add_subcommand(
      "sense-plan",
      "Choose sensing operations that disambiguate uncertain identities and stable poses");
  command->add_option("scenario", options->scenario, "scenario file (docs/scenario.md)")
      ->required();
  command->add_flag("--json", options->json, "print JSON");
  command->callback([options] { run(*options); });
}

}  // namespace spar::cli
