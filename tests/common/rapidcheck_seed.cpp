// Fixes RapidCheck's seed for every test binary unless RC_PARAMS is already set, so that runs are
// reproducible; RapidCheck prints the seed of a failing run so it can be replayed with RC_PARAMS.
#include <cstdlib>

namespace {
const bool kSeedFixed = [] { return setenv("RC_PARAMS", "seed=20261123", /*overwrite=*/0) == 0; }();
}  // namespace
