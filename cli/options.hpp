// What every `spar` subcommand shares at the command-line boundary: the usage error, numeric
// options read by spar's one number reader (common/number.hpp), expressions that start with '-',
// and output that must not be lost silently.
//
// Numeric options: add_number_option / add_count_option read the text with read_number /
// read_count, so every option accepts what spar prints (subnormals, 17 digits) and refuses NaN,
// infinities, overflow and values outside its limits with "--name: must be a positive number, got
// 'nan'" -- never CLI11's "Value ... not in range [2.2e-308 - 1.797...e+308]". Options that set
// the amount of work take an upper limit too, so no option can make a command run unbounded.
//
// Leading minus: CLI11 reads "-x" and "-(x)" as short options. spar has no short option but -h,
// so `protect_leading_minus` marks every "-c..." argument (other than -h) as a value, and
// `accept_leading_minus` makes every option and positional of the app remove the mark again:
// `spar simplify "-(x)"` and `spar bound --constraint "-x<=1" ...` work as written: every
// expression spar prints (a report's "-(...)") is accepted back. After `--`
// arguments are left alone (CLI11 takes them all as positionals).
//
// Output: `flush_standard_output` (main.cpp calls it after every command) and `write_file` throw
// spar::Error when the output cannot be written (a full disk, /dev/full), so no command exits 0
// having lost its output.
//
// Example:
//   auto opening = std::make_shared<double>(0.1016);
//   add_number_option(*command, "--max-opening", *opening, "gripper opening (m)",
//                     NumberLimits::positive());
//   std::vector<std::string> args = protect_leading_minus(argc, argv);
//   accept_leading_minus(app);
//   app.parse(args);   // args as protect_leading_minus returns them (reversed, as CLI11 wants)
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "spar/common/error.hpp"
#include "spar/common/limits.hpp"
#include "spar/common/number.hpp"

namespace spar::cli {

// A mistake in how spar was called (an option's value, a conflict between options); main prints it
// as one "spar: error: ..." line and exits 1.
class UsageError : public Error {
 public:
  using Error::Error;
};

// `name` takes one number inside `limits` into `value` (its default is shown by --help).
CLI::Option* add_number_option(CLI::App& command, const std::string& name, double& value,
                               const std::string& description, const NumberLimits& limits);
// The same for an option whose default is decided later (value stays empty when not given).
CLI::Option* add_number_option(CLI::App& command, const std::string& name,
                               std::optional<double>& value, const std::string& description,
                               const NumberLimits& limits);

// `name` takes one whole number from `low` to `high` into `value` (high must fit the type).
CLI::Option* add_count_option(CLI::App& command, const std::string& name, std::uint64_t& value,
                              const std::string& description, std::uint64_t low,
                              std::uint64_t high);
CLI::Option* add_count_option(CLI::App& command, const std::string& name, int& value,
                              const std::string& description, std::uint64_t low,
                              std::uint64_t high);

// On a terminal (stderr is a tty), one line of stderr saying what a long command is doing
// ("spar object: grasps ..."), replaced by each show() and cleared when destroyed (or by clear(),
// before a line of the command's own); nothing when stderr is not a terminal.
class StatusLine {
 public:
  explicit StatusLine(std::string command);
  StatusLine(const StatusLine&) = delete;
  StatusLine& operator=(const StatusLine&) = delete;
  ~StatusLine();
  void show(std::string_view stage) const;
  void clear() const;
  [[nodiscard]] bool shown() const { return shown_; }

 private:
  std::string command_;
  bool shown_;
};

// Throws UsageError "<option>: must be ..." when `value` (metres, radians or a count) is outside
// the row `limit_key` of the table of numeric limits (common/limits.hpp), shown in `unit`: the
// options that set what a scenario key sets refuse what the scenario loader refuses.
void check_limit(std::string_view option, std::string_view limit_key, double value,
                 GivenUnit unit = {}, std::string_view given_text = {});

// argv[1..] with every "-<letter>..." argument before a "--" marked as a value, in the reversed
// order CLI::App::parse(std::vector<std::string>&) takes.
[[nodiscard]] std::vector<std::string> protect_leading_minus(int argc, const char* const* argv);
// Makes every option and positional of `app` and its subcommands drop protect_leading_minus' mark.
void accept_leading_minus(CLI::App& app);

// Flushes std::cout (and C stdio); throws spar::Error naming the system's reason if anything
// written to standard output was lost.
void flush_standard_output();
// Writes `path` with `write`, closes it and throws spar::Error ("cannot write <what> to 'path':
// reason") if it cannot be opened, is a directory, or any byte was not written.
void write_file(const std::string& path, const std::string& what,
                const std::function<void(std::ostream&)>& write);

}  // namespace spar::cli
