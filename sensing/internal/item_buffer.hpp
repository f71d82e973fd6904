// A depth-buffered item buffer: at each sample (pixel centre) the item of the nearest triangle
// drawn there. render.cpp draws a scene's front-facing triangles into it (their global index as
// the item); aspects.cpp draws one object per view direction.
//
// Depth: a key that is smaller for nearer points and affine in screen coordinates over each
// triangle: the camera depth z for an orthographic camera, -1/z for a pinhole (1/z, not z, is
// affine in the image). A sample takes the triangle whose key there is strictly smaller than what
// it holds, so of two equal depths the first drawn stays.
// Coverage: a sample belongs to a triangle when it is inside or on its boundary (edge functions
// >= 0 after orienting the triangle counter-clockwise in the image); degenerate (zero-area)
// triangles draw nothing.
//
// Window: the buffer may hold only a window of the image (x0 <= x < x0 + width, likewise y); a
// sample outside it is never drawn, and samples keep their image coordinates, so a window that
// holds every triangle's samples gives exactly what the whole image would (render.cpp draws a
// scene into the window its triangles cover).
//
// Example:
//   ItemBuffer buffer(64, 64);
//   buffer.draw({{0, 0}, {64, 0}, {0, 64}}, {1, 1, 1}, 7);
//   buffer.item(1, 1);     // 7
//   buffer.item(63, 63);   // -1: not covered
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

namespace spar::sensing::internal {

// Samples x0 <= x < x0 + width, y0 <= y < y0 + height of an image.
struct PixelWindow {
  int x0{0}, y0{0}, width{0}, height{0};
};

class ItemBuffer {
 public:
  ItemBuffer(int width, int height) : ItemBuffer(PixelWindow{0, 0, width, height}) {}
  explicit ItemBuffer(const PixelWindow& window);
  void clear();  // every sample back to no item, infinite depth
  void draw(const std::array<Eigen::Vector2d, 3>& corners, const std::array<double, 3>& depth,
            int item);
  [[nodiscard]] const PixelWindow& window() const { return window_; }
  [[nodiscard]] int width() const { return window_.width; }
  [[nodiscard]] int height() const { return window_.height; }
  // Image coordinates, inside the window.
  [[nodiscard]] int item(int x, int y) const { return items_[index(x, y)]; }
  [[nodiscard]] double depth(int x, int y) const { return depth_[index(x, y)]; }
  [[nodiscard]] const std::vector<int>& items() const { return items_; }  // row-major, -1 none

 private:
  [[nodiscard]] std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y - window_.y0) * static_cast<std::size_t>(window_.width) +
           static_cast<std::size_t>(x - window_.x0);
  }
  PixelWindow window_;
  std::vector<int> items_;
  std::vector<double> depth_;
};

}  // namespace spar::sensing::internal
