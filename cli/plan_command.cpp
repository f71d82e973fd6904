// `spar plan`: plans scenario files with SPAR's two phases and reports on them. Everything it
// prints is written from the report model (reports/model.hpp), never from planner internals.
//
//   spar plan SCENARIO                      the Markdown report on standard output (SCENARIO "-":
//                                           read from standard input, meshes relative to the
//                                           working directory)
//   spar plan SCENARIO --report DIR         writes DIR/report.{json,md,html} atomically (nothing
//             [--format json,md,html]       when planning fails) and prints a summary and where
//   spar plan SCENARIO --json               the JSON report on standard output
//   spar plan SCENARIO --jobs N             N threads for its grasp searches and the chosen
//                                           instance's margins (0, the default: one per core;
//                                           the report is the same)
//   spar plan --batch FILE_OR_DIR [--jobs N] [--report DIR]
//             many scenarios (a folder's *.yaml, or a file listing one path per line, relative to
//             the file) on a thread pool: one JSON line per scenario, in input order, either
//             {"file", "report"} or {"file", "error"}; a progress bar on stderr when it is a
//             terminal; with --report, each report goes to DIR/<file stem>/. A bad scenario gives
//             an error record and the batch goes on.
//   exit status (normative): 0 planned with every precondition proved, 1 bad input or usage, 2 no
//             plan, 3 planned with errors left to verify at execution; a batch exits with the
//             highest of its scenarios' (a bad scenario counts 1, and is named on stderr).
//   one scenario on a terminal: the stage planning is at on one line of stderr (phase 1, phase 2
//             instance k of N, margins, probability), cleared when it ends.
//   common options: --domain FILE, --instances N, --max-nodes N, --max-steps N, --samples N
//             (Monte Carlo points of the failure-probability analysis; 0 turns it and the
//             tolerance allocation off: planner/uncertainty/probability.hpp)
//
// `spar demo [--report DIR] [--json] ...` is `spar plan` on the built-in example, the seed's
// peg-and-block task with the block face down (examples/peg_block_face_down.yaml, compiled in),
// its report written to report/ unless --report says where.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <future>
#include <iostream>
#include <iterator>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "cli/batch.hpp"
#include "cli/commands.hpp"
#include "cli/demo_scenario.hpp"
#include "cli/options.hpp"
#include "spar/common/deadline.hpp"
#include "spar/common/parallel.hpp"
#include "spar/common/text.hpp"
#include "spar/planner/plan.hpp"
#include "spar/reports/build.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/markdown.hpp"
#include "spar/reports/write.hpp"

