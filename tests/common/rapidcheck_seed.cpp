// Fixes RapidCheck's parameters for a test binary unless RC_PARAMS is already set, so that runs
// are reproducible; RapidCheck prints the parameters of a failing run so it can be replayed with
// RC_PARAMS. SPAR_RAPIDCHECK_PARAMS comes from spar_add_test (tests/CMakeLists.txt).
#include <cstdlib>

namespace {
const bool kParametersFixed = [] {
  return setenv("RC_PARAMS", SPAR_RAPIDCHECK_PARAMS, /*overwrite=*/0) == 0;
}();
}  // namespace
