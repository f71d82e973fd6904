#include "cli/options.hpp"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>

namespace spar::cli {
namespace {

// What protect_leading_minus puts before "-x": a space is never part of an option name, so CLI11
// takes " -x" as a value; every option drops it again.
constexpr char kValueMark = ' ';

// CLI11 (2.1.2) reads "-c..." as the short option -c for every c but '-', '!', ' ' and '\n'
// (detail::valid_first_char): "-(x)" and "-sin(x)" too, and "-2*x" unless no option -2 exists.
// spar has no short option but -h, so every other "-c..." is a value ("-" alone is stdin).
bool looks_like_short_option(const std::string& argument) {
  return argument.size() >= 2 && argument[0] == '-' && argument[1] != '-' && argument != "-h";
}

std::string system_reason() { return errno != 0 ? std::strerror(errno) : "input/output error"; }

template <typename Integer>
CLI::Option* add_whole_number_option(CLI::App& command, const std::string& name, Integer& value,
                                     const std::string& description, std::uint64_t low,
                                     std::uint64_t high) {
  if (high > static_cast<std::uint64_t>(std::numeric_limits<Integer>::max())) {
    throw std::logic_error(name + ": the upper limit does not fit the option's type");
  }
  CLI::Option* option = command.add_option_function<std::string>(
      name,
      [&value, name, low, high](const std::string& text) {
        try {
          value = static_cast<Integer>(read_count(text, name, low, high));
        } catch (const NumberError& error) {
          throw UsageError(error.what());
        }
      },
      description);
  return option->type_name("INT")->default_str(std::to_string(value));
}

CLI::Option* add_number_option_with(CLI::App& command, const std::string& name,
                                    std::function<void(double)> store,
                                    const std::string& description, const NumberLimits& limits) {
  CLI::Option* option = command.add_option_function<std::string>(
      name,
      [store = std::move(store), name, limits](const std::string& text) {
        try {
          store(read_number(text, name, limits));
        } catch (const NumberError& error) {
          throw UsageError(error.what());
        }
      },
      description);
  return option->type_name("NUMBER");
}

}  // namespace

CLI::Option* add_number_option(CLI::App& command, const std::string& name, double& value,
                               const std::string& description, const NumberLimits& limits) {
  return add_number_option_with(
             command, name, [&value](double read) { value = read; }, description, limits)
      ->default_str(format_number(value));
}

CLI::Option* add_number_option(CLI::App& command, const std::string& name,
                               std::optional<double>& value, const std::string& description,
                               const NumberLimits& limits) {
  return add_number_option_with(
      command, name, [&value](double read) { value = read; }, description, limits);
}

CLI::Option* add_count_option(CLI::App& command, const std::string& name, std::uint64_t& value,
                              const std::string& description, std::uint64_t low,
                              std::uint64_t high) {
  return add_whole_number_option(command, name, value, description, low, high);
}

CLI::Option* add_count_option(CLI::App& command, const std::string& name, int& value,
                              const std::string& description, std::uint64_t low,
                              std::uint64_t high) {
  return add_whole_number_option(command, name, value, description, low, high);
}

StatusLine::StatusLine(std::string command)
    : command_(std::move(command)), shown_(isatty(STDERR_FILENO) == 1) {}

StatusLine::~StatusLine() { clear(); }

void StatusLine::show(std::string_view stage) const {
  if (shown_) std::cerr << "\r\033[K" << command_ << ": " << stage << " ..." << std::flush;
}

void StatusLine::clear() const {
  if (shown_) std::cerr << "\r\033[K" << std::flush;
}

void check_limit(std::string_view option, std::string_view limit_key, double value, GivenUnit unit,
                 std::string_view given_text) {
  if (const auto problem = limit_problem(numeric_limit(limit_key), value, unit, given_text))
    throw UsageError(std::string(option) + ": " + *problem);
}

std::vector<std::string> protect_leading_minus(int argc, const char* const* argv) {
  std::vector<std::string> arguments;
  bool after_separator = false;
  for (int i = 1; i < argc; ++i) {
    std::string argument = argv[i];
    if (argument == "--") after_separator = true;
    if (!after_separator && looks_like_short_option(argument)) argument.insert(0, 1, kValueMark);
    arguments.push_back(std::move(argument));
  }
  return {arguments.rbegin(), arguments.rend()};
}

void accept_leading_minus(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_size() == 0) continue;  // a flag takes no value
    option->transform(
        [](std::string value) {
          if (value.starts_with(std::string{kValueMark, '-'})) value.erase(0, 1);
          return value;
        },
        "", "");
  }
  for (CLI::App* command : app.get_subcommands({})) accept_leading_minus(*command);
}

void flush_standard_output() {
  // A write that already failed left its reason in errno: keep it for the message.
  const int earlier = std::cout ? 0 : errno;
  errno = 0;
  std::cout.flush();
  const bool lost = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout) != 0;
  if (errno == 0) errno = earlier;
  if (lost) throw Error("cannot write the output to standard output: " + system_reason());
}

void write_file(const std::string& path, const std::string& what,
                const std::function<void(std::ostream&)>& write) {
  errno = 0;
  std::ofstream file(path);
  if (!file) throw Error("cannot write " + what + " to '" + path + "': " + system_reason());
  write(file);
  file.close();
  if (!file) throw Error("cannot write " + what + " to '" + path + "': " + system_reason());
}

}  // namespace spar::cli
