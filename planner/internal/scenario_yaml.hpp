// The YAML reader behind load_scenario / parse_scenario (planner/scenario.hpp; the schema is
// docs/scenario.md). yaml-cpp is used here and nowhere else in spar.
//
// The reader walks the document once, converting every length and angle from the file's units
// (`units:`, read first) to metres and radians, and throws ScenarioError with
// `source:line:col: <key path>: what is wrong` at the first mistake. It keeps no state between
// calls and touches no global state (so it can be fuzzed); it reads only the mesh files the
// document names, relative to `base_dir`.
//
// Example:
//   const Scenario scenario = internal::read_scenario_yaml(
//       "objects: {cube: {builtin: cube, pose: {stable: P1, at: [0.5, 0]}}}", "inline.yaml", ".");
//   scenario.objects[0].initial_pose.translation().x();  // 0.5 (metres: no `units:` given)
//   scenario.name;                                       // "inline", the source's stem
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "spar/planner/scenario.hpp"

namespace spar::planner::internal {

[[nodiscard]] Scenario read_scenario_yaml(std::string_view text, const std::string& source,
                                          const std::filesystem::path& base_dir);

}  // namespace spar::planner::internal
