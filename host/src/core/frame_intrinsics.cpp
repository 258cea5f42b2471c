#include "core/frame_intrinsics.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/stats.hpp"

namespace groovetrace {
namespace {

constexpr float kMaxSlack = 1.0f;  // pixels; beyond, windows grow past the cost of the grid

// Pixels per unit of x/z (the focal length) from steps of `gap` pixels, or 0 when the steps
// disagree.
double focal_length(std::vector<double>& steps, int gap) {
  if (steps.size() < 16) return 0;
  const double m = upper_median(steps);
  if (!(std::abs(m) > 0) || !std::isfinite(m)) return 0;
  const auto agree = std::count_if(steps.begin(), steps.end(),
                                   [&](double s) { return std::abs(s - m) <= 0.05 * std::abs(m); });
  if (agree < static_cast<std::ptrdiff_t>(0.9 * static_cast<double>(steps.size()))) return 0;
  return gap / m;
}

}  // namespace

FrameIntrinsics estimate_intrinsics(const Cloud& cloud) {
  FrameIntrinsics out;
  const std::size_t w = cloud.width, h = cloud.height;
  if (h < 2 || w < 2 || cloud.size() != w * h) return out;
  auto usable = [&](std::size_t i) { return cloud.valid(i) && cloud.z[i] > 0; };
  auto u = [&](std::size_t i) { return static_cast<double>(cloud.x[i]) / cloud.z[i]; };
  auto v = [&](std::size_t i) { return static_cast<double>(cloud.y[i]) / cloud.z[i]; };
  // Steps over 32 pixels (fewer in tiny frames) average out the noise of smoothed points;
  // about 24 sample rows and columns bound the cost to about 3 * 10^4 pairs.
  const int gx = static_cast<int>(std::clamp<std::size_t>(w / 8, 1, 32));
  const int gy = static_cast<int>(std::clamp<std::size_t>(h / 8, 1, 32));
  std::vector<double> sx, sy;
  for (std::size_t r = 0; r < h; r += std::max<std::size_t>(1, h / 24)) {
    for (std::size_t c = 0; c + gx < w; ++c) {
      const std::size_t i = r * w + c;
      if (usable(i) && usable(i + gx)) sx.push_back(u(i + gx) - u(i));
    }
  }
  for (std::size_t c = 0; c < w; c += std::max<std::size_t>(1, w / 24)) {
    for (std::size_t r = 0; r + gy < h; ++r) {
      const std::size_t i = r * w + c;
      if (usable(i) && usable(i + gy * w)) sy.push_back(v(i + gy * w) - v(i));
    }
  }
  const double fx = focal_length(sx, gx), fy = focal_length(sy, gy);
  if (fx == 0 || fy == 0) return out;

  // Principal point and residuals on a sample of about 3 * 10^4 points.
  const std::size_t stride = std::max<std::size_t>(1, cloud.size() / 30000) | 1;
  std::vector<double> ox, oy;
  for (std::size_t i = 0; i < cloud.size(); i += stride) {
    if (!usable(i)) continue;
    ox.push_back(static_cast<double>(i % w) - fx * u(i));
    oy.push_back(static_cast<double>(i / w) - fy * v(i));
  }
  if (ox.size() < 16) return out;
  std::vector<double> tmp = ox;
  const double cx = upper_median(tmp);
  tmp = oy;
  const double cy = upper_median(tmp);
  std::vector<double> residual(ox.size());
  for (std::size_t k = 0; k < ox.size(); ++k) {
    residual[k] = std::max(std::abs(ox[k] - cx), std::abs(oy[k] - cy));
  }
  auto q90 = residual.begin() + static_cast<std::ptrdiff_t>(0.9 * (residual.size() - 1));
  std::nth_element(residual.begin(), q90, residual.end());
  const double slack = *q90;
  if (!(slack <= kMaxSlack)) return out;
  out.pinhole = true;
  out.fx = static_cast<float>(std::abs(fx));
  out.fy = static_cast<float>(std::abs(fy));
  out.cx = static_cast<float>(cx);
  out.cy = static_cast<float>(cy);
  out.slack = static_cast<float>(slack);
  return out;
}

}  // namespace groovetrace
