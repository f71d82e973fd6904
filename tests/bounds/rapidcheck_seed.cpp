// Fixes RapidCheck's seed for bounds_tests unless RC_PARAMS is already set, so runs are
// reproducible; RapidCheck prints the seed of a failing run so it can be replayed with RC_PARAMS.
#include <cstdlib>

namespace {
const bool kSeedFixed = [] {
  return setenv("RC_PARAMS", "seed=20261123 max_success=300", /*overwrite=*/0) == 0;
}();
}  // namespace
