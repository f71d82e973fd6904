// Fixes RapidCheck's parameters for a test binary unless RC_PARAMS is already set, so that runs
// are reproducible; RapidCheck prints the parameters of a failing run so it can be replayed with
// RC_PARAMS. SPAR_RAPIDCHECK_PARAMS comes from spar_add_test (tests/CMakeLists.txt).
//
// SPAR_PROPERTY_DIVISOR=N (set by scripts/hunt.sh for its sanitizer stage) divides every
// property's case count (RapidCheck's default 100 when the binary names none) by N, keeping at
// least one case: that stage looks for memory and undefined-behaviour errors on the paths the
// Release stage has just run at the full count, at a quarter of the speed.
#include <algorithm>
#include <cstdlib>
#include <string>

namespace {
std::string parameters() {
  std::string params = SPAR_RAPIDCHECK_PARAMS;
  const char* divisor_text = std::getenv("SPAR_PROPERTY_DIVISOR");
  const long divisor = divisor_text == nullptr ? 1 : std::strtol(divisor_text, nullptr, 10);
  if (divisor <= 1) return params;
  const std::string key = "max_success=";
  long cases = 100;  // RapidCheck's default
  if (const auto at = params.find(key); at != std::string::npos) {
    const auto end = params.find(' ', at);
    cases = std::stol(params.substr(at + key.size(), end - (at + key.size())));
    params.erase(at, end == std::string::npos ? std::string::npos : end - at + 1);
  }
  return params + " " + key + std::to_string(std::max(1L, cases / divisor));
}

const bool kParametersFixed = [] {
  return setenv("RC_PARAMS", parameters().c_str(), /*overwrite=*/0) == 0;
}();
}  // namespace
