#pragma once
// Small analytic scenes for the robust method: a height field z = h(x, y) (world frame, z up,
// metres) seen by a pinhole camera looking down, ray-marched exactly, so that tests know the
// true seam. Grooves are V-shaped in the distance from a path (line, L, circle), which is
// also how a V swept along a curve looks: sharp inside corners, round outside ones.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <groovetrace/cloud.hpp>
#include <random>
#include <vector>

namespace groovetrace::test {

/// Distance (m) from p to the polyline `path` (any dimension, m); closed joins last to first.
template <int D>
double polyline_distance(const std::vector<Eigen::Matrix<double, D, 1>>& path, bool closed,
                         const Eigen::Matrix<double, D, 1>& p) {
  double best = INFINITY;
  const std::size_t n = path.size();
  for (std::size_t k = 0; k + 1 < n + (closed ? 1 : 0); ++k) {
    const Eigen::Matrix<double, D, 1> a = path[k], ab = path[(k + 1) % n] - a;
    const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-18), 0.0, 1.0);
    best = std::min(best, (a + t * ab - p).norm());
  }
  return best;
}

/// Distance (m) from (x, y) to the polyline `path` (world xy, m); closed joins last to first.
inline double polyline_distance(const std::vector<Eigen::Vector2d>& path, bool closed, double x,
                                double y) {
  return polyline_distance(path, closed, Eigen::Vector2d(x, y));
}

/// Depth (m, >= 0) of a V-groove of top width `width` and depth `depth` at distance d from
/// its root line (the walls meet at the root: no gap).
inline double v_depth(double d, double width, double depth) {
  return depth * std::max(0.0, 1.0 - d / (0.5 * width));
}

/// A circle of `radius` (m) about (cx, cy) as a closed polyline of `n` vertices.
inline std::vector<Eigen::Vector2d> circle_path(double cx, double cy, double radius, int n = 360) {
  std::vector<Eigen::Vector2d> p;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    p.emplace_back(cx + radius * std::cos(a), cy + radius * std::sin(a));
  }
  return p;
}

struct TopCamera {
  int width = 320, height = 240;
  double fx = 251.0;       // pixels (a D415 at 320 columns)
  double distance = 0.25;  // camera height above z = 0 (m)
  double tilt_deg = 0.0;   // rotation about the world x axis
  double noise = 0.0;      // Gaussian depth noise along the ray (m)
  unsigned seed = 1;
};

struct HeightRender {
  Cloud cloud;                      // camera frame (x right, y down, z forward), metres
  std::vector<std::uint8_t> label;  // 1 where `in_groove` holds at the hit
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  /// A world point in the camera frame.
  Eigen::Vector3d to_camera(const Eigen::Vector3d& p_world) const {
    return T_world_camera.inverse() * p_world;
  }
};

