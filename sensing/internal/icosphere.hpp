// The icosphere: the icosahedron's 20 triangles, each split into four `level` times, on the unit
// sphere (20 · 4^level spherical triangles of nearly equal area). The view sphere of aspects.cpp
// and the wrist viewpoints of selection.cpp are its cells.
//
// Example:
//   for (const auto& [a, b, c] : icosphere(2)) directions.push_back((a + b + c).normalized());
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace spar::sensing::internal {

[[nodiscard]] std::vector<std::array<Eigen::Vector3d, 3>> icosphere(int level);

}  // namespace spar::sensing::internal
