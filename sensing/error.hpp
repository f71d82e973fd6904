// sensing::SensingError: a bad input to the sensing layer (an evidence file, a frame with a
// repeated name, masses that do not sum to 1, a camera with no pixels) or evidence that cannot be
// combined (total conflict). Derives from spar::Error (common/error.hpp), like every module's
// error.
//
// Example:
//   try {
//     const Combination both = combine(certain_a, certain_b);
//   } catch (const SensingError& error) {
//     std::cerr << error.what() << '\n';   // "Dempster's rule: total conflict (K = 1) ..."
//   }
#pragma once

#include "spar/common/error.hpp"

namespace spar::sensing {

class SensingError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::sensing