/// Ray-marches z = height(x, y) (world; z_lo <= h <= z_hi) through every pixel: steps of
/// 0.1 mm in depth, then bisection. Pixels that miss the band stay NaN.
inline HeightRender render_heightfield(const std::function<double(double, double)>& height,
                                       const std::function<bool(double, double)>& in_groove,
                                       double z_lo, double z_hi, const TopCamera& cam) {
  HeightRender out;
  Eigen::Matrix3d R0;  // camera looking down: x_c = x_w, y_c = -y_w, z_c = -z_w
  R0 << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(cam.tilt_deg * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix() *
      R0;
  const Eigen::Vector3d c = -cam.distance * R.col(2);
  out.T_world_camera.linear() = R;
  out.T_world_camera.translation() = c;
  std::mt19937 rng(cam.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double cx = 0.5 * (cam.width - 1), cy = 0.5 * (cam.height - 1);
  out.cloud.width = cam.width;
  out.cloud.height = cam.height;
  out.cloud.resize(static_cast<std::size_t>(cam.width) * cam.height);
  out.label.assign(out.cloud.size(), 0);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * cam.width + u;
      out.cloud.x[i] = out.cloud.y[i] = out.cloud.z[i] = NAN;
      const Eigen::Vector3d ray_c((u - cx) / cam.fx, (v - cy) / cam.fx, 1.0);
      const Eigen::Vector3d d = R * ray_c;
      if (d.z() >= 0) continue;
      auto f = [&](double t) {
        const Eigen::Vector3d p = c + t * d;
        return p.z() - height(p.x(), p.y());
      };
      const double t0 = (z_hi + 1e-4 - c.z()) / d.z(), t1 = (z_lo - 1e-4 - c.z()) / d.z();
      const double dt = 1e-4 / std::abs(d.z());
      double a = t0, fa = f(a), t = NAN;
      for (double b = t0 + dt; b <= t1 + dt; b += dt) {
        const double fb = f(b);
        if (fa > 0 && fb <= 0) {
          for (int it = 0; it < 30; ++it) {
            const double m = 0.5 * (a + b);
            (f(m) > 0 ? a : b) = m;
          }
          t = 0.5 * (a + b);
          break;
        }
        a = b;
        fa = fb;
      }
      if (!std::isfinite(t)) continue;
      const Eigen::Vector3d p_w = c + t * d;
      Eigen::Vector3d p_c = t * ray_c;  // camera frame, z = depth
      if (cam.noise > 0) p_c *= 1.0 + cam.noise * gauss(rng) / p_c.z();
      out.cloud.x[i] = static_cast<float>(p_c.x());
      out.cloud.y[i] = static_cast<float>(p_c.y());
      out.cloud.z[i] = static_cast<float>(p_c.z());
      out.label[i] = in_groove(p_w.x(), p_w.y()) ? 1 : 0;
    }
  }
  return out;
}

/// A plate (top at z = 0, filling the view) with a V-groove whose root line lies at the
/// distance `distance(x, y)` (m) = 0.
inline HeightRender render_plate_groove(const std::function<double(double, double)>& distance,
                                        const TopCamera& cam, double width = 0.010,
                                        double depth = 0.006) {
  auto h = [=](double x, double y) { return -v_depth(distance(x, y), width, depth); };
  auto g = [=](double x, double y) { return distance(x, y) < 0.5 * width; };
  return render_heightfield(h, g, -depth, 0.0, cam);
}

/// The same along a polyline `path` (world xy, m).
inline HeightRender render_plate_groove(const std::vector<Eigen::Vector2d>& path, bool closed,
                                        const TopCamera& cam, double width = 0.010,
                                        double depth = 0.006) {
  return render_plate_groove(
      [=](double x, double y) { return polyline_distance(path, closed, x, y); }, cam, width, depth);
}

/// The same along a circle of `radius` (m) about the origin: a closed ring.
inline HeightRender render_plate_ring(double radius, const TopCamera& cam, double width = 0.010,
                                      double depth = 0.006) {
  return render_plate_groove(
      [=](double x, double y) { return std::abs(std::hypot(x, y) - radius); }, cam, width, depth);
}

/// A block of `size_x` x `size_y` x `block_height` (m) centred on the origin on a table
/// (z = 0), optionally with a V-groove across its top along x.
inline HeightRender render_box(const TopCamera& cam, bool groove, double size_x = 0.12,
                               double size_y = 0.08, double block_height = 0.03,
                               double width = 0.010, double depth = 0.006) {
  auto h = [=](double x, double y) {
    if (std::abs(x) > 0.5 * size_x || std::abs(y) > 0.5 * size_y) return 0.0;
    return block_height - (groove ? v_depth(std::abs(y), width, depth) : 0.0);
  };
  auto g = [=](double x, double y) {
    return groove && std::abs(x) <= 0.5 * size_x && std::abs(y) < 0.5 * width;
  };
  return render_heightfield(h, g, 0.0, block_height, cam);
}

}  // namespace groovetrace::test
