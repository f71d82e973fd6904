// JSON values every spar writer shares (the report JSON, `spar fk/ik --json`): numbers (JSON has
// no inf or NaN: they are written as the strings "inf", "-inf" and "nan", so a reader never meets
// an invalid document) and 4x4 poses (row-major, lengths scaled to the output's unit).
//
// Example:
//   nlohmann::ordered_json out;
//   out["hi"] = number_json(std::numeric_limits<double>::infinity());   // "inf"
//   out["pose"] = matrix_json(pose, 1 / 0.0254);                         // translation in inches
#pragma once

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace spar::reports {

[[nodiscard]] nlohmann::ordered_json number_json(double value);
// Rows of the 4x4 homogeneous matrix; the translation column multiplied by `length_scale`.
[[nodiscard]] nlohmann::ordered_json matrix_json(const Eigen::Isometry3d& pose,
                                                 double length_scale = 1.0);

}  // namespace spar::reports
