// The `spar` command's subcommands. Each lives in its own `<name>_command.cpp` and registers itself
// on the top-level CLI11 app; main.cpp calls every add_*_command in the order they are listed here.
//
// A subcommand reports a user's mistake by throwing std::exception (or a module's error type
// derived from it) with a message a person can act on; main.cpp prints it as one line on stderr and
// exits 1. Exit status: 0 success, 1 bad input or usage; `spar plan` and `spar demo` also say
// their verdict in it (kPlan... below) through `exit_status`, which main returns.
#pragma once

#include <CLI/CLI.hpp>

namespace spar::cli {

// `spar plan`'s exit status (normative; spar plan --help, README, docs/report-schema.md):
inline constexpr int kPlanProved = 0;      // planned, every precondition proved
inline constexpr int kPlanBadInput = 1;    // bad input or usage (any command)
inline constexpr int kPlanNoPlan = 2;      // no plan
inline constexpr int kPlanWithErrors = 3;  // planned, with errors left to verify at execution

void add_demo_command(CLI::App& app, int& exit_status);
void add_simplify_command(CLI::App& app);
void add_fk_command(CLI::App& app);
void add_ik_command(CLI::App& app);
void add_qr_command(CLI::App& app);
void add_object_command(CLI::App& app);
void add_bound_command(CLI::App& app);
void add_plan_command(CLI::App& app, int& exit_status);
void add_evidence_command(CLI::App& app);
void add_vision_command(CLI::App& app);

// Thrown by a subcommand whose output is complete but whose outcome is not a success (`spar plan`
// found no plan: exit status 2); main.cpp exits with `status` and prints nothing more.
struct ExitStatus {
  int status{0};
};

}  // namespace spar::cli
