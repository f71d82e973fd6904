#include "spar/reports/vision_svg.hpp"

#include <algorithm>
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
  const auto line = [&](double left, const Segment& s, const std::string& stroke, double w) {
    svg << "<line x1=\"" << internal::fixed(left + scale * s.p0.x(), 2) << "\" y1=\""
        << internal::fixed(kMargin + scale * s.p0.y(), 2) << "\" x2=\""
        << internal::fixed(left + scale * s.p1.x(), 2) << "\" y2=\""
        << internal::fixed(kMargin + scale * s.p1.y(), 2) << "\" stroke=\"" << stroke
        << "\" stroke-width=\"" << w << "\"/>\n";
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
    for (const Segment& piece : edge.pieces) line(kMargin, piece, "black", 1);
    text(kMargin, edge.span.midpoint(), edge.id, "black");
  }
  // (b) the image panel: every active element, coloured by its label, with "label:NN%".
  const auto& matched = *result.expected;
  for (const ImageEdge& edge : result.board.edges) {
    if (!edge.active) continue;
    line(right, edge.segment, colour(edge.label), edge.label < 0 ? 1 : 1.5);
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

}  // namespace spar::reports
