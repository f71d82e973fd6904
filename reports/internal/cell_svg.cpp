#include "spar/reports/internal/cell_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "spar/reports/internal/text.hpp"

namespace spar::reports::internal {
namespace {

constexpr double kWidth = 360;  // drawing width in SVG units
constexpr double kPad = 8;
constexpr double kTitle = 18;  // height of a view's heading line

std::string num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f", v);
  std::string out = buffer;
  if (out.size() > 2 && out.compare(out.size() - 2, 2, ".0") == 0) out.resize(out.size() - 2);
  return out == "-0" ? "0" : out;
}

// Maps the cell's coordinates (length unit) to SVG units for one of the two views.
struct Frame {
  double scale{1}, x0{0}, v1{0}, top{0};  // svg x = (x - x0) s; svg y = top + (v1 - v) s
  [[nodiscard]] double x(double value) const { return (value - x0) * scale; }
  [[nodiscard]] double y(double value) const { return top + (v1 - value) * scale; }
};

std::string path_of(const std::vector<Ring>& rings, const Frame& f) {
  std::string d;
  for (const Ring& ring : rings) {
    for (std::size_t i = 0; i < ring.size(); ++i)
      d += (i == 0 ? "M" : "L") + num(f.x(ring[i][0])) + "," + num(f.y(ring[i][1])) + " ";
    d += "Z ";
  }
  if (!d.empty()) d.pop_back();
  return d;
}

// The area centroid of the largest ring (where a label goes), or its first point.
std::array<double, 2> label_point(const std::vector<Ring>& rings) {
  const Ring* largest = nullptr;
  double best = -1;
  for (const Ring& ring : rings) {
    double area = 0;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const auto& p = ring[i];
      const auto& q = ring[(i + 1) % ring.size()];
      area += p[0] * q[1] - q[0] * p[1];
    }
    if (area > best) best = area, largest = &ring;  // outer rings are counter-clockwise: > 0
  }
  if (largest == nullptr || largest->empty()) return {0, 0};
  double cx = 0, cy = 0;
  for (const auto& p : *largest) cx += p[0], cy += p[1];
  return {cx / double(largest->size()), cy / double(largest->size())};
}

struct Extent {
  double lo{HUGE_VAL}, hi{-HUGE_VAL};
  void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
};

void extend(Extent& a, Extent& b, const std::vector<Ring>& rings) {
  for (const Ring& ring : rings)
    for (const auto& p : ring) a.add(p[0]), b.add(p[1]);
}

const char* kStyle =
    ".table{fill:#efe6d6;stroke:#b8a98c}.reach{fill:none;stroke:#8a94a3;stroke-dasharray:4,3}"
    ".robot-base{fill:#55606e}.object{fill:#9db7db;stroke:#2b4f80;stroke-width:.8;"
    "fill-rule:evenodd}.object.held{fill:#f3c77d;stroke:#8a5a00}.gripper{fill:#6b7480;"
    "fill-opacity:.55;stroke:#3c434d;stroke-width:.6;fill-rule:nonzero}"
    ".uncertainty{fill:#e0523f;fill-opacity:.25;stroke:#b3261e;stroke-width:.8}"
    ".sensing circle{fill:none;stroke:#a05a00;stroke-width:1.2;stroke-dasharray:3,2}"
    ".place line{stroke:#7a6a4f;stroke-width:1}text{font-family:sans-serif;fill:#1d2430}"
    ".label{font-size:9px;text-anchor:middle}.small{font-size:8px;fill:#55606e}"
    ".heading{font-size:11px;font-weight:bold}";

// Where the drawing puts things: one scale for both views (the table, the robot's base, every
// view's outlines), and for each view its frame and where it starts. Each view is a nested <svg>
// (it clips what reaches outside it: the reach's circle) with its own coordinates.
struct Layout {
  double scale{1}, slab{0};  // slab: the table's thickness drawn in the side view
  double top_top{0}, top_height{0}, side_top{0}, side_height{0}, height{0};
  Frame top, side;
};

