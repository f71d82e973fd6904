// spar bound: sound SUP/INF of an expression over a box, with witnesses and the measured gap.
//   spar bound "EXPR" --var x=LO:HI [--var ...] [--constraint "x+y<=2"] [--tol 1e-3] [--json]
//   spar bound "EXPR" --var ... [--constraint ...] --keep y [--keep ...]   symbolic SUP/INF in the
//       kept variables (Shostak; linear constraints, target linear in the other variables)
//   spar bound --jsonl FILE [--tol T]     one JSON result per line of an FPBench-style corpus
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/bound_json.hpp"
#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "spar/bounds/bound.hpp"
#include "spar/bounds/shostak.hpp"
#include "spar/common/number.hpp"
#include "spar/symbolic/operations.hpp"
#include "spar/symbolic/parse.hpp"

namespace spar::cli {
namespace {

using bounds::BoundsError;
using symbolic::Expr;

struct BoundArguments {
  std::string expression;
  std::vector<std::string> variables;
  std::vector<std::string> constraints;
  std::vector<std::string> keep;
  std::string jsonl;
  double tolerance{1e-3};
  std::uint64_t max_evaluations{200'000};
  bool json{false};
};

// At most this many boxes per bound: about a minute of work on a simple expression.
constexpr std::uint64_t kMaxEvaluationsLimit = 100'000'000;

double read_bound(const std::string& text, const std::string& what) {
  try {
    return read_number(text, what);
  } catch (const NumberError& error) {
    throw UsageError(error.what());
  }
}

struct VariableRange {
  std::string name, lo, hi;  // the text of "name=LO:HI"
};

VariableRange split_variable(const std::string& text) {
  const auto equals = text.find('='), colon = text.rfind(':');
  if (equals == std::string::npos || colon == std::string::npos || colon < equals) {
    throw UsageError("--var '" + text + "' must look like name=LO:HI");
  }
  return {text.substr(0, equals), text.substr(equals + 1, colon - equals - 1),
          text.substr(colon + 1)};
}

// "x=LO:HI".
void add_variable(symbolic::ExprPool& pool, bounds::Box& box, const std::string& text) {
  const VariableRange range = split_variable(text);
  box.add(pool.variable(range.name), read_bound(range.lo, "--var " + range.name + ": lower bound"),
          read_bound(range.hi, "--var " + range.name + ": upper bound"));
}

// "lhs REL rhs" -> (lhs - rhs) REL 0.
bounds::Constraint parse_constraint(symbolic::ExprPool& pool, const std::string& text) {
  const auto at = text.find_first_of("<>");
  if (at == std::string::npos || text.find_first_of("<>", at + 2) != std::string::npos) {
    throw UsageError("constraint '" + text + "' needs exactly one of <, <=, >, >=");
  }
  const std::size_t length = at + 1 < text.size() && text[at + 1] == '=' ? 2 : 1;
  const Expr lhs = symbolic::parse(pool, text.substr(0, at));
  const Expr rhs = symbolic::parse(pool, text.substr(at + length));
  return {lhs - rhs, relation_named(text.substr(at, length))};
}

bounds::BoundOptions options(const BoundArguments& arguments) {
  bounds::BoundOptions options;
  options.tolerance = arguments.tolerance;
  options.max_box_evaluations = arguments.max_evaluations;
  return options;
}

void run_jsonl(const BoundArguments& arguments) {
  if (std::filesystem::is_directory(arguments.jsonl)) {
    throw UsageError("--jsonl '" + arguments.jsonl + "' is a directory: give a JSONL file");
  }
  std::ifstream in(arguments.jsonl);
  if (!in) throw UsageError("--jsonl: cannot open '" + arguments.jsonl + "'");
  // Progress goes to a terminal only, so redirected stderr stays clean; each result line is
  // flushed as it is done, so an interrupted run keeps every answer it had.
  const bool show_progress = isatty(STDERR_FILENO) != 0;
  std::string line;
  std::size_t failures = 0, done = 0;
  for (std::size_t line_number = 1; std::getline(in, line); ++line_number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    bool ok = true;
    // Invalid UTF-8 (in a name or an error quoting the line) is written as U+FFFD, not thrown.
    std::cout << bound_record(line, line_number, options(arguments), ok)
                     .dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace)
              << std::endl;
    if (!std::cout) flush_standard_output();  // throws: the output is lost, stop now
    failures += ok ? 0 : 1;
    if (show_progress) std::cerr << "\rspar bound: " << ++done << " records bounded" << std::flush;
  }
  if (show_progress && done > 0) std::cerr << '\n';
  if (in.bad()) throw Error("--jsonl: reading '" + arguments.jsonl + "' failed");
  if (failures > 0) {
    throw Error(std::to_string(failures) + " line(s) of '" + arguments.jsonl +
                "' could not be bounded (see their \"error\")");
  }
}

// --keep: Shostak's SUP/INF as expressions in the kept variables. The box ranges become the linear
// constraints LO <= x <= HI (read exactly from their text); every --constraint must be linear.
void run_symbolic(const BoundArguments& arguments) {
  symbolic::ExprPool pool;
  bounds::Box box;  // checks the ranges (NaN, LO > HI, a variable twice)
  std::vector<bounds::LinearConstraint> constraints;
  const auto shostak_error = [](const std::string& what, const bounds::ShostakError& error) {
    return BoundsError("--keep (symbolic SUP/INF) " + what + ": " + error.what());
  };
  for (const std::string& text : arguments.variables) {
    add_variable(pool, box, text);
    const VariableRange range = split_variable(text);
    try {
      for (auto& c : bounds::parse_linear_constraints(
               pool, range.lo + " <= " + range.name + " <= " + range.hi)) {
        constraints.push_back(std::move(c));
      }
    } catch (const bounds::ShostakError& error) {
      throw shostak_error("cannot use the range of '" + range.name + "'", error);
    }
  }
  for (const std::string& text : arguments.constraints) {
    try {
      for (auto& c : bounds::parse_linear_constraints(pool, text)) constraints.push_back(c);
    } catch (const bounds::ShostakError& error) {
      throw shostak_error("needs linear constraints with exact coefficients, not '" + text + "'",
                          error);
    }
  }
  std::vector<Expr> keep;
  for (const std::string& name : arguments.keep) {
    const Expr v = pool.variable(name);
    if (std::find(box.variables.begin(), box.variables.end(), v) == box.variables.end()) {
      throw UsageError("--keep '" + name + "' is not a variable given with --var");
    }
    keep.push_back(v);
  }
  const Expr f = symbolic::parse(pool, arguments.expression);
  for (Expr v : symbolic::free_variables(f)) {
    if (std::find(box.variables.begin(), box.variables.end(), v) == box.variables.end()) {
      throw UsageError("unknown variable '" + v.name() + "' in the expression: give it a range");
    }
  }
  Expr upper, lower;
  try {
    upper = bounds::sup(f, constraints, keep);
    lower = bounds::inf(f, constraints, keep);
  } catch (const bounds::ShostakError& error) {
    throw shostak_error("cannot bound '" + arguments.expression + "'", error);
  }
  if (arguments.json) {
    nlohmann::json out;
    out["sup"] = symbolic::to_string(upper);
    out["inf"] = symbolic::to_string(lower);
    out["keep"] = arguments.keep;
    std::cout << out.dump(2) << '\n';
    return;
  }
  std::cout << "SUP = " << symbolic::to_string(upper) << "\n"
            << "INF = " << symbolic::to_string(lower) << "\n";
}

void run_single(const BoundArguments& arguments) {
  if (arguments.expression.empty()) throw UsageError("give an expression or --jsonl FILE");
  if (!arguments.keep.empty()) return run_symbolic(arguments);
  symbolic::ExprPool pool;
  bounds::Box box;
  for (const std::string& v : arguments.variables) add_variable(pool, box, v);
  const Expr f = symbolic::parse(pool, arguments.expression);
  std::vector<bounds::Constraint> constraints;
  for (const std::string& c : arguments.constraints) {
    constraints.push_back(parse_constraint(pool, c));
  }
  const auto start = std::chrono::steady_clock::now();
  const bounds::BoundResult r = bounds::bound(f, box, options(arguments), constraints);
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  if (arguments.json) {
    std::cout << bound_result_json("", box, r, elapsed.count()).dump(2) << '\n';
    return;
  }
  if (r.status == bounds::BoundStatus::kInfeasible) {
    std::cout << "status   infeasible: no point of the box satisfies the constraints and gives the "
                 "expression a defined value\n";
    return;
  }
  std::cout.precision(17);
  std::cout << "range    [" << r.lo << ", " << r.hi << "]   (sound)\n";
  if (r.has_inner_range()) {
    std::cout << "attained [" << r.inner_lo << ", " << r.inner_hi << "]\n";
  } else {
    std::cout << "attained none (" << r.why_no_inner_range() << ")\n";
  }
  std::cout << "status   " << bounds::to_string(r.status)
            << (r.possibly_undefined ? " (possibly undefined somewhere in the box)" : "") << '\n';
  std::cout.precision(6);
  const double gap = r.relative_gap();
  std::cout << "gap      ";
  if (std::isfinite(gap)) {
    std::cout << gap << " of the attained width";
  } else {
    std::cout << "none measurable (unbounded or a single attained value)";
  }
  std::cout << ", " << r.evaluations << " boxes, " << std::round(elapsed.count() * 1e6) << " us\n";
  const auto print_point = [&](const char* label, const std::vector<double>& x) {
    if (x.empty()) return;
    std::cout << label;
    for (std::size_t i = 0; i < x.size(); ++i) {
      std::cout << ' ' << box.variables[i].name() << '=' << x[i];
    }
    std::cout << '\n';
  };
  print_point("argmin  ", r.argmin);
  print_point("argmax  ", r.argmax);
}

}  // namespace

void add_bound_command(CLI::App& app) {
  auto* command = app.add_subcommand(
      "bound", "Sound SUP/INF of an expression over a box, with witnesses and the tightness gap");
  auto arguments = std::make_shared<BoundArguments>();
  command->add_option("expression", arguments->expression, "Infix expression, e.g. \"x*sin(y)\"");
  // One value per occurrence, so a following expression is never taken as another range.
  command->add_option("--var", arguments->variables, "Variable range name=LO:HI (repeatable)")
      ->allow_extra_args(false);
  command
      ->add_option("--constraint", arguments->constraints,
                   "Constraint such as \"x+y<=2\" (repeatable)")
      ->allow_extra_args(false);
  command
      ->add_option("--keep", arguments->keep,
                   "Keep this variable: print SUP/INF as expressions in the kept variables "
                   "(Shostak; linear constraints only; repeatable)")
      ->allow_extra_args(false);
  command->add_option("--jsonl", arguments->jsonl,
                      "Bound every line of an FPBench-style JSONL corpus");
  add_number_option(*command, "--tol", arguments->tolerance, "Relative tolerance",
                    NumberLimits::non_negative());
  add_count_option(*command, "--max-evals", arguments->max_evaluations, "Box evaluation limit", 1,
                   kMaxEvaluationsLimit);
  command->add_flag("--json", arguments->json, "Print the result as JSON");
  command->callback([arguments] {
    if (!arguments->jsonl.empty()) {
      if (!arguments->expression.empty() || !arguments->variables.empty() ||
          !arguments->constraints.empty() || !arguments->keep.empty() || arguments->json) {
        throw UsageError(
            "--jsonl bounds the records of a file (each with its own expression and ranges): it "
            "cannot be combined with an expression, --var, --constraint, --keep or --json");
      }
      run_jsonl(*arguments);
    } else {
      run_single(*arguments);
    }
  });
}

}  // namespace spar::cli
