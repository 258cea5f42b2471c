#pragma once
// A small RGB image and the few shapes the overview picture draws on it: pixels, blended
// pixels, rectangles, and anti-aliased lines and discs.
//
// Pixel coordinates: x right, y down; pixel (i, j) covers [i, i + 1) x [j, j + 1), so its
// centre is (i + 0.5, j + 0.5). Shapes take such continuous coordinates (pixels, doubles).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace groovetrace::picture {

/// An 8-bit sRGB colour.
struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
  bool operator!=(const Rgb& o) const { return !(*this == o); }
};

/// `a` moved towards `b` by `t` in [0, 1] (0 = a, 1 = b), rounded per channel.
Rgb mix(Rgb a, Rgb b, double t);

/// Row-major RGB pixels, 3 bytes each, no padding.
class Raster {
 public:
  Raster() = default;
  Raster(int width, int height, Rgb fill = {});

  int width() const { return width_; }
  int height() const { return height_; }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
  Rgb at(int x, int y) const;
  /// Sets pixel (x, y); a pixel outside the image is ignored, so shapes may cross the edge.
  void set(int x, int y, Rgb c);
  /// Mixes `c` into pixel (x, y) with opacity `alpha` in [0, 1]; outside is ignored.
  void blend(int x, int y, Rgb c, double alpha);
  /// Fills the pixels [x0, x0 + w) x [y0, y0 + h), clipped to the image.
  void fill_rect(int x0, int y0, int w, int h, Rgb c);
  /// Copies `other` with its top-left corner at pixel (x0, y0), clipped to this image.
  void paste(const Raster& other, int x0, int y0);
  /// A segment from a to b (pixel coordinates) of the given width (pixels), anti-aliased:
  /// each pixel is covered by how far its centre lies inside the stroke. A non-finite end
  /// draws nothing.
  void line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double width, Rgb c);
  /// A filled disc (pixel coordinates and radius in pixels), anti-aliased like line().
  void disc(const Eigen::Vector2d& centre, double radius, Rgb c);
  /// The pixels, row-major, RGB: row y starts at 3 * width * y.
  const std::vector<std::uint8_t>& bytes() const { return rgb_; }

 private:
  // Blends `c` over the pixels whose centres lie within `half` (pixels) of the segment a-b.
  void stroke(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double half, Rgb c);

  int width_ = 0, height_ = 0;
  std::vector<std::uint8_t> rgb_;
};

}  // namespace groovetrace::picture
