// Fixes RapidCheck's seed for kinematics_tests unless RC_PARAMS is already set, so runs are
// reproducible; RapidCheck prints the seed of a failing run so it can be replayed with RC_PARAMS.
#include <cstdlib>

namespace {
const bool kSeedFixed = [] {
  return setenv("RC_PARAMS", "seed=1986 max_success=2000", /*overwrite=*/0) == 0;
}();
}  // namespace
