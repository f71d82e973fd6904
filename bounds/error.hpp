// bounds::BoundsError: a caller's mistake in a bounding request (a bad box or range, an unknown
// variable, a malformed constraint or inequality); the message says which. Derives from
// spar::Error (common/error.hpp), like every module's error; shostak.hpp's ShostakError derives
// from it.
//
// Example:
//   try {
//     const BoundResult r = bound(f, box);
//   } catch (const BoundsError& error) {
//     std::cerr << error.what() << '\n';   // "unknown variable 'z' in the expression: give it a
//     range"
//   }
#pragma once

#include "spar/common/error.hpp"

namespace spar::bounds {

class BoundsError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::bounds
