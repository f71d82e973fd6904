// The reports of the seed's four peg-and-block experiments (examples/peg_block_*.yaml), planned
// once per test binary (each test process: ctest runs every test on its own) with the default
// options (phase 2 with blame, reverse analysis and Monte
// Carlo, as `spar plan` runs it), plus a run whose search budget is too small to find a plan and
// the on-back task with a camera (examples/peg_block_on_back_camera.yaml).
#pragma once

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "spar/planner/plan.hpp"
#include "spar/reports/json.hpp"
#include "spar/reports/plan_json.hpp"

namespace spar::reports::testing {

inline const std::vector<std::string>& example_names() {
  static const std::vector<std::string> names = {"peg_block_face_down", "peg_block_on_sides",
                                                 "peg_block_face_up", "peg_block_on_back"};
  return names;
}

inline std::string example_path(const std::string& name) {
  return std::string(SPAR_SOURCE_DIR) + "/examples/" + name + ".yaml";
}

inline const nlohmann::ordered_json& example_report(const std::string& name) {
  static std::map<std::string, nlohmann::ordered_json> cache;
  auto found = cache.find(name);
  if (found == cache.end())
    found = cache
                .emplace(name, plan_json(planner::plan(planner::load_scenario(example_path(name)),
                                                       planner::builtin_domain())))
                .first;
  return found->second;
}

// The golden report of an example (tests/reports/golden/<name>.json, which GoldenReport checks
// against the planner), read once per test binary: renderer tests use it and plan nothing.
inline const nlohmann::ordered_json& golden_json(const std::string& name) {
  static std::map<std::string, nlohmann::ordered_json> cache;
  auto found = cache.find(name);
  if (found == cache.end()) {
    std::ifstream in(std::string(SPAR_SOURCE_DIR) + "/tests/reports/golden/" + name + ".json");
    found = cache.emplace(name, nlohmann::ordered_json::parse(in)).first;
  }
  return found->second;
}
inline const Report& golden_report(const std::string& name) {
  static std::map<std::string, Report> cache;
  auto found = cache.find(name);
  if (found == cache.end()) found = cache.emplace(name, report_from_json(golden_json(name))).first;
  return found->second;
}

// The face-down task with a search budget of 3 partial plans: status no_plan, with a reason.
inline const nlohmann::ordered_json& no_plan_report() {
  static const nlohmann::ordered_json report = [] {
    planner::PlanOptions options;
    options.posting.max_nodes = 3;
    return plan_json(planner::plan(planner::load_scenario(example_path("peg_block_face_down")),
                                   planner::builtin_domain(), options));
  }();
  return report;
}

// examples/sensing_block_pose.yaml: the block on its left or right face, sensed first; its report
// has sensing steps, the sense plan and one branch per outcome.
inline const nlohmann::ordered_json& sensing_report() {
  static const nlohmann::ordered_json report = plan_json(planner::plan(
      planner::load_scenario(example_path("sensing_block_pose")), planner::builtin_domain()));
  return report;
}

// The on-back task (its assembly is an error left to verify at execution) with a camera looking
// at the block, where the peg is inserted (18, -4, 6) in: the verification names what PSEIKI must
// see to accept (issue 27). The camera is the example's (examples/peg_block_on_back_camera.yaml).
inline const nlohmann::ordered_json& camera_report() {
  return example_report("peg_block_on_back_camera");
}

}  // namespace spar::reports::testing