Layout layout_of(const Cell& cell) {
  Extent x, y, z;
  x.add(cell.table_x[0]), x.add(cell.table_x[1]), y.add(cell.table_y[0]), y.add(cell.table_y[1]);
  x.add(cell.robot_base[0]), y.add(cell.robot_base[1]), z.add(0);
  // The reach's arc where it crosses the line from the base through the table's centre (else a
  // far base and long arm would draw no part of it).
  const double to_x = (cell.table_x[0] + cell.table_x[1]) / 2 - cell.robot_base[0];
  const double to_y = (cell.table_y[0] + cell.table_y[1]) / 2 - cell.robot_base[1];
  if (const double distance = std::hypot(to_x, to_y); distance > 0) {
    x.add(cell.robot_base[0] + cell.reach * to_x / distance);
    y.add(cell.robot_base[1] + cell.reach * to_y / distance);
  }
  for (const CellView& v : cell.views) {
    for (const CellObject& object : v.objects) extend(x, z, object.outline.side);
    if (v.gripper) extend(x, z, v.gripper->side);
  }
  Layout out;
  const double width = x.hi - x.lo;
  out.scale = (kWidth - 2 * kPad) / std::max(width, 1e-9);
  out.slab = 0.04 * width;
  out.top_height = (y.hi - y.lo) * out.scale;
  out.side_height = (z.hi - z.lo + out.slab) * out.scale;
  out.top_top = kTitle + 14;
  out.side_top = out.top_top + out.top_height + 2 * kPad + 16;
  out.top = {out.scale, x.lo - kPad / out.scale, y.hi, kPad};
  out.side = {out.scale, x.lo - kPad / out.scale, z.hi, kPad};
  out.height = out.side_top + out.side_height + 2 * kPad;
  return out;
}

// The view's objects, gripper and uncertainty region in one of the two views.
void write_objects(std::ostringstream& svg, const CellView& view, const Frame& f, bool top,
                   const std::string& unit) {
  for (const CellObject& object : view.objects) {
    const std::vector<Ring>& rings = top ? object.outline.top : object.outline.side;
    if (rings.empty()) continue;
    const auto at = label_point(rings);
    svg << "<path class=\"object" << (object.held ? " held" : "") << "\" data-object=\""
        << html_escape(object.name) << "\" d=\"" << path_of(rings, f) << "\"><title>"
        << html_escape(object.name) << (object.held ? " (held)" : "") << "</title></path>"
        << "<text class=\"label\" x=\"" << num(f.x(at[0])) << "\" y=\"" << num(f.y(at[1]) + 3)
        << "\">" << html_escape(object.name) << "</text>\n";
  }
  if (view.gripper)
    svg << "<path class=\"gripper\" d=\""
        << path_of(top ? view.gripper->top : view.gripper->side, f)
        << "\"><title>the gripper</title></path>\n";
  if (view.region) {
    const UncertaintyRegion& r = *view.region;
    const int v = top ? 1 : 2;
    std::string size;
    for (const int axis : {0, 1, 2})
      size += std::string(axis ? " x " : "") + "±" + rounded((r.hi[axis] - r.lo[axis]) / 2, 2);
    svg << "<rect class=\"uncertainty\" x=\"" << num(f.x(r.lo[0])) << "\" y=\"" << num(f.y(r.hi[v]))
        << "\" width=\"" << num(std::max(0.6, (r.hi[0] - r.lo[0]) * f.scale)) << "\" height=\""
        << num(std::max(0.6, (r.hi[v] - r.lo[v]) * f.scale)) << "\"><title>"
        << html_escape(r.object) << ": the box of positions its origin may occupy, " << size << " "
        << html_escape(unit) << " (x, y, z)</title></rect>\n";
  }
}

