// Fuzz target: the scenario loader (planner/scenario.hpp, yaml-cpp behind planner/internal/), then
// the planner on whatever loads, with a small budget (issue 22).
// Property: any text is either refused with spar::Error (ScenarioError: file:line:col and what is
// wrong) or gives a scenario whose numbers lie inside the table of limits; planning that scenario
// either gives a result or a spar::Error (PlanError, a time limit); no crash, no other exception
// (yaml-cpp's included), no sanitizer report, no hang. Mesh paths resolve in a folder that does
// not exist, so a `mesh:` entry is always a clear error; built-in objects get their stable poses
// computed as in a real load.
#include <chrono>
#include <cstdint>
#include <string_view>

#include "spar/common/deadline.hpp"
#include "spar/common/error.hpp"
#include "spar/planner/plan.hpp"
#include "spar/planner/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // One input may take at most this long (libFuzzer's -timeout is 10 s): a scenario that loads
  // but plans slowly is stopped by the cooperative time limit, not reported as a hang.
  const spar::ScopedDeadline limit(std::chrono::seconds(2));
  try {
    spar::planner::Scenario scenario =
        spar::planner::parse_scenario(text, "fuzz.yaml", "/nonexistent/spar-fuzz");
    spar::planner::PlanOptions options;
    options.max_instances = 2;
    options.posting.max_nodes = 300;
    options.posting.max_steps = 8;
    options.probability.reset();
    options.analysis.reverse = false;
    options.analysis.blame = false;
    options.analysis.samples = 0;
    (void)spar::planner::plan(std::move(scenario), spar::planner::builtin_domain(), options);
  } catch (const spar::Error&) {
    return 0;  // a clear refusal (or a time limit) is a correct answer
  }
  return 0;
}
