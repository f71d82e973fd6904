// `spar plan SCENARIO`: plans a scenario file with SPAR's two phases and prints the plan family and
// the chosen plan instance (or, with --json, one JSON object: reports/plan_json.hpp).
//
//   spar plan examples/peg_block_face_down.yaml [--json] [--domain FILE] [--instances N]
//             [--max-nodes N] [--max-steps N]
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli/commands.hpp"
#include "planner/plan.hpp"
#include "reports/plan_json.hpp"

namespace spar::cli {
namespace {

struct PlanArguments {
  std::string scenario;
  std::string domain;
  bool json{false};
  std::size_t instances{16};
  std::size_t max_nodes{200'000};
  int max_steps{64};
};

std::string fixed(double value, int digits = 3) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

void print_text(const planner::PlanResult& result, std::ostream& out) {
  const planner::Scenario& scenario = result.world.scenario();
  const planner::PlanFamily& family = result.family;
  const planner::Units& units = scenario.units;
  const std::string length(units.length_name());
  const auto vector_text = [&](const Eigen::Vector3d& v) {
    return "(" + fixed(units.to_file_length(v.x())) + ", " + fixed(units.to_file_length(v.y())) +
           ", " + fixed(units.to_file_length(v.z())) + ") " + length;
  };
  out << "plan " << scenario.name << ": " << to_string(family.status);
  if (result.planned()) out << ", " << family.steps.size() - 2 << " actions";
  out << " (" << family.stats.expanded << " partial plans expanded, "
      << fixed(family.stats.seconds * 1e3, 2) << " ms)\n";
  if (!result.planned()) {
    out << "  " << family.reason << '\n';
    return;
  }
  out << "\nplan family\n  steps (in the order they were added):\n";
  for (std::size_t s = 2; s < family.steps.size(); ++s)
    out << "    " << std::setw(2) << family.steps[s].id << "  "
        << family.describe(family.steps[s], result.world, result.domain) << '\n';
  out << "  ordering (prior_to):";
  for (const auto& [before, after] : family.ordering.transitive_reduction())
    if (family.steps[before].action >= 0 && family.steps[after].action >= 0)
      out << "  " << before << " < " << after;
  out << "\n  variables:\n";
  for (int v = 0; v < family.network.variable_count(); ++v) {
    if (family.network.representative(v) != v) continue;
    const planner::PlanVariable& meta = family.variables[v];
    const planner::ObjectWorld& object = result.world.object(meta.object);
    out << "    " << std::left << std::setw(16) << meta.name << std::right;
    for (const int label : family.network.labels(v))
      out << ' '
          << (meta.type == planner::ParameterType::kGrasp ? object.grasps[label].label
                                                           : object.positions[label].name);
    out << '\n';
  }
  out << "  constraint network: " << family.network.arcs().size() << " arcs\n";
  out << "\ninstances: " << result.instances.instances.size()
      << (result.instances.limit_reached ? " (limit reached; more exist)" : "") << '\n';
  const planner::PlanInstance& chosen = result.chosen();
  const planner::InstanceAnalysis* analysis = result.chosen_analysis();
  out << "\nchosen instance " << chosen.index + 1;
  if (analysis != nullptr) {
    out << " (" << analysis->errors << " error" << (analysis->errors == 1 ? "" : "s")
        << "; examined:";
    for (const planner::InstanceAnalysis& examined : result.examined)
      out << " #" << examined.instance + 1 << "=" << examined.errors;
    out << ")";
  }
  out << ", in execution order:\n";
  const auto print_step = [&](int number, const planner::InstanceStep& step, bool inserted) {
    const planner::ObjectSpec& object = scenario.objects[step.object];
    out << "  " << number << ". " << step.action_name << ' ' << object.name;
    if (step.is_assembly()) out << " into " << scenario.objects[step.fixed_object].name;
    out << (inserted ? "   [inserted by phase 2]" : "") << '\n';
    if (step.grasp >= 0) {
      const geometry::Grasp& grasp = result.world.object(step.object).grasps[step.grasp];
      out << "       grasp " << grasp.label << " (faces " << grasp.face_plus_y << "/"
          << grasp.face_minus_y << ", width " << fixed(units.to_file_length(grasp.width))
          << ' ' << length << ")\n";
    }
    if (step.position >= 0 && !step.is_assembly())
      out << "       object at " << vector_text(step.object_pose.translation())
          << (step.stable_pose >= 0 ? ", stable pose " + object.stable_poses[step.stable_pose].label
                                    : std::string())
          << '\n';
    if (step.is_assembly())
      out << "       " << scenario.objects[step.fixed_object].name << " at "
          << vector_text(step.fixed_pose.translation()) << ", " << object.name << " goes to "
          << vector_text(step.held_pose.translation()) << '\n';
    if (step.grasp >= 0) {
      out << "       gripper at " << vector_text(step.gripper_pose.translation()) << ", tilt "
          << fixed(units.to_file_angle(step.reach.tilt), 1) << ' ' << units.angle_name();
      if (step.reach.solution) {
        out << ", joints (";
        for (int j = 0; j < 6; ++j)
          out << (j ? ", " : "") << fixed(units.to_file_angle(step.reach.solution->q[j]), 1);
        out << ") " << units.angle_name() << " " << step.reach.solution->configuration.label();
      }
      out << '\n';
    }
  };
  if (analysis == nullptr) {
    int number = 0;
    for (const planner::InstanceStep& step : chosen.steps) print_step(++number, step, false);
    return;
  }
  int number = 0;
  for (const planner::AnalysedStep& analysed : analysis->steps) {
    planner::InstanceStep step;
    if (analysed.inserted) {
      step.action_name = analysed.action;
      step.object = analysed.step.object;
      step.grasp = -1;
      step.object_pose = analysed.step.object_pose;
    } else {
      step = chosen.steps[analysed.step.instance_step];
    }
    print_step(++number, step, analysed.inserted);
    for (const planner::PreconditionResult& p : analysed.preconditions) {
      out << "       " << std::left << std::setw(10) << bounds::to_string(p.verdict) << std::right
          << p.kind << "  " << p.inequality.name << "   bound [" << std::setprecision(6)
          << p.bound.lo << ", " << p.bound.hi << "] m";
      if (p.holds_up_to_scale) out << "   holds up to x" << fixed(*p.holds_up_to_scale, 2);
      out << '\n';
    }
    for (const planner::VerificationPlan& plan : analysed.verification) {
      out << "       verify: " << plan.sense << " (expect " << plan.expect << ")\n";
      for (const auto& outcome : plan.outcomes)
        out << "         if " << outcome.when << " -> " << outcome.error << ": recover by "
            << outcome.recovery << '\n';
    }
  }
  for (const planner::RepairAttempt& attempt : analysis->repairs)
    out << "  repair tried: " << attempt.action << ' ' << scenario.objects[attempt.object].name
        << (attempt.helped ? " (made the step's preconditions hold)" : " (did not help)") << '\n';
}

void run_plan(const PlanArguments& arguments) {
  planner::Domain domain = arguments.domain.empty() ? planner::builtin_domain()
                                                    : planner::load_domain(arguments.domain);
  planner::PlanOptions options;
  options.max_instances = arguments.instances;
  options.posting.max_nodes = arguments.max_nodes;
  options.posting.max_steps = arguments.max_steps;
  const planner::PlanResult result =
      planner::plan(planner::load_scenario(arguments.scenario), domain, options);
  if (arguments.json)
    std::cout << reports::plan_json(result).dump(2) << '\n';
  else
    print_text(result, std::cout);
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write the plan to standard output");
}

}  // namespace

void add_plan_command(CLI::App& app) {
  auto arguments = std::make_shared<PlanArguments>();
  CLI::App* command = app.add_subcommand(
      "plan", "Plan a scenario file (SPAR): plan family, plan instances, the chosen plan");
  command->add_option("scenario", arguments->scenario, "scenario file (YAML, docs/scenario.md)")
      ->required();
  command->add_flag("--json", arguments->json, "print one JSON object");
  command->add_option("--domain", arguments->domain,
                      "action templates (YAML; default: the built-in planner/domain.yaml)");
  command->add_option("--instances", arguments->instances, "plan instances to enumerate (default 16)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100'000}));
  command->add_option("--max-nodes", arguments->max_nodes,
                      "partial plans the search may expand (default 200000)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100'000'000}));
  command->add_option("--max-steps", arguments->max_steps, "actions in one plan (default 64)")
      ->check(CLI::Range(1, 10'000));
  command->callback([arguments] { run_plan(*arguments); });
}

}  // namespace spar::cli