// Top view: the table, the reach, the places, the base, the objects, the sensing.
void write_top_view(std::ostringstream& svg, const Cell& cell, const CellView& view,
                    const Layout& layout, const std::string& unit) {
  const Frame& t = layout.top;
  const double scale = layout.scale;
  svg << "<text class=\"small\" x=\"" << num(kPad) << "\" y=\"" << num(layout.top_top - 4)
      << "\">from above (x right, y up)</text>\n<svg class=\"top-view\" x=\"0\" y=\""
      << num(layout.top_top) << "\" width=\"" << num(kWidth) << "\" height=\""
      << num(layout.top_height + 2 * kPad) << "\">\n<rect class=\"table\" x=\""
      << num(t.x(cell.table_x[0])) << "\" y=\"" << num(t.y(cell.table_y[1])) << "\" width=\""
      << num((cell.table_x[1] - cell.table_x[0]) * scale) << "\" height=\""
      << num((cell.table_y[1] - cell.table_y[0]) * scale) << "\"><title>the table top (z = 0)"
      << "</title></rect>\n<circle class=\"reach\" cx=\"" << num(t.x(cell.robot_base[0]))
      << "\" cy=\"" << num(t.y(cell.robot_base[1])) << "\" r=\"" << num(cell.reach * scale)
      << "\"><title>the robot's reach: at most " << rounded(cell.reach) << " " << html_escape(unit)
      << " from the shoulder</title></circle>\n";
  for (const CellPlace& place : cell.places)
    svg << "<g class=\"place\"><title>place " << html_escape(place.name) << " (" << rounded(place.x)
        << ", " << rounded(place.y) << ") " << html_escape(unit) << "</title><line x1=\""
        << num(t.x(place.x) - 3) << "\" y1=\"" << num(t.y(place.y) - 3) << "\" x2=\""
        << num(t.x(place.x) + 3) << "\" y2=\"" << num(t.y(place.y) + 3) << "\"/><line x1=\""
        << num(t.x(place.x) - 3) << "\" y1=\"" << num(t.y(place.y) + 3) << "\" x2=\""
        << num(t.x(place.x) + 3) << "\" y2=\"" << num(t.y(place.y) - 3)
        << "\"/><text class=\"small\" x=\"" << num(t.x(place.x) + 4) << "\" y=\""
        << num(t.y(place.y) + 10) << "\">" << html_escape(place.name) << "</text></g>\n";
  svg << "<circle class=\"robot-base\" cx=\"" << num(t.x(cell.robot_base[0])) << "\" cy=\""
      << num(t.y(cell.robot_base[1])) << "\" r=\"4\"><title>the robot's base</title></circle>"
      << "<text class=\"small\" x=\"" << num(t.x(cell.robot_base[0]) + 6) << "\" y=\""
      << num(t.y(cell.robot_base[1]) - 5) << "\">robot</text>\n";
  write_objects(svg, view, t, true, unit);
  for (const CellSensing& sensing : view.sensed)
    for (const CellObject& object : view.objects)
      if (object.name == sensing.object && !object.outline.top.empty()) {
        const auto at = label_point(object.outline.top);
        svg << "<g class=\"sensing\"><title>" << html_escape(sensing.step)
            << " (inserted sensing)</title><circle cx=\"" << num(t.x(at[0])) << "\" cy=\""
            << num(t.y(at[1])) << "\" r=\"14\"/><text class=\"small\" x=\"" << num(t.x(at[0]))
            << "\" y=\"" << num(t.y(at[1]) - 16) << "\" text-anchor=\"middle\">"
            << html_escape(sensing.step) << "</text></g>\n";
      }
  svg << "</svg>\n";
}

// Side view: the table's slab, the base and the reach about the shoulder, the objects.
void write_side_view(std::ostringstream& svg, const Cell& cell, const CellView& view,
                     const Layout& layout, const std::string& unit) {
  const Frame& s = layout.side;
  const double scale = layout.scale;
  svg << "<text class=\"small\" x=\"" << num(kPad) << "\" y=\"" << num(layout.side_top - 4)
      << "\">from the front (x right, z up)</text>\n<svg class=\"side-view\" x=\"0\" y=\""
      << num(layout.side_top) << "\" width=\"" << num(kWidth) << "\" height=\""
      << num(layout.side_height + 2 * kPad) << "\">\n<rect class=\"table\" x=\""
      << num(s.x(cell.table_x[0])) << "\" y=\"" << num(s.y(0)) << "\" width=\""
      << num((cell.table_x[1] - cell.table_x[0]) * scale) << "\" height=\""
      << num(layout.slab * scale)
      << "\"><title>the table (its top is z = 0)</title></rect>\n<circle class=\"reach\" cx=\""
      << num(s.x(cell.robot_base[0])) << "\" cy=\"" << num(s.y(cell.robot_base[2] + cell.shoulder))
      << "\" r=\"" << num(cell.reach * scale) << "\"/><circle class=\"robot-base\" cx=\""
      << num(s.x(cell.robot_base[0])) << "\" cy=\"" << num(s.y(cell.robot_base[2]))
      << "\" r=\"4\"><title>the robot's base</title></circle>\n";
  write_objects(svg, view, s, false, unit);
  svg << "</svg>\n";
}

}  // namespace

std::string cell_view_file(std::size_t view) { return "cell-" + std::to_string(view) + ".svg"; }

std::string cell_view_svg(const Report& report, std::size_t index, bool standalone) {
  const Cell& cell = report.cell.value();
  const CellView& view = cell.views.at(index);
  const std::string& unit = report.units.length;
  const Layout layout = layout_of(cell);
  std::ostringstream svg;
  if (standalone) svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"cell-view\" viewBox=\"0 0 "
      << num(kWidth) << " " << num(layout.height) << "\" width=\"" << num(kWidth) << "\" height=\""
      << num(layout.height) << "\" role=\"img\" aria-label=\"the work cell, "
      << html_escape(view.title) << "\">\n<style>" << kStyle
      << "</style>\n<text class=\"heading\" x=\"" << num(kPad) << "\" y=\"13\">"
      << html_escape(view.title) << "</text>\n";
  write_top_view(svg, cell, view, layout, unit);
  write_side_view(svg, cell, view, layout, unit);
  svg << "</svg>";
  if (standalone) svg << '\n';
  return svg.str();
}

}  // namespace spar::reports::internal
