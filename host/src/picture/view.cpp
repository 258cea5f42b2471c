#include "picture/view.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/frame_intrinsics.hpp"

namespace groovetrace::picture {
namespace {

constexpr int kTopSide = 800;  // pixels on the long side of a top view by default

// Whether the frame's points land on their own pixels through the view (within 2 grid
// pixels for nine in ten of a sample): the estimator's focal lengths are unsigned, so a
// mirrored frame would otherwise pass.
bool lands_on_grid(const Cloud& cloud, const View& v) {
  const std::size_t stride = std::max<std::size_t>(1, cloud.size() / 2000) | 1;
  std::size_t n = 0, on = 0;
  for (std::size_t i = 0; i < cloud.size(); i += stride) {
    if (!cloud.valid(i) || !(cloud.z[i] > 0)) continue;
    const double u = v.fx * cloud.x[i] / cloud.z[i] + v.cx;
    const double w = v.fy * cloud.y[i] / cloud.z[i] + v.cy;
    const double col = static_cast<double>(i % cloud.width),
                 row = static_cast<double>(i / cloud.width);
    ++n;
    on += std::abs(u - col) <= 2 && std::abs(w - row) <= 2 ? 1 : 0;
  }
  return n > 0 && on >= 0.9 * static_cast<double>(n);
}

// The quantile q in [0, 1] of v (reordered).
double quantile(std::vector<double>& v, double q) {
  auto it = v.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), it, v.end());
  return *it;
}

// Rows right, down, forward (away from the viewer) for a view towards -`to_viewer`; down
// follows the cloud's y (a camera frame's down), else its z, else its x.
Eigen::Matrix3d view_rotation(const Eigen::Vector3d& to_viewer) {
  const Eigen::Vector3d f = -to_viewer.normalized();
  Eigen::Vector3d down = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& hint :
       {Eigen::Vector3d::UnitY().eval(), Eigen::Vector3d::UnitZ().eval(),
        Eigen::Vector3d::UnitX().eval()}) {
    down = hint - hint.dot(f) * f;
    if (down.norm() > 0.3) break;
  }
  down.normalize();
  Eigen::Matrix3d R;
  R.row(0) = down.cross(f);
  R.row(1) = down;
  R.row(2) = f;
  return R;
}

}  // namespace

Eigen::Vector3d valid_centroid(const Cloud& cloud) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    sum += cloud.point(i).cast<double>();
    ++n;
  }
  return n > 0 ? Eigen::Vector3d(sum / static_cast<double>(n)) : Eigen::Vector3d::Zero();
}

namespace {

// Sets origin, px_per_m, width and height of a top view so that the valid points (0.1% to
// 99.9% on each axis: a few stray points must not shrink the scan) fill `side` pixels.
void fit_extent(const Cloud& cloud, int side, View& v) {
  std::vector<double> xs, ys;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    const Eigen::Vector3d q = v.R_view_cloud * cloud.point(i).cast<double>();
    xs.push_back(q.x());
    ys.push_back(q.y());
  }
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  if (!xs.empty()) {
    x0 = quantile(xs, 0.001), x1 = quantile(xs, 0.999);
    y0 = quantile(ys, 0.001), y1 = quantile(ys, 0.999);
  }
  const double margin = 0.04 * std::max({x1 - x0, y1 - y0, 1e-3});  // m
  const double sx = x1 - x0 + 2 * margin, sy = y1 - y0 + 2 * margin;
  v.px_per_m = side / std::max(sx, sy);
  v.origin = Eigen::Vector2d(x0 - margin, y0 - margin);
  v.width = std::max(1, static_cast<int>(std::lround(sx * v.px_per_m)));
  v.height = std::max(1, static_cast<int>(std::lround(sy * v.px_per_m)));
}

}  // namespace

Eigen::Vector2d View::project(const Eigen::Vector3d& p_cloud) const {
  if (kind == Kind::top) {
    const Eigen::Vector3d q = R_view_cloud * p_cloud;
    return (q.head<2>() - origin) * px_per_m;
  }
  if (!(p_cloud.z() > 0)) return Eigen::Vector2d::Constant(NAN);
  // Grid pixel (col, row) has its centre at (col + 0.5, row + 0.5) in the picture at scale 1.
  const double u = fx * p_cloud.x() / p_cloud.z() + cx;
  const double w = fy * p_cloud.y() / p_cloud.z() + cy;
  return Eigen::Vector2d(u + 0.5, w + 0.5) * scale;
}

double View::pixels_per_metre(const Eigen::Vector3d& p_cloud) const {
  if (kind == Kind::top) return px_per_m;
  return p_cloud.z() > 0 ? fx * scale / p_cloud.z() : NAN;
}

View pinhole_view(const Cloud& cloud, int max_side) {
  View v;
  if (!cloud.organized() || cloud.size() != std::size_t{cloud.width} * cloud.height) return v;
  const FrameIntrinsics k = estimate_intrinsics(cloud);
  if (!k.pinhole) return v;
  v.fx = k.fx, v.fy = k.fy, v.cx = k.cx, v.cy = k.cy;
  if (!lands_on_grid(cloud, v)) return v;
  const int long_side = static_cast<int>(std::max(cloud.width, cloud.height));
  v.kind = View::Kind::pinhole;
  v.scale = max_side > 0 ? static_cast<double>(max_side) / long_side : 1.0;
  v.width = std::max(1, static_cast<int>(std::lround(cloud.width * v.scale)));
  v.height = std::max(1, static_cast<int>(std::lround(cloud.height * v.scale)));
  return v;
}

View top_view(const Cloud& cloud, const Eigen::Vector3f& viewpoint, int max_side) {
  View v;
  const Eigen::Vector3d c = valid_centroid(cloud);
  Eigen::Vector3d to_viewer = viewpoint.cast<double>() - c;
  // A viewpoint at the centroid gives no direction: look along z like a camera.
  if (!(to_viewer.norm() > 1e-9)) to_viewer = -Eigen::Vector3d::UnitZ();
  v.R_view_cloud = view_rotation(to_viewer);
  fit_extent(cloud, max_side > 0 ? max_side : kTopSide, v);
  return v;
}

}  // namespace groovetrace::picture
