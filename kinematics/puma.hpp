// The robots built into spar: standard-DH tables of the Unimation Puma 560 and (a community model
// of) the Puma 762 that SPAR ran on. The tables are in code so the CLI works without the corpus;
// tests check them against data/puma560.json, which cites the same sources.
//
// Both use Paul's alpha signs (alpha = +90, 0, -90, +90, -90, 0 degrees; the negative of Lee's), so
// q = 0 is a "righty" configuration, and the same closed-form solver (kinematics/ik.hpp) applies.
//
// Example:
//   const DhChain& puma = spar::kinematics::builtin_robot("puma560");
//   Transform flange = puma.forward({0, 0, 0, 0, 0, 0});   // (0.4521, -0.15005, 1.10363)
#pragma once

#include <string_view>
#include <vector>

#include "spar/kinematics/dh.hpp"

namespace spar::kinematics {

// Puma 560 as in Corke's Robotics Toolbox for Python (Puma560.py): Corke & Armstrong-Helouvry 1994
// kinematics with d3 = 150.05 mm, the 26.45 in (0.67183 m) pedestal as d1, and the Wang & Chen 1991
// joint limits (+-160, +-110, +-135, +-266, +-100, +-266 degrees).
[[nodiscard]] const DhChain& puma560();

// Puma 762, a COMMUNITY model (Don Riley's "3D Puma Robot Demo", MathWorks File Exchange #14932):
// a2 = 650 mm, a3 = 0, d3 = 190 mm, d4 = 600 mm, unknown pedestal (d1 = 0), and the Puma 560
// limits, which are UNVERIFIED for the 762.
[[nodiscard]] const DhChain& puma762();

// "puma560" or "puma762"; throws KinematicsError naming the known robots otherwise.
[[nodiscard]] const DhChain& builtin_robot(std::string_view name);
[[nodiscard]] std::vector<std::string_view> builtin_robot_names();

}  // namespace spar::kinematics
