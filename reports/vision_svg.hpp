// The SVG drawing of a PSEIKI verification, like the survey's Fig. 11 (seed 003, section 4): on
// the left the expected scene at the believed poses (the model panel, each edge with its id), on
// the right the image's edges, each labelled "label:NN%" with the belief of its label (edges
// without a label grey, merged and split ones as the image panel holds them), and under both the
// scene's belief and whether it was accepted. Coordinates are the camera's pixels, scaled so
// each panel is at most 480 pixels wide.
//
// Example:
//   const Verification result = verify(scene, camera, uncertainty, image.edges, options);
//   std::ofstream("match.svg") << vision_svg(ModelPanel(scene, camera, uncertainty), result,
//   image);
//
// expected_scene_svg draws a report's verification view (reports/model.hpp's VisionCheck.view):
// the expected scene alone, as the camera renders it at the step (y down, like the image), the
// verified object's edges emphasised, the other bodies' (objects, gripper) thin and grey, each
// edge a g.edge with its id as a <title> tooltip, and a legend under it. A viewBox sized to the
// image scaled to 480 px wide, so that it shrinks to a phone's width. Inline HTML (no XML
// declaration).
#pragma once

#include <string>

#include "spar/reports/model.hpp"
#include "spar/sensing/pseiki/matcher.hpp"
#include "spar/sensing/pseiki/vision_json.hpp"

namespace spar::reports {

[[nodiscard]] std::string vision_svg(const sensing::pseiki::ModelPanel& expected,
                                     const sensing::pseiki::Verification& result,
                                     const sensing::pseiki::ImageFile& image);

// `check.view` must be set.
[[nodiscard]] std::string expected_scene_svg(const VisionCheck& check);

}  // namespace spar::reports
