// Fuzz target: the scenario loader (planner/scenario.hpp, yaml-cpp behind planner/internal/).
// Property: any text is either refused with spar::Error (ScenarioError: file:line:col and what is
// wrong) or gives a scenario; no crash, no other exception (yaml-cpp's included), no sanitizer
// report. Mesh paths resolve in a folder that does not exist, so a `mesh:` entry is always a clear
// error; built-in objects get their stable poses computed as in a real load.
#include <cstdint>
#include <string_view>

#include "spar/common/error.hpp"
#include "spar/planner/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)spar::planner::parse_scenario(text, "fuzz.yaml", "/nonexistent/spar-fuzz");
  } catch (const spar::Error&) {
    return 0;  // a clear refusal is a correct answer
  }
  return 0;
}
