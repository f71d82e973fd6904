// spar::Error: the one base of every error that reports a user's or a file's mistake.
//
// Each module derives its own type in its own `error.hpp` (symbolic::SymbolicError,
// bounds::BoundsError, geometry::GeometryError, planner::ScenarioError, ...), so a caller can catch
// one module's mistakes or all of spar's. The message is complete and meant for a person: what is
// wrong and where (`file:line:col: ...` for files, the offending token for expressions). The CLI
// prints it as one line; Python raises it with the same text.
//
// Example:
//   try {
//     run();
//   } catch (const spar::Error& error) {
//     std::cerr << "spar: error: " << error.what() << '\n';
//   }
#pragma once

#include <stdexcept>

namespace spar {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  ~Error() override;
};

}  // namespace spar
