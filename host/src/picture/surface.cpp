#include "picture/surface.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <utility>

namespace groovetrace::picture {
namespace {

// Towards the light, view frame: from the viewer's side, 20 deg up and to the left, so that
// flat ground facing the viewer is a light grey, the two walls of a groove differ, and the
// sensor's undulation of flat ground (slopes of a few degrees) hardly shows.
const Eigen::Vector3f kLight = Eigen::Vector3f(-0.2f, -0.3f, -1.0f).normalized();
constexpr double kAmbient = 0.1;     // share of the grey that is not lit
constexpr double kDepthFade = 0.45;  // the lowest points are this much darker

Surface empty_surface(int width, int height) {
  Surface s;
  s.width = width;
  s.height = height;
  s.p_view.assign(static_cast<std::size_t>(width) * height, Eigen::Vector3f::Constant(NAN));
  s.groove.assign(s.p_view.size(), 0);
  return s;
}

bool filled(const Surface& s, int x, int y) {
  return x >= 0 && y >= 0 && x < s.width && y < s.height &&
         std::isfinite(s.p_view[static_cast<std::size_t>(y) * s.width + x].z());
}

const Eigen::Vector3f& at(const Surface& s, int x, int y) {
  return s.p_view[static_cast<std::size_t>(y) * s.width + x];
}

// The surface's tangent at (x, y) along pixel step (dx, dy), from the points on both sides,
// or one side at an edge; NaN when neither has a point.
Eigen::Vector3f tangent(const Surface& s, int x, int y, int dx, int dy) {
  const bool ahead = filled(s, x + dx, y + dy), behind = filled(s, x - dx, y - dy);
  if (ahead && behind) return at(s, x + dx, y + dy) - at(s, x - dx, y - dy);
  if (ahead) return at(s, x + dx, y + dy) - at(s, x, y);
  if (behind) return at(s, x, y) - at(s, x - dx, y - dy);
  return Eigen::Vector3f::Constant(NAN);
}

// Unit normal at (x, y) towards the viewer (negative z), NaN when it cannot be had.
Eigen::Vector3f normal_at(const Surface& s, int x, int y, int baseline) {
  Eigen::Vector3f n = tangent(s, x, y, baseline, 0).cross(tangent(s, x, y, 0, baseline));
  if (!(n.norm() > 0)) return Eigen::Vector3f::Constant(NAN);
  n.normalize();
  return n.z() > 0 ? Eigen::Vector3f(-n) : n;
}

// One pass of a box filter along pixel step (dx, dy): each filled point becomes the mean of
// the filled points within `radius` steps.
Surface box_pass(const Surface& in, int radius, int dx, int dy) {
  Surface out = in;
  for (int y = 0; y < in.height; ++y) {
    for (int x = 0; x < in.width; ++x) {
      if (!filled(in, x, y)) continue;
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int n = 0;
      for (int k = -radius; k <= radius; ++k) {
        if (!filled(in, x + k * dx, y + k * dy)) continue;
        sum += at(in, x + k * dx, y + k * dy);
        ++n;
      }
      out.p_view[static_cast<std::size_t>(y) * in.width + x] = sum / static_cast<float>(n);
    }
  }
  return out;
}

// Heights (m) of the filled pixels towards the viewer above the plane z = a x + b y + c
// fitted to them (least squares, view frame), NaN where empty: the ground of most scans, so
// that a workpiece stands out from its table whatever the angle of view.
std::vector<float> heights(const Surface& s) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : s.p_view) {
    if (!std::isfinite(p.z())) continue;
    const Eigen::Vector3d row(p.x(), p.y(), 1.0);
    A += row * row.transpose();
    b += row * p.z();
  }
  const Eigen::Vector3d plane = A.ldlt().solve(b);
  std::vector<float> h(s.p_view.size(), NAN);
  for (std::size_t i = 0; i < h.size(); ++i) {
    const Eigen::Vector3f& p = s.p_view[i];
    const double ground = plane.allFinite() ? plane.dot(Eigen::Vector3d(p.x(), p.y(), 1)) : 0.0;
    if (std::isfinite(p.z())) h[i] = static_cast<float>(ground - p.z());
  }
  return h;
}

// The low and high ends (2% and 98%) of the finite heights, for the fade.
std::pair<float, float> height_range(std::vector<float> h) {
  h.erase(std::remove_if(h.begin(), h.end(), [](float v) { return !std::isfinite(v); }), h.end());
  if (h.empty()) return {0.0f, 1.0f};
  auto q = [&](double f) {
    auto it = h.begin() + static_cast<std::ptrdiff_t>(f * static_cast<double>(h.size() - 1));
    std::nth_element(h.begin(), it, h.end());
    return *it;
  };
  const float low = q(0.02), high = q(0.98);
  return {low, std::max(high, low + 1e-3f)};
}

// One pass: every empty pixel with at least five filled neighbours of eight takes their mean
// point and their majority label (closes the gaps a sparse splat leaves, not the outline).
void fill_holes(Surface& s) {
  const Surface before = s;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      if (filled(before, x, y)) continue;
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int n = 0, groove = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (!filled(before, x + dx, y + dy)) continue;
          sum += at(before, x + dx, y + dy);
          groove += before.groove[static_cast<std::size_t>(y + dy) * s.width + x + dx];
          ++n;
        }
      }
      if (n < 5) continue;
      const std::size_t i = static_cast<std::size_t>(y) * s.width + x;
      s.p_view[i] = sum / static_cast<float>(n);
      s.groove[i] = 2 * groove >= n ? 1 : 0;
    }
  }
}

}  // namespace

