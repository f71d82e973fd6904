// yaml-cpp's parse errors as a person reads them (scenario and domain files): its own text,
// except for nesting beyond its recursion limit, which yaml-cpp calls "bad file".
#pragma once

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/exceptions.h>

#include <string>

namespace spar::planner::internal {

[[nodiscard]] inline std::string yaml_syntax_error(const YAML::Exception& error) {
  if (dynamic_cast<const YAML::DeepRecursion*>(&error) != nullptr)
    return "nested too deeply (a scenario or domain file needs a handful of levels)";
  return error.msg;
}

}  // namespace spar::planner::internal
