#include <iostream>
#include <string>

#include "cli/commands.hpp"
#include "spar/symbolic/parse.hpp"
#include "spar/symbolic/smp.hpp"

namespace spar::cli {

void add_simplify_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "simplify", "Simplify an expression (SMP: fewer repeated variables) and print it");
  auto expression = std::make_shared<std::string>();
  command->add_option("expression", *expression, "Infix expression, e.g. \"sin(x)^2+cos(x)^2\"")
      ->required();
  command->callback([expression] {
    symbolic::ExprPool pool;
    const symbolic::Expr e = symbolic::parse(pool, *expression);
    std::cout << symbolic::to_string(symbolic::simplify(e)) << '\n';
  });
}

}  // namespace spar::cli