namespace spar::cli {
namespace {

namespace fs = std::filesystem;

// The exit status `spar plan` gives a report (kPlan... in cli/commands.hpp).
int plan_exit_status(const reports::Report& report) {
  if (!report.chosen) return kPlanNoPlan;
  const reports::Chosen& chosen = *report.chosen;
  bool proved = chosen.errors.value_or(0) == 0;
  for (const reports::Step& step : chosen.steps)
    if (step.preconditions)
      for (const reports::Precondition& precondition : *step.preconditions)
        proved = proved && precondition.verdict == "satisfied";
  return proved ? kPlanProved : kPlanWithErrors;
}

const char* kExitStatusHelp =
    "Exit status: 0 planned, every precondition proved; 1 bad input or usage; 2 no plan; 3 "
    "planned, with errors left to verify at execution (the report's verification and recovery). "
    "--batch exits with the highest status of its scenarios (a scenario that cannot be read "
    "counts 1).";

struct PlanArguments {
  bool demo{false};      // plan the built-in example instead of `scenario`
  std::string scenario;  // "-": standard input
  std::string domain;
  std::string report;
  std::string formats{"json,md,html"};
  std::string batch;
  bool json{false};
  int jobs{0};  // 0: the core count
  std::uint64_t instances{16};
  std::uint64_t max_nodes{200'000};
  int max_steps{64};
  std::uint64_t samples{20'000};     // probabilistic analysis (0: off)
  std::optional<double> time_limit;  // seconds per scenario (common/deadline.hpp)
};

reports::Report plan_report(const planner::Scenario& scenario, const planner::Domain& domain,
                            const planner::PlanOptions& options) {
  return reports::build_report(planner::plan(scenario, domain, options));
}

// "wrote report/report.html (and report.json, report.md)".
std::string written_text(const std::vector<fs::path>& files) {
  std::string out = "report: " + files.front().string();
  for (std::size_t i = 1; i < files.size(); ++i)
    out += (i == 1 ? " (also " : ", ") + files[i].filename().string();
  return out + (files.size() > 1 ? ")" : "");
}

// The HTML first when there is one: it is what a person opens.
std::vector<reports::Format> html_first(std::vector<reports::Format> formats) {
  std::stable_partition(formats.begin(), formats.end(),
                        [](reports::Format format) { return format == reports::Format::kHtml; });
  return formats;
}

// The scenario `spar plan` names: a file, "-" for standard input (mesh paths relative to the
// working directory), or the built-in example.
planner::Scenario read_scenario(const PlanArguments& arguments) {
  if (arguments.demo)
    return planner::parse_scenario(kDemoScenarioText, "peg_block_face_down.yaml (built in)", ".");
  if (arguments.scenario == "-") {
    const std::string text{std::istreambuf_iterator<char>(std::cin),
                           std::istreambuf_iterator<char>()};
    if (std::cin.bad()) throw Error("cannot read the scenario from standard input");
    return planner::parse_scenario(text, "<stdin>", ".");
  }
  return planner::load_scenario(arguments.scenario);
}

// `domain` is read on another thread meanwhile: the scenario's loading and the domain's parsing
// take a few milliseconds each.
int run_single(const PlanArguments& arguments, std::future<planner::Domain> domain,
               planner::PlanOptions options) {
  const std::vector<reports::Format> formats =
      html_first(reports::parse_formats(arguments.formats));
  const reports::Report report = [&] {
    // On a terminal, the stage planning is at, cleared when it ends (or fails, before the error
    // is printed).
    const StatusLine status("spar plan");
    if (status.shown())
      options.progress = [&status](std::string_view stage) { status.show(stage); };
    std::optional<ScopedDeadline> deadline;
    if (arguments.time_limit)
      deadline.emplace(std::chrono::duration<double>(*arguments.time_limit));
    status.show("loading the scenario (meshes, stable poses)");
    const planner::Scenario scenario = [&] {
      try {
        return read_scenario(arguments);
      } catch (...) {
        (void)domain.get();  // a bad domain is reported first, as when it was read first
        throw;
      }
    }();
    const planner::Domain read_domain = domain.get();
    status.clear();
    for (const std::string& warning : scenario.warnings)
      std::cerr << "spar: warning: " << warning << '\n';
    return plan_report(scenario, read_domain, options);
  }();
  std::vector<fs::path> files;
  if (!arguments.report.empty()) files = reports::write_reports(report, arguments.report, formats);
  if (arguments.json) {
    std::cout << reports::to_json(report).dump(2) << '\n';
    if (!files.empty()) std::cerr << written_text(files) << '\n';
  } else if (!files.empty()) {
    std::cout << reports::summary(report) << written_text(files) << '\n';
  } else {
    std::cout << reports::render_markdown(report);
  }
  return plan_exit_status(report);
}

// "[#####.....] 3/10 scenarios, 2 running for 41 s": redrawn every second while scenarios run, so
// a batch whose scenario takes minutes is not silent.
void draw_progress(std::size_t done, std::size_t total, std::size_t running, double seconds) {
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(kWidth * done / total);
  std::cerr << "\r\033[K[" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] "
            << done << "/" << total << " scenarios";
  if (running > 0 && seconds >= 1)
    std::cerr << ", " << running << " running for " << static_cast<long>(seconds) << " s";
  std::cerr << (done == total ? "\n" : "") << std::flush;
}

int run_batch(const PlanArguments& arguments, const planner::Domain& domain,
              const planner::PlanOptions& options) {
  const std::vector<BatchItem> items = batch_items(arguments.batch);
  const std::vector<reports::Format> formats =
      html_first(reports::parse_formats(arguments.formats));
  if (!arguments.report.empty()) {
    std::set<std::string> stems;
    for (const BatchItem& item : items)
      if (!stems.insert(fs::path(item.path).stem().string()).second)
        throw UsageError("--batch with --report: two scenarios are named " +
                         single_quoted(fs::path(item.path).stem().string()) +
                         " (each report goes to DIR/<stem>/)");
  }
  const std::size_t jobs =
      std::min<std::size_t>(items.size(), arguments.jobs > 0 ? arguments.jobs : default_threads());
  std::mutex mutex;
  int status = kPlanProved;  // the highest of the scenarios' (a failed one: kPlanBadInput)
  const PlanOne plan_one = [&](const planner::Scenario& scenario, nlohmann::ordered_json& record) {
    const reports::Report report = plan_report(scenario, domain, options);
    {
      const std::lock_guard lock(mutex);
      status = std::max(status, plan_exit_status(report));
    }
    record["report"] = reports::to_json(report);
    if (!arguments.report.empty())
      (void)reports::write_reports(
          report, fs::path(arguments.report) / fs::path(scenario.path).stem(), formats);
  };

  // Workers take the next index; the calling thread prints the lines in input order.
  std::vector<std::string> lines(items.size());
  std::vector<bool> ready(items.size(), false);
  std::atomic<std::size_t> next{0};
  std::condition_variable finished;
  std::size_t failures = 0, started = 0;
  const auto work = [&] {
    for (std::size_t i = next++; i < items.size(); i = next++) {
      {
        const std::lock_guard lock(mutex);
        ++started;
      }
      BatchLine line = batch_line(items[i], plan_one, arguments.time_limit);  // never throws
      const std::lock_guard lock(mutex);
      lines[i] = std::move(line.json);
      ready[i] = true;
      failures += line.failed ? 1 : 0;
      if (line.failed) status = std::max(status, kPlanBadInput);
      finished.notify_all();
    }
  };
  std::vector<std::jthread> pool;
  for (std::size_t j = 0; j < jobs; ++j) pool.emplace_back(work);
  const bool progress = isatty(STDERR_FILENO) == 1;
  const auto start = std::chrono::steady_clock::now();
  std::size_t printed = 0;
  while (printed < items.size()) {
    std::unique_lock lock(mutex);
    if (!finished.wait_for(lock, std::chrono::seconds(1), [&] { return ready[printed]; })) {
      const std::size_t done = std::count(ready.begin(), ready.end(), true);
      lock.unlock();
      if (progress)
        draw_progress(
            done, items.size(), started - done,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      continue;
    }
    const std::string line = std::move(lines[printed++]);
    const std::size_t done = std::count(ready.begin(), ready.end(), true);
    lock.unlock();
    if (progress) std::cerr << "\r\033[K" << std::flush;  // clear the bar, print, redraw it
    std::cout << line << '\n' << std::flush;
    if (progress) draw_progress(done, items.size(), 0, 0);
  }
  pool.clear();
  if (failures > 0)
    std::cerr << "spar: error: " << failures << " of " << items.size()
              << " scenarios failed (their records say why)\n";
  return status;
}

int run_plan(const PlanArguments& arguments) {
  if (!arguments.demo && arguments.scenario.empty() == arguments.batch.empty())
    throw UsageError("spar plan takes a SCENARIO file or --batch FILE_OR_DIR (one of the two)");
  if (!arguments.batch.empty() && arguments.json)
    throw UsageError("--json: a batch always prints JSON lines");
  std::future<planner::Domain> domain = std::async(std::launch::async, [&arguments] {
    return arguments.domain.empty() ? planner::builtin_domain()
                                    : planner::load_domain(arguments.domain);
  });
  planner::PlanOptions options;
  options.max_instances = arguments.instances;
  options.posting.max_nodes = arguments.max_nodes;
  options.posting.max_steps = arguments.max_steps;
  if (arguments.samples == 0)
    options.probability.reset();
  else
    options.probability->samples = arguments.samples;
  // One scenario uses every core for its parts; a batch uses them for its scenarios.
  if (arguments.batch.empty())
    options.threads = arguments.jobs > 0 ? arguments.jobs : default_threads();
  return arguments.batch.empty() ? run_single(arguments, std::move(domain), options)
                                 : run_batch(arguments, domain.get(), options);
}

// The options `spar plan` and `spar demo` share.
CLI::Option* add_report_options(CLI::App& command, PlanArguments& arguments) {
  command
      .add_option("--report", arguments.report,
                  "write the report into this folder (report.json, report.md, report.html)")
      ->check([](const std::string& folder) {
        return folder.empty() ? std::string("give a folder name, not ''") : std::string();
      });
  CLI::Option* format = command.add_option(
      "--format", arguments.formats, "report formats, comma-separated (default json,md,html)");
  command.add_flag("--json", arguments.json, "print the JSON report (docs/report-schema.md)");
  command.add_option("--domain", arguments.domain,
                     "action templates (YAML; default: the built-in planner/domain.yaml)");
  add_count_option(command, "--instances", arguments.instances,
                   "plan instances to enumerate (default 16)", 1, 100'000);
  add_count_option(command, "--max-nodes", arguments.max_nodes,
                   "partial plans the search may expand (default 200000)", 1, 100'000'000);
  add_count_option(command, "--max-steps", arguments.max_steps, "actions in one plan (default 64)",
                   1, 10'000);
  add_count_option(command, "--samples", arguments.samples,
                   "Monte Carlo points of the failure-probability analysis (default 20000; 0: no "
                   "probability analysis or tolerance allocation)",
                   0, 100'000'000);
  add_number_option(command, "--time-limit", arguments.time_limit,
                    "seconds one scenario may take, loading included (default: none); in a "
                    "batch, a scenario past it gets a \"time_limit\" record and the batch goes on",
                    NumberLimits{0, 1e6, true});
  return format;
}

void set_callback(CLI::App& command, std::shared_ptr<PlanArguments> arguments, CLI::Option* format,
                  int& exit_status) {
  command.footer(kExitStatusHelp);
  command.callback([arguments, format, &exit_status] {
    if (format->count() > 0 && arguments->report.empty())
      throw UsageError("--format needs --report DIR");
    exit_status = run_plan(*arguments);
  });
}

}  // namespace

void add_plan_command(CLI::App& app, int& exit_status) {
  auto arguments = std::make_shared<PlanArguments>();
  CLI::App* command = app.add_subcommand(
      "plan", "Plan a scenario file (SPAR) and report on it: plan, preconditions, repairs");
  command->add_option("scenario", arguments->scenario,
                      "scenario file (YAML, docs/scenario.md); - reads it from standard input");
  command->add_option("--batch", arguments->batch,
                      "plan many scenarios: a folder of *.yaml or a file listing paths");
  add_count_option(*command, "--jobs", arguments->jobs,
                   "threads: a batch's scenarios at once, or one scenario's parts; 0 for "
                   "the number of cores (default 0)",
                   0, 256);
  set_callback(*command, arguments, add_report_options(*command, *arguments), exit_status);
}

void add_demo_command(CLI::App& app, int& exit_status) {
  auto arguments = std::make_shared<PlanArguments>();
  arguments->demo = true;
  arguments->report = "report";
  CLI::App* command = app.add_subcommand(
      "demo",
      "spar plan on the built-in example: the seed's peg and block, block face down; the report "
      "goes to report/ (--report DIR: elsewhere)");
  set_callback(*command, arguments, add_report_options(*command, *arguments), exit_status);
}

}  // namespace spar::cli
