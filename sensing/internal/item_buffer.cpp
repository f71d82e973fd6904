#include "spar/sensing/internal/item_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace spar::sensing::internal {

ItemBuffer::ItemBuffer(const PixelWindow& window)
    : window_(window),
      items_(static_cast<std::size_t>(window.width) * static_cast<std::size_t>(window.height), -1),
      depth_(items_.size(), std::numeric_limits<double>::infinity()) {}

void ItemBuffer::clear() {
  std::fill(items_.begin(), items_.end(), -1);
  std::fill(depth_.begin(), depth_.end(), std::numeric_limits<double>::infinity());
}

void ItemBuffer::draw(const std::array<Eigen::Vector2d, 3>& corners,
                      const std::array<double, 3>& depth, int item) {
  Eigen::Vector2d a = corners[0], b = corners[1], c = corners[2];
  double da = depth[0], db = depth[1], dc = depth[2];
  double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  if (!(std::abs(area) > 0) || !std::isfinite(area)) return;
  if (area < 0) {  // orient counter-clockwise in the image
    std::swap(b, c);
    std::swap(db, dc);
    area = -area;
  }
  // Samples at centres (x + 0.5, y + 0.5) inside the triangle's box, clamped to the image.
  const PixelWindow& w = window_;
  const int x0 = std::max(w.x0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}) - 0.5)));
  const int x1 = std::min(w.x0 + w.width - 1,
                          static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}) - 0.5)));
  const int y0 = std::max(w.y0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}) - 0.5)));
  const int y1 = std::min(w.y0 + w.height - 1,
                          static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}) - 0.5)));
  if (x0 > x1 || y0 > y1) return;
  // Edge function of p against the directed side p -> q: > 0 on the triangle's side.
  const auto edge = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double x, double y) {
    return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
  };
  const double inverse_area = 1.0 / area;
  for (int y = y0; y <= y1; ++y) {
    const double sy = y + 0.5;
    const double sx0 = x0 + 0.5;
    // Edge functions at the row's first sample and their step per sample in x.
    double wa = edge(b, c, sx0, sy), wb = edge(c, a, sx0, sy), wc = edge(a, b, sx0, sy);
    const double step_a = -(c.y() - b.y()), step_b = -(a.y() - c.y()), step_c = -(b.y() - a.y());
    for (int x = x0; x <= x1; ++x, wa += step_a, wb += step_b, wc += step_c) {
      if (wa < 0 || wb < 0 || wc < 0) continue;
      const double key = (wa * da + wb * db + wc * dc) * inverse_area;
      const std::size_t i = index(x, y);
      if (key < depth_[i]) {
        depth_[i] = key;
        items_[i] = item;
      }
    }
  }
}

}  // namespace spar::sensing::internal
