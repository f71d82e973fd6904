#include "spar/reports/json_values.hpp"

#include <cmath>

namespace spar::reports {

nlohmann::ordered_json number_json(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

nlohmann::ordered_json matrix_json(const Eigen::Isometry3d& pose, double length_scale) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  const Eigen::Matrix4d matrix = pose.matrix();
  for (int row = 0; row < 4; ++row) {
    nlohmann::ordered_json values = nlohmann::ordered_json::array();
    for (int column = 0; column < 4; ++column)
      values.push_back(number_json(column == 3 && row < 3 ? matrix(row, column) * length_scale
                                                          : matrix(row, column)));
    rows.push_back(std::move(values));
  }
  return rows;
}

}  // namespace spar::reports
