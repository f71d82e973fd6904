// kinematics::KinematicsError: a user's or a file's mistake in the kinematics module (bad joint
// count, non-rigid pose, unknown robot, a chain the closed-form solver cannot handle, a bad pickup
// geometry). Derives from spar::Error (common/error.hpp), like every module's error.
//
// Example:
//   try {
//     const DhChain& robot = builtin_robot("puma999");
//   } catch (const KinematicsError& error) {
//     std::cerr << error.what() << '\n';   // names the known robots
//   }
#pragma once

#include "spar/common/error.hpp"

namespace spar::kinematics {

class KinematicsError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::kinematics
