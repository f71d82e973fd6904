// `spar plan`: plans scenario files with SPAR's two phases and reports on them. Everything it
// prints is written from the report model (reports/model.hpp), never from planner internals.
//
//   spar plan SCENARIO                      the Markdown report on standard output
//   spar plan SCENARIO --report DIR         writes DIR/report.{json,md,html} atomically (nothing
//             [--format json,md,html]       when planning fails) and prints a summary and where
//   spar plan SCENARIO --json               the JSON report on standard output
//   spar plan --batch FILE_OR_DIR [--jobs N] [--report DIR]
//             many scenarios (a folder's *.yaml, or a file listing one path per line, relative to
//             the file) on a thread pool: one JSON line per scenario, in input order, either
//             {"file", "report"} or {"file", "error"}; a progress bar on stderr when it is a
//             terminal; with --report, each report goes to DIR/<file stem>/. A bad scenario gives
//             an error record and the batch goes on; the command fails at the end if any did.
//   one scenario on a terminal: the stage planning is at on one line of stderr (phase 1, phase 2
//             instance k of N, margins, probability), cleared when it ends.
//   common options: --domain FILE, --instances N, --max-nodes N, --max-steps N, --samples N
//             (Monte Carlo points of the failure-probability analysis; 0 turns it and the
//             tolerance allocation off: planner/uncertainty/probability.hpp)
//
// `spar demo [--report DIR] [--json] ...` is `spar plan` on the built-in example, the seed's
// peg-and-block task with the block face down (examples/peg_block_face_down.yaml, compiled in).
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <set>
#include <thread>

#include "cli/commands.hpp"
#include "cli/demo_scenario.hpp"
#include "cli/options.hpp"
#include "spar/planner/plan.hpp"
#include "spar/reports/build.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/markdown.hpp"
#include "spar/reports/write.hpp"

