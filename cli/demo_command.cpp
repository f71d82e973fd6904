#include <iostream>
#include <string>

#include "cli/commands.hpp"
#include "symbolic/operations.hpp"
#include "symbolic/parse.hpp"

namespace spar::cli {

void add_demo_command(CLI::App& app) {
  auto* command = app.add_subcommand("demo", "Run the built-in example");
  command->callback([] {
    symbolic::ExprPool pool;
    const symbolic::Expr e = symbolic::parse(pool, "x*cos(t) - y*sin(t)");
    std::cout << symbolic::to_string(e) << "  (" << symbolic::dag_size(e) << " nodes)\n";
  });
}

}  // namespace spar::cli
