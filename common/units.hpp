// Units: inside spar every length is in metres and every angle in radians (REP 103). Other units
// appear only at a boundary (a scenario file, a CLI option, a report), which multiplies by one of
// these factors on the way in and divides on the way out. The factors are exact by definition
// (1 in = 0.0254 m since 1959).
//
// Example:
//   const double opening = 4 * units::kInch;                 // 0.1016 m
//   const double tilt = 60 * units::kDegree;                 // radians
//   std::printf("%.3g in\n", opening / units::kInch);        // back to the file's unit
//   const double step = 1.5 * units::kMillimetre;            // 0.0015 m
//   const double half_turn = 180 * units::kDegree;           // pi
#pragma once

#include <numbers>

namespace spar::units {

inline constexpr double kMetre = 1.0;
inline constexpr double kMillimetre = 0.001;  // metres per millimetre
inline constexpr double kInch = 0.0254;       // metres per inch
inline constexpr double kRadian = 1.0;
inline constexpr double kDegree = std::numbers::pi / 180;  // radians per degree
inline constexpr double kPi = std::numbers::pi;            // radians per half turn

}  // namespace spar::units
