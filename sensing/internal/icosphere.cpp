#include "spar/sensing/internal/icosphere.hpp"

#include <cmath>

namespace spar::sensing::internal {

std::vector<std::array<Eigen::Vector3d, 3>> icosphere(int level) {
  const double phi = (1 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> v = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0},
                                    {0, -1, phi}, {0, 1, phi}, {0, -1, -phi}, {0, 1, -phi},
                                    {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  for (Eigen::Vector3d& p : v) p.normalize();
  const int faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                            {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                            {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                            {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  std::vector<std::array<Eigen::Vector3d, 3>> triangles;
  for (const auto& f : faces) triangles.push_back({v[f[0]], v[f[1]], v[f[2]]});
  for (int l = 0; l < level; ++l) {
    std::vector<std::array<Eigen::Vector3d, 3>> finer;
    finer.reserve(triangles.size() * 4);
    for (const auto& [a, b, c] : triangles) {
      const Eigen::Vector3d ab = (a + b).normalized(), bc = (b + c).normalized(),
                            ca = (c + a).normalized();
      finer.push_back({a, ab, ca});
      finer.push_back({ab, b, bc});
      finer.push_back({ca, bc, c});
      finer.push_back({ab, bc, ca});
    }
    triangles = std::move(finer);
  }
  return triangles;
}

}  // namespace spar::sensing::internal
