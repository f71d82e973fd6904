// A drawing of the work cell in one state (reports/ only): an SVG with the top view (world x to
// the right, y up) above the side view (x to the right, z up, seen along +y), one scale for both.
// The HTML report inlines one per view; the Markdown report links to the same SVGs as files.
//
// Class names (normative: tests and readers find the parts by them):
//   svg.cell-view        the drawing (a viewBox, so it scales to its box)
//   svg.top-view, svg.side-view   the two views, nested (each clips what reaches outside it)
//   rect.table           the table top (top view) and its slab below z = 0 (side view)
//   circle.robot-base    the robot's base; circle.reach: its reach (dashed, an upper bound)
//   g.place              a free place: a cross and its name (top view)
//   path.object          one per object and view, its silhouette (data-object: its name), with
//                        text.label; .held when the gripper holds it
//   path.gripper         the gripper's palm and fingers
//   rect.uncertainty     the box of positions the handled object's origin may occupy (true
//                        scale; its size in the title)
//   g.sensing            inserted sensing: a dashed ring around the object sensed, and the step
//
// Example:
//   out << cell_view_svg(report, 0, false);       // the initial state, for inline HTML
//   file << cell_view_svg(report, 3, true);       // a standalone .svg file (XML declaration)
#pragma once

#include <cstddef>
#include <string>

#include "spar/reports/model.hpp"

namespace spar::reports::internal {

// report.cell must hold `view`.
[[nodiscard]] std::string cell_view_svg(const Report& report, std::size_t view, bool standalone);
// "cell-3.svg": the file name of view `view` beside report.md.
[[nodiscard]] std::string cell_view_file(std::size_t view);

}  // namespace spar::reports::internal
