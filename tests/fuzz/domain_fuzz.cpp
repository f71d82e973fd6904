// Fuzz target: the domain loader (planner/domain.hpp, planner/internal/domain_yaml.cpp), issue 22.
// Property: any text is either refused with spar::Error (DomainError: file:line:col and what is
// wrong) or gives a domain whose templates meet the header's invariants; no crash, no other
// exception (yaml-cpp's TypedBadConversion included), no sanitizer report.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "spar/common/error.hpp"
#include "spar/planner/domain.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const spar::planner::Domain domain = spar::planner::parse_domain(text, "fuzz.yaml");
    // What the loader guarantees: every typed parameter names an object parameter, and every
    // verification an action names exists.
    for (const spar::planner::ActionTemplate& action : domain.actions) {
      for (const spar::planner::Parameter& parameter : action.parameters)
        if (parameter.type != spar::planner::ParameterType::kObject &&
            action.parameter_index(parameter.of) < 0)
          std::abort();
      for (const std::string& verification : action.verification)
        (void)domain.verification(verification);  // throws (a finding) if it does not exist
    }
  } catch (const spar::Error&) {
    return 0;  // a clear refusal is a correct answer
  }
  return 0;
}
