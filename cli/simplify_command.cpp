#include <iostream>
#include <string>

#include "cli/commands.hpp"
#include "symbolic/operations.hpp"
#include "symbolic/parse.hpp"

namespace spar::cli {

void add_simplify_command(CLI::App& app) {
  auto* command =
      app.add_subcommand("simplify", "Parse an expression and print its canonical form");
  auto expression = std::make_shared<std::string>();
  command->add_option("expression", *expression, "Infix expression, e.g. \"sin(x)^2+cos(x)^2\"")
      ->required();
  command->callback([expression] {
    symbolic::ExprPool pool;
    const symbolic::Expr e = symbolic::parse(pool, *expression);
    std::cout << symbolic::to_string(e) << '\n';
  });
}

}  // namespace spar::cli