namespace spar::cli {
namespace {

namespace fs = std::filesystem;

struct PlanArguments {
  bool demo{false};  // plan the built-in example instead of `scenario`
  std::string scenario;
  std::string domain;
  std::string report;
  std::string formats{"json,md,html"};
  std::string batch;
  bool json{false};
  int jobs{0};  // 0: the core count
  std::uint64_t instances{16};
  std::uint64_t max_nodes{200'000};
  int max_steps{64};
  std::uint64_t samples{20'000};  // probabilistic analysis (0: off)
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

// On a terminal, the stage plan() is at on one line of stderr, cleared when planning ends (or
// fails, before the error is printed).
class StageLine {
 public:
  explicit StageLine(planner::PlanOptions& options) : shown_(isatty(STDERR_FILENO) == 1) {
    if (shown_)
      options.progress = [](std::string_view stage) {
        std::cerr << "\r\033[Kspar plan: " << stage << " ..." << std::flush;
      };
  }
  StageLine(const StageLine&) = delete;
  StageLine& operator=(const StageLine&) = delete;
  ~StageLine() {
    if (shown_) std::cerr << "\r\033[K" << std::flush;
  }

 private:
  bool shown_;
};

void run_single(const PlanArguments& arguments, const planner::Domain& domain,
                planner::PlanOptions options) {
  const std::vector<reports::Format> formats =
      html_first(reports::parse_formats(arguments.formats));
  const reports::Report report = [&] {
    const StageLine stage_line(options);
    return plan_report(
        arguments.demo
            ? planner::parse_scenario(kDemoScenarioText, "peg_block_face_down.yaml (built in)", ".")
            : planner::load_scenario(arguments.scenario),
        domain, options);
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
}

// The scenarios of a batch: a folder's *.yaml / *.yml files (sorted), or the lines of a list file
// (blank lines and # comments skipped), relative to the list's folder.
std::vector<std::string> batch_files(const std::string& source) {
  std::vector<std::string> files;
  if (fs::is_directory(source)) {
    for (const auto& entry : fs::directory_iterator(source))
      if (entry.is_regular_file() &&
          (entry.path().extension() == ".yaml" || entry.path().extension() == ".yml"))
        files.push_back(entry.path().string());
    std::sort(files.begin(), files.end());
    if (files.empty()) throw UsageError("--batch: no *.yaml scenario in folder '" + source + "'");
    return files;
  }
  std::ifstream list(source);
  if (!list) throw UsageError("--batch: cannot read '" + source + "' (a folder or a list file)");
  const fs::path base = fs::path(source).parent_path();
  for (std::string line; std::getline(list, line);) {
    line.erase(0, line.find_first_not_of(" \t"));
    line.erase(line.find_last_not_of(" \t\r") + 1);
    if (line.empty() || line[0] == '#') continue;
    files.push_back(fs::path(line).is_absolute() ? line : (base / line).string());
  }
  if (files.empty()) throw UsageError("--batch: '" + source + "' lists no scenario");
  return files;
}

void draw_progress(std::size_t done, std::size_t total) {
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(kWidth * done / total);
  std::cerr << "\r[" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] "
            << done << "/" << total << " scenarios" << (done == total ? "\n" : "") << std::flush;
}

void run_batch(const PlanArguments& arguments, const planner::Domain& domain,
               const planner::PlanOptions& options) {
  const std::vector<std::string> files = batch_files(arguments.batch);
  const std::vector<reports::Format> formats =
      html_first(reports::parse_formats(arguments.formats));
  if (!arguments.report.empty()) {
    std::set<std::string> stems;
    for (const std::string& file : files)
      if (!stems.insert(fs::path(file).stem().string()).second)
        throw UsageError("--batch with --report: two scenarios are named '" +
                         fs::path(file).stem().string() + "' (each report goes to DIR/<stem>/)");
  }
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t jobs =
      std::min<std::size_t>(files.size(), arguments.jobs > 0 ? arguments.jobs : cores);

  // Workers take the next index; the calling thread prints the lines in input order.
  std::vector<std::string> lines(files.size());
  std::vector<bool> ready(files.size(), false);
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::condition_variable finished;
  std::size_t failures = 0;
  const auto work = [&] {
    for (std::size_t i = next++; i < files.size(); i = next++) {
      nlohmann::ordered_json record = {{"file", files[i]}};
      bool failed = false;
      try {
        const reports::Report report =
            plan_report(planner::load_scenario(files[i]), domain, options);
        record["report"] = reports::to_json(report);
        if (!arguments.report.empty())
          (void)reports::write_reports(
              report, fs::path(arguments.report) / fs::path(files[i]).stem(), formats);
      } catch (const std::exception& error) {
        record.erase("report");
        record["error"] = error.what();
        failed = true;
      }
      const std::lock_guard lock(mutex);
      lines[i] = record.dump();
      ready[i] = true;
      failures += failed ? 1 : 0;
      finished.notify_all();
    }
  };
  std::vector<std::jthread> pool;
  for (std::size_t j = 0; j < jobs; ++j) pool.emplace_back(work);
  const bool progress = isatty(STDERR_FILENO) == 1;
  std::size_t printed = 0;
  while (printed < files.size()) {
    std::unique_lock lock(mutex);
    finished.wait(lock, [&] { return ready[printed]; });
    const std::string line = std::move(lines[printed++]);
    const std::size_t done = std::count(ready.begin(), ready.end(), true);
    lock.unlock();
    if (progress) std::cerr << "\r\033[K" << std::flush;  // clear the bar, print, redraw it
    std::cout << line << '\n' << std::flush;
    if (progress) draw_progress(done, files.size());
  }
  pool.clear();
  if (failures > 0)
    throw Error(std::to_string(failures) + " of " + std::to_string(files.size()) +
                " scenarios failed (their records say why)");
}

void run_plan(const PlanArguments& arguments) {
  if (!arguments.demo && arguments.scenario.empty() == arguments.batch.empty())
    throw UsageError("spar plan takes a SCENARIO file or --batch FILE_OR_DIR (one of the two)");
  if (!arguments.batch.empty() && arguments.json)
    throw UsageError("--json: a batch always prints JSON lines");
  const planner::Domain domain =
      arguments.domain.empty() ? planner::builtin_domain() : planner::load_domain(arguments.domain);
  planner::PlanOptions options;
  options.max_instances = arguments.instances;
  options.posting.max_nodes = arguments.max_nodes;
  options.posting.max_steps = arguments.max_steps;
  if (arguments.samples == 0)
    options.probability.reset();
  else
    options.probability->samples = arguments.samples;
  if (arguments.batch.empty())
    run_single(arguments, domain, options);
  else
    run_batch(arguments, domain, options);
}

// The options `spar plan` and `spar demo` share.
CLI::Option* add_report_options(CLI::App& command, PlanArguments& arguments) {
  command.add_option("--report", arguments.report,
                     "write the report into this folder (report.json, report.md, report.html)");
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
  return format;
}

void set_callback(CLI::App& command, std::shared_ptr<PlanArguments> arguments,
                  CLI::Option* format) {
  command.callback([arguments, format] {
    if (format->count() > 0 && arguments->report.empty())
      throw UsageError("--format needs --report DIR");
    run_plan(*arguments);
  });
}

}  // namespace

void add_plan_command(CLI::App& app) {
  auto arguments = std::make_shared<PlanArguments>();
  CLI::App* command = app.add_subcommand(
      "plan", "Plan a scenario file (SPAR) and report on it: plan, preconditions, repairs");
  command->add_option("scenario", arguments->scenario, "scenario file (YAML, docs/scenario.md)");
  command->add_option("--batch", arguments->batch,
                      "plan many scenarios: a folder of *.yaml or a file listing paths");
  add_count_option(*command, "--jobs", arguments->jobs,
                   "batch threads (default: the number of cores)", 1, 256);
  set_callback(*command, arguments, add_report_options(*command, *arguments));
}

void add_demo_command(CLI::App& app) {
  auto arguments = std::make_shared<PlanArguments>();
  arguments->demo = true;
  CLI::App* command = app.add_subcommand(
      "demo", "spar plan on the built-in example: the seed's peg and block, block face down");
  set_callback(*command, arguments, add_report_options(*command, *arguments));
}

}  // namespace spar::cli
