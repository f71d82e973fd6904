// `spar demo`: SPAR's pickup example (the peg of the peg-and-block task). Builds the uncertain
// poses of eq. 1 and 2, the four pickup inequalities, bounds each over Table 2's box and prints a
// verdict; then repeats with the object's displacement uncertainty widened (--widen), and searches
// for the smallest widening that is no longer proved (--step). The example is in metres inside;
// options and output are in inches, as in the paper and examples/pickup.md.
#include <algorithm>
#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "common/units.hpp"
#include "kinematics/pickup_check.hpp"
#include "symbolic/operations.hpp"
#include "symbolic/parse.hpp"

namespace spar::cli {
namespace {

using kinematics::PoseUncertainty;

void run_case(const char* title, const PoseUncertainty& object_bounds, bool show_expression) {
  symbolic::ExprPool pool;
  const kinematics::UncertainManipulator gripper(pool, kinematics::kTable2Gripper);
  const kinematics::UncertainObject peg(pool, object_bounds);
  const kinematics::PickupPreconditions preconditions =
      kinematics::pickup_preconditions(kinematics::peg_pickup_example(), gripper, peg);
  std::printf("\n%s: object dx, dy, dz +-%.3g in, dtheta +-%.3g deg\n", title,
              object_bounds.dx / units::kInch, object_bounds.dtheta / units::kDegree);
  std::printf("  %-24s %5s %10s %10s  %s\n", "condition", "nodes", "lo", "hi", "verdict");
  int satisfied = 0;
  for (const kinematics::PickupCheck& check : kinematics::check_pickup(preconditions)) {
    std::printf("  %-24s %5zu %10.4f %10.4f  %s\n", check.condition.name.c_str(),
                symbolic::dag_size(check.condition.expression), check.bound.lo / units::kInch,
                check.bound.hi / units::kInch, kinematics::to_string(check.verdict));
    satisfied += check.verdict == kinematics::Verdict::kSatisfied ? 1 : 0;
  }
  std::printf("  => %s (%d/4 proved)\n",
              satisfied == 4 ? "pickup preconditions hold for every value in the box"
                             : "pickup preconditions NOT guaranteed: add sensing or recovery",
              satisfied);
  if (show_expression) {
    std::printf("\n  [0,1,0,0] P1^-1 C1 = %s\n",
                symbolic::to_string(preconditions.conditions[0].expression).c_str());
  }
}

// Grows the object's displacement half-width from Table 2's in steps of `step` until some
// condition is no longer proved; one PickupChecker (one compiled tape) serves every step.
// `step_in` is in inches.
void widen_until_failure(double step_in) {
  symbolic::ExprPool pool;
  const kinematics::UncertainManipulator gripper(pool, kinematics::kTable2Gripper);
  const kinematics::UncertainObject peg(pool, kinematics::kTable2Object);
  const kinematics::PickupPreconditions preconditions =
      kinematics::pickup_preconditions(kinematics::peg_pickup_example(), gripper, peg);
  kinematics::PickupChecker checker(preconditions);
  std::vector<kinematics::UncertaintyVariable> variables = preconditions.variables;
  const double start = kinematics::kTable2Object.dx / units::kInch;  // inches from here on
  std::printf("\nWidening until failure: object dx, dy, dz from +-%.3g in in steps of %.3g in\n",
              start, step_in);
  for (int k = 0; start + k * step_in <= 10.0; ++k) {
    const double half_width = start + k * step_in;
    for (std::size_t i = 4; i < 7; ++i) {  // dx_o, dy_o, dz_o
      variables[i].lower = -half_width * units::kInch;
      variables[i].upper = half_width * units::kInch;
    }
    const std::array<kinematics::PickupCheck, 4> checks = checker.check(variables);
    const bool all_proved = std::all_of(checks.begin(), checks.end(), [](const auto& check) {
      return check.verdict == kinematics::Verdict::kSatisfied;
    });
    if (all_proved) continue;
    std::printf(
        "  all four proved up to +-%.3g in; at +-%.3g in (%d checks of one compiled tape):\n",
        half_width - step_in, half_width, k + 1);
    for (const kinematics::PickupCheck& check : checks) {
      std::printf("  %-24s %10.4f %10.4f  %s\n", check.condition.name.c_str(),
                  check.bound.lo / units::kInch, check.bound.hi / units::kInch,
                  kinematics::to_string(check.verdict));
    }
    return;
  }
  std::printf("  all four proved up to +-10 in\n");
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "demo", "SPAR's pickup example: uncertain poses, the four pickup inequalities, bounds");
  auto widened = std::make_shared<double>(0.4);
  auto show = std::make_shared<bool>(false);
  auto step = std::make_shared<double>(0.01);
  add_number_option(*command, "--widen", *widened,
                    "object dx, dy, dz half-width (in) of the second, widened run, up to 1000",
                    {0, 1000, true});
  // The search runs up to 10 in: a step of at least 1e-4 in bounds it to 100 000 checks.
  add_number_option(*command, "--step", *step,
                    "step (in) of the widening-until-failure search, 1e-4 to 10", {1e-4, 10});
  command->add_flag("--show-expression", *show, "print the first inequality's expression");
  command->callback([widened, show, step] {
    std::printf(
        "SPAR pickup preconditions (the peg of the peg-and-block task): a 3 in wide peg at\n"
        "(20, 10, 0.75) in, "
        "turned 30 deg about z;\ngripper from above, 1 in along the peg; fingers open 4 in.\n"
        "Gripper uncertainty (Table 2): dx, dy, dz +-0.001 in, dtheta +-0.001 rad.\n");
    run_case("Table 2", kinematics::kTable2Object, *show);
    PoseUncertainty wide = kinematics::kTable2Object;
    wide.dx = wide.dy = wide.dz = *widened * units::kInch;
    run_case("Widened", wide, false);
    widen_until_failure(*step);
  });
}

}  // namespace spar::cli
