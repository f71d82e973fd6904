#include <exception>
#include <iostream>

#include "cli/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"spar: symbolic worst-case uncertainty analysis of robot task plans"};
  app.require_subcommand(1);
  spar::cli::add_demo_command(app);
  spar::cli::add_simplify_command(app);
  spar::cli::add_fk_command(app);
  spar::cli::add_ik_command(app);
  spar::cli::add_qr_command(app);
  spar::cli::add_object_command(app);
  spar::cli::add_bound_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);  // --help
    std::cerr << "spar: error: " << error.what() << " (see spar --help)\n";
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "spar: error: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
