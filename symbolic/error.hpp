// symbolic::SymbolicError: a user's mistake in building, parsing or evaluating an expression. The
// message names the problem (and, for parse errors, the offending token and its column). Derives
// from spar::Error (common/error.hpp), like every module's error.
//
// Example:
//   try {
//     const Expr f = parse(pool, "sin(x");
//   } catch (const SymbolicError& error) {
//     std::cerr << error.what() << '\n';   // "expected ')' at column 6 ..."
//   }
#pragma once

#include "spar/common/error.hpp"

namespace spar::symbolic {

class SymbolicError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::symbolic
