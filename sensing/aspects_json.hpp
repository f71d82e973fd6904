// The JSON of `spar aspects --json` (normative: "aspects", "label", "faces", "solid_angle",
// "direction"; Python's spar.aspects returns the same):
//   {"object", "units", "method", "max_angle" (degrees), ["view_sphere": {"level", "cells",
//    "resolution"}], "aspects": [{"label", "faces" (ids as `spar object` numbers them),
//    "solid_angle" (sr), "direction" (unit, object frame, toward the viewer), "features":
//    {"faces": [{"face", "visible_area" (units²), "prominence"}], "edges": [{"edge", "faces",
//    "visible_length" (units), "contrast", "prominence"}]}}]}
// Lengths and areas are divided by `metres_per_unit` (the --units of the command).
//
// Example:
//   const ObjectModel cube = make_builtin_object("cube");
//   const AspectOptions options;
//   std::cout << aspects_json(cube, compute_aspects(cube, options), options, "in", 0.0254).dump(2);
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "spar/sensing/aspects.hpp"

namespace spar::sensing {

[[nodiscard]] nlohmann::ordered_json aspects_json(const geometry::ObjectModel& model,
                                                  const AspectSet& aspects,
                                                  const AspectOptions& options,
                                                  const std::string& units, double metres_per_unit);

}  // namespace spar::sensing
