#include "picture/raster.hpp"

#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>

#include "core/segment.hpp"

namespace groovetrace::picture {
namespace {

std::uint8_t channel(double a, double b, double t) {
  return static_cast<std::uint8_t>(std::lround(std::clamp(a + (b - a) * t, 0.0, 255.0)));
}

}  // namespace

Rgb mix(Rgb a, Rgb b, double t) {
  return {channel(a.r, b.r, t), channel(a.g, b.g, t), channel(a.b, b.b, t)};
}

Raster::Raster(int width, int height, Rgb fill) : width_(width), height_(height) {
  if (width <= 0 || height <= 0 || width > 1 << 15 || height > 1 << 15) {
    throw InternalError("raster: bad size " + std::to_string(width) + "x" + std::to_string(height));
  }
  rgb_.resize(3 * static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < rgb_.size(); i += 3) {
    rgb_[i] = fill.r;
    rgb_[i + 1] = fill.g;
    rgb_[i + 2] = fill.b;
  }
}

Rgb Raster::at(int x, int y) const {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * width_ + x);
  return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

void Raster::set(int x, int y, Rgb c) {
  if (!inside(x, y)) return;
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * width_ + x);
  rgb_[i] = c.r;
  rgb_[i + 1] = c.g;
  rgb_[i + 2] = c.b;
}

void Raster::blend(int x, int y, Rgb c, double alpha) {
  if (!inside(x, y) || !(alpha > 0)) return;
  set(x, y, mix(at(x, y), c, std::min(alpha, 1.0)));
}

void Raster::fill_rect(int x0, int y0, int w, int h, Rgb c) {
  for (int y = std::max(0, y0); y < std::min(height_, y0 + h); ++y) {
    for (int x = std::max(0, x0); x < std::min(width_, x0 + w); ++x) set(x, y, c);
  }
}

void Raster::paste(const Raster& other, int x0, int y0) {
  for (int y = 0; y < other.height(); ++y) {
    for (int x = 0; x < other.width(); ++x) set(x0 + x, y0 + y, other.at(x, y));
  }
}

void Raster::line(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double width, Rgb c) {
  stroke(a, b, 0.5 * width, c);
}

void Raster::disc(const Eigen::Vector2d& centre, double radius, Rgb c) {
  stroke(centre, centre, radius, c);
}

void Raster::stroke(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double half, Rgb c) {
  if (!a.allFinite() || !b.allFinite() || !(half > 0)) return;
  // The bounding box, clipped to the image before any cast: an end far outside costs nothing.
  const double pad = half + 1;
  auto clip = [](double v, int hi) { return static_cast<int>(std::clamp(v, 0.0, 1.0 * hi)); };
  const int x0 = clip(std::floor(std::min(a.x(), b.x()) - pad), width_);
  const int y0 = clip(std::floor(std::min(a.y(), b.y()) - pad), height_);
  const int x1 = clip(std::ceil(std::max(a.x(), b.x()) + pad), width_);
  const int y1 = clip(std::ceil(std::max(a.y(), b.y()) + pad), height_);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      // Coverage ramps over one pixel across the stroke's edge.
      const double d = segment_distance(Eigen::Vector2d(x + 0.5, y + 0.5), a, b);
      blend(x, y, c, std::clamp(half + 0.5 - d, 0.0, 1.0));
    }
  }
}

}  // namespace groovetrace::picture
