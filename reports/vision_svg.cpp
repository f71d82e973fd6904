#include "spar/reports/vision_svg.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "spar/reports/internal/text.hpp"

namespace spar::reports {
namespace {

using sensing::pseiki::ImageEdge;
using sensing::pseiki::PanelEdge;
using sensing::pseiki::Segment;

constexpr double kPanelWidth = 480;
constexpr double kMargin = 20;

// A colour per label (the same model edge in both panels), grey for none.
std::string colour(int label) {
  if (label < 0) return "#999999";
  static const char* const kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                         "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};
  return kPalette[label % 8];
}

void line(std::ostringstream& svg, double x1, double y1, double x2, double y2,
          const std::string& stroke, double width) {
  svg << "<line x1=\"" << internal::fixed(x1, 2) << "\" y1=\"" << internal::fixed(y1, 2)
      << "\" x2=\"" << internal::fixed(x2, 2) << "\" y2=\"" << internal::fixed(y2, 2)
      << "\" stroke=\"" << stroke << "\" stroke-width=\"" << width << "\"/>";
}

}  // namespace

std::string vision_svg(const sensing::pseiki::ModelPanel& expected,
                       const sensing::pseiki::Verification& result,
                       const sensing::pseiki::ImageFile& image) {
  const sensing::Intrinsics& k = expected.camera().intrinsics();
  const double scale = std::min(1.0, kPanelWidth / k.width);
  const double width = k.width * scale, height = k.height * scale;
  const double right = 2 * kMargin + width;
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << 3 * kMargin + 2 * width
      << "\" height=\"" << height + 3 * kMargin + 30
      << "\" font-family=\"sans-serif\" font-size=\"9\">\n";
  for (const double left : {kMargin, right})
    svg << "<rect x=\"" << left << "\" y=\"" << kMargin << "\" width=\"" << width << "\" height=\""
        << height << "\" fill=\"white\" stroke=\"black\"/>\n";
  const auto segment = [&](double left, const Segment& s, const std::string& stroke, double w) {
    line(svg, left + scale * s.p0.x(), kMargin + scale * s.p0.y(), left + scale * s.p1.x(),
         kMargin + scale * s.p1.y(), stroke, w);
    svg << '\n';
  };
  const auto text = [&](double left, const Eigen::Vector2d& at, const std::string& words,
                        const std::string& fill) {
    svg << "<text x=\"" << internal::fixed(left + scale * at.x() + 2, 2) << "\" y=\""
        << internal::fixed(kMargin + scale * at.y() - 2, 2) << "\" fill=\"" << fill << "\">"
        << internal::html_escape(words) << "</text>\n";
  };
  // (a) the expected scene: the believed poses' edges, labelled.
  for (std::size_t e = 0; e < expected.edges().size(); ++e) {
    const PanelEdge& edge = expected.edges()[e];
    for (const Segment& piece : edge.pieces) segment(kMargin, piece, "black", 1);
    text(kMargin, edge.span.midpoint(), edge.id, "black");
  }
  // (b) the image panel: every active element, coloured by its label, with "label:NN%".
  const auto& matched = *result.expected;
  for (const ImageEdge& edge : result.board.edges) {
    if (!edge.active) continue;
    segment(right, edge.segment, colour(edge.label), edge.label < 0 ? 1 : 1.5);
    if (edge.label >= 0)
      text(right, edge.segment.midpoint(),
           matched.edges()[static_cast<std::size_t>(edge.label)].id + ":" +
               internal::fixed(100 * edge.belief, 0) + "%",
           colour(edge.label));
  }
  svg << "<text x=\"" << kMargin << "\" y=\"" << kMargin - 6
      << "\" font-size=\"11\">(a) expected scene</text>\n<text x=\"" << right << "\" y=\""
      << kMargin - 6 << "\" font-size=\"11\">(b) " << image.edges.size()
      << " image edges, labels and beliefs</text>\n<text x=\"" << kMargin << "\" y=\""
      << height + 2 * kMargin + 10 << "\" font-size=\"11\">scene belief "
      << internal::fixed(result.board.scene.belief, 2) << ": "
      << (result.accepted ? "accepted" : "rejected") << " after " << result.passes
      << (result.passes == 1 ? " pass" : " passes") << "</text>\n</svg>\n";
  return svg.str();
}

std::string expected_scene_svg(const VisionCheck& check) {
  constexpr double kEdge = 8, kLegend = 40;
  constexpr const char* kObject = "#b3261e";
  constexpr const char* kOther = "#8a94a3";
  const VisionView& view = *check.view;
  const double scale = kPanelWidth / std::max(1, view.width);
  const double width = 2 * kEdge + scale * view.width;
  const double height = 2 * kEdge + scale * view.height + kLegend;
  std::size_t others = 0;
  for (const VisionViewEdge& edge : view.edges) others += edge.object != check.object;
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"vision-view\" viewBox=\"0 0 "
      << internal::fixed(width, 2) << " " << internal::fixed(height, 2) << "\" width=\""
      << internal::fixed(width, 2) << "\" height=\"" << internal::fixed(height, 2)
      << "\" style=\"max-width:100%;height:auto\" font-size=\"11\" role=\"img\"><title>"
      << internal::html_escape("the expected scene: camera " + check.camera + ", " +
                               std::to_string(view.width) + " x " + std::to_string(view.height) +
                               " px")
      << "</title>\n<rect class=\"image\" x=\"" << kEdge << "\" y=\"" << kEdge << "\" width=\""
      << internal::fixed(scale * view.width, 2) << "\" height=\""
      << internal::fixed(scale * view.height, 2) << "\" fill=\"#fbfcfd\" stroke=\"#55606e\"/>\n";
  // The other bodies first, so that the object's edges are drawn over them.
  for (const bool object : {false, true})
    for (const VisionViewEdge& edge : view.edges) {
      if ((edge.object == check.object) != object) continue;
      svg << "<g class=\"edge" << (object ? " object" : "") << "\" data-edge=\""
          << internal::html_escape(edge.id) << "\"><title>" << internal::html_escape(edge.id)
          << "</title>";
      for (const std::array<double, 4>& piece : edge.pieces)
        line(svg, kEdge + scale * piece[0], kEdge + scale * piece[1], kEdge + scale * piece[2],
             kEdge + scale * piece[3], object ? kObject : kOther, object ? 2 : 1);
      svg << "</g>\n";
    }
  const double legend = 2 * kEdge + scale * view.height + 6;
  const auto key = [&](double y, const char* stroke, double w, const std::string& words) {
    line(svg, kEdge, y, kEdge + 24, y, stroke, w);
    svg << "<text x=\"" << kEdge + 30 << "\" y=\"" << internal::fixed(y + 4, 2) << "\">"
        << internal::html_escape(words) << "</text>\n";
  };
  key(legend + 6, kObject, 2,
      check.object + ": the " + std::to_string(check.edges.size()) + " edges PSEIKI must see");
  key(legend + 24, kOther, 1,
      others ? "the other objects and the gripper (" + std::to_string(others) + " edges)"
             : "nothing else in view");
  svg << "</svg>";
  return svg.str();
}

}  // namespace spar::reports