Surface grid_surface(const Cloud& cloud, const std::vector<std::uint8_t>& groove) {
  Surface s = empty_surface(static_cast<int>(cloud.width), static_cast<int>(cloud.height));
  const bool labels = groove.size() == cloud.size();
  for (std::size_t i = 0; i < cloud.size() && i < s.p_view.size(); ++i) {
    if (!cloud.valid(i)) continue;
    s.p_view[i] = cloud.point(i);
    s.groove[i] = labels && groove[i] ? 1 : 0;
  }
  return s;
}

Surface splat_surface(const Cloud& cloud, const std::vector<std::uint8_t>& groove, const View& view,
                      int side) {
  Surface s = empty_surface(view.width, view.height);
  const bool labels = groove.size() == cloud.size();
  const Eigen::Matrix3f R = view.R_view_cloud.cast<float>();
  const int lo = -(side - 1) / 2;  // the square's first offset from the point's pixel
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    const Eigen::Vector3f q = R * cloud.point(i);
    const Eigen::Vector2d px = view.project(cloud.point(i).cast<double>());
    const int x0 = static_cast<int>(std::floor(px.x())) + lo;
    const int y0 = static_cast<int>(std::floor(px.y())) + lo;
    for (int y = std::max(0, y0); y < std::min(s.height, y0 + side); ++y) {
      for (int x = std::max(0, x0); x < std::min(s.width, x0 + side); ++x) {
        const std::size_t k = static_cast<std::size_t>(y) * s.width + x;
        if (s.p_view[k].z() <= q.z()) continue;  // a nearer point holds it (NaN: empty)
        s.p_view[k] = q;
        s.groove[k] = labels && groove[i] ? 1 : 0;
      }
    }
  }
  fill_holes(s);
  return s;
}

int splat_side(const Cloud& cloud, const View& view) {
  constexpr int kCell = 8;  // pixels; coarse enough that a cell of the surface is never empty
  const int cw = (view.width + kCell - 1) / kCell, ch = (view.height + kCell - 1) / kCell;
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(cw) * ch, 0);
  double n = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    const Eigen::Vector2d px = view.project(cloud.point(i).cast<double>());
    if (!(px.x() >= 0 && px.y() >= 0 && px.x() < view.width && px.y() < view.height)) continue;
    occupied[static_cast<std::size_t>(px.y() / kCell) * cw + static_cast<int>(px.x() / kCell)] = 1;
    n += 1;
  }
  const double area =
      kCell * kCell * static_cast<double>(std::count(occupied.begin(), occupied.end(), 1));
  if (!(n > 0)) return 1;
  // Mean spacing in pixels; a little over a whole pixel still leaves the random gaps to fill.
  const double spacing = std::sqrt(area / n);
  return std::clamp(static_cast<int>(std::ceil(spacing - 0.15)), 1, 8);
}

Raster shade(const Surface& s, int baseline) {
  Raster out(s.width, s.height, kNothing);
  const std::vector<float> h = heights(s);
  const auto [low, high] = height_range(h);
  // Normals of the surface smoothed over the baseline: the shape, not the sensor's noise.
  const Surface smooth = box_pass(box_pass(s, baseline, 1, 0), baseline, 0, 1);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      if (!filled(s, x, y)) continue;
      const std::size_t i = static_cast<std::size_t>(y) * s.width + x;
      const Eigen::Vector3f n = normal_at(smooth, x, y, baseline);
      // A lone point has no normal: lit as if it faced the viewer.
      const double lambert = n.allFinite() ? std::max(0.0f, n.dot(kLight)) : -kLight.z();
      const double t = std::clamp((high - h[i]) / (high - low), 0.0f, 1.0f);
      const double level = 255 * (kAmbient + (1 - kAmbient) * lambert) * (1 - kDepthFade * t);
      const auto g = static_cast<std::uint8_t>(std::lround(std::clamp(level, 0.0, 255.0)));
      out.set(x, y, s.groove[i] ? mix({g, g, g}, kGrooveTint, kGrooveAlpha) : Rgb{g, g, g});
    }
  }
  return out;
}

Raster resample(const Raster& image, int width, int height) {
  if (width == image.width() && height == image.height()) return image;
  Raster out(width, height);
  auto span = [](int i, int from, int to) {  // source pixels under target pixel i
    const int a = static_cast<int>(static_cast<long long>(i) * from / to);
    const int b = static_cast<int>(static_cast<long long>(i + 1) * from / to);
    return std::pair<int, int>(a, std::max(a + 1, b));
  };
  for (int y = 0; y < height; ++y) {
    const auto [y0, y1] = span(y, image.height(), height);
    for (int x = 0; x < width; ++x) {
      const auto [x0, x1] = span(x, image.width(), width);
      long sum[3] = {0, 0, 0};
      for (int sy = y0; sy < y1; ++sy) {
        for (int sx = x0; sx < x1; ++sx) {
          const Rgb c = image.at(sx, sy);
          sum[0] += c.r, sum[1] += c.g, sum[2] += c.b;
        }
      }
      const long n = static_cast<long>(y1 - y0) * (x1 - x0);
      auto avg = [&](long v) { return static_cast<std::uint8_t>((v + n / 2) / n); };
      out.set(x, y, {avg(sum[0]), avg(sum[1]), avg(sum[2])});
    }
  }
  return out;
}

}  // namespace groovetrace::picture
