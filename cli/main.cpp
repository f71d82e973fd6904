#include <exception>
#include <iostream>

#include "cli/commands.hpp"
#include "cli/options.hpp"

int main(int argc, char** argv) {
  CLI::App app{"spar: symbolic worst-case uncertainty analysis of robot task plans"};
  app.require_subcommand(1);
  app.set_version_flag("--version", SPAR_VERSION, "Print spar's version and exit");
  app.footer(
      "Exit status: 0 success, 1 bad input or usage; spar plan and spar demo also exit 2 (no "
      "plan) and 3 (planned, with errors left to verify at execution): see spar plan --help.");
  int exit_status = 0;  // a command's verdict (spar plan), when it has one
  spar::cli::add_demo_command(app, exit_status);
  spar::cli::add_simplify_command(app);
  spar::cli::add_fk_command(app);
  spar::cli::add_ik_command(app);
  spar::cli::add_qr_command(app);
  spar::cli::add_object_command(app);
  spar::cli::add_bound_command(app);
  spar::cli::add_plan_command(app, exit_status);
  spar::cli::add_evidence_command(app);
  spar::cli::add_vision_command(app);
  try {
    app.name("spar");
    spar::cli::accept_leading_minus(app);  // after every add_*_command: covers all their options
    std::vector<std::string> arguments = spar::cli::protect_leading_minus(argc, argv);
    app.parse(arguments);
    spar::cli::flush_standard_output();
  } catch (const spar::cli::ExitStatus& exit) {
    try {
      spar::cli::flush_standard_output();
    } catch (const std::exception& error) {
      std::cerr << "spar: error: " << error.what() << '\n';
      return 1;
    }
    return exit.status;
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);  // --help, --version
    std::cerr << "spar: error: " << error.what() << " (see spar --help)\n";
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "spar: error: " << error.what() << '\n';
    return 1;
  }
  return exit_status;
}
