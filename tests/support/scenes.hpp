#pragma once
// Analytic test scenes: a pinhole camera (RealSense-like intrinsics) looking at a plate with
// a straight V-groove, ray-cast exactly so that tests know the true geometry.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <groovetrace/cloud.hpp>
#include <random>
#include <string>
#include <vector>

namespace groovetrace::test {

struct VGrooveScene {
  int width = 640, height = 480;
  double distance = 0.4;     // camera to plate along the optical axis at zero tilt (m)
  double tilt_deg = 0.0;     // camera rotation about the world x axis (across the groove)
  double yaw_deg = 0.0;      // camera rotation about the plate normal (turns the groove)
  double top_width = 0.010;  // groove opening (m)
  double depth = 0.004;      // groove depth below the plate (m)
  double noise_sigma = 0.0;  // Gaussian depth noise along the ray (m)
  unsigned seed = 1;
};

struct RenderedScene {
  Cloud cloud;                      // camera frame, metres
  std::vector<std::uint8_t> label;  // 1 = on a groove wall
  Eigen::Isometry3d T_world_camera;
  Eigen::Vector3d groove_dir_camera;  // unit direction of the groove (camera frame)
  Eigen::Vector3d root_point_camera;  // a point on the root line (camera frame)
  Eigen::Vector3d up_camera;          // plate normal (towards the camera), camera frame
};

// World frame: plate top at z = 0, +z towards the camera, groove along world y centred on
// x = 0; the V's walls reach z = -depth at the root. Tilt and yaw move the camera.
inline RenderedScene render_vgroove(const VGrooveScene& s) {
  RenderedScene out;
  const double fx = 0.5 * s.width / std::tan(32.5 * M_PI / 180.0);
  const double cx = 0.5 * s.width, cy = 0.5 * s.height;
  Eigen::Matrix3d R0;  // camera looking down: x_c = x_w, y_c = -y_w, z_c = -z_w
  R0 << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  const Eigen::Matrix3d R_world_camera =
      Eigen::AngleAxisd(s.yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(s.tilt_deg * M_PI / 180, Eigen::Vector3d::UnitX()) * R0;
  const Eigen::Vector3d c = -s.distance * R_world_camera.col(2);
  out.T_world_camera.linear() = R_world_camera;
  out.T_world_camera.translation() = c;
  out.T_world_camera.makeAffine();

  const Eigen::Matrix3d R_camera_world = R_world_camera.transpose();
  out.groove_dir_camera = R_camera_world * Eigen::Vector3d::UnitY();
  out.root_point_camera = R_camera_world * (Eigen::Vector3d(0, 0, -s.depth) - c);
  out.up_camera = R_camera_world * Eigen::Vector3d::UnitZ();

  const double half = s.top_width / 2;
  // Three planes n . p = k in world: flat (z = 0) and the two walls.
  const double slope = s.depth / half;  // wall height change per metre across
  struct Plane {
    Eigen::Vector3d n;
    double k, x_lo, x_hi;
  };
  const std::vector<Plane> planes = {
      {Eigen::Vector3d(0, 0, 1), 0.0, -1e9, 1e9},  // flat: valid where |x| >= half
      {Eigen::Vector3d(slope, 0, 1).normalized(), -s.depth / std::hypot(slope, 1.0), -half, 0},
      {Eigen::Vector3d(-slope, 0, 1).normalized(), -s.depth / std::hypot(slope, 1.0), 0, half},
  };
  std::mt19937 rng(s.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  out.cloud.width = s.width;
  out.cloud.height = s.height;
  out.cloud.resize(static_cast<std::size_t>(s.width) * s.height);
  out.label.assign(out.cloud.size(), 0);
  for (int v = 0; v < s.height; ++v) {
    for (int u = 0; u < s.width; ++u) {
      const Eigen::Vector3d ray_c((u - cx) / fx, (v - cy) / fx, 1.0);
      const Eigen::Vector3d d = R_world_camera * ray_c;
      double best_t = INFINITY;
      bool wall = false;
      for (std::size_t k = 0; k < planes.size(); ++k) {
        const double denom = planes[k].n.dot(d);
        if (std::abs(denom) < 1e-12) continue;
        const double t = (planes[k].k - planes[k].n.dot(c)) / denom;
        if (t <= 0) continue;
        const Eigen::Vector3d hit = c + t * d;
        const bool ok = k == 0 ? std::abs(hit.x()) >= half
                               : hit.x() >= planes[k].x_lo && hit.x() <= planes[k].x_hi;
        if (ok && t < best_t) {
          best_t = t;
          wall = k != 0;
        }
      }
      const std::size_t i = static_cast<std::size_t>(v) * s.width + u;
      if (!std::isfinite(best_t)) {
        out.cloud.x[i] = out.cloud.y[i] = out.cloud.z[i] = NAN;
        continue;
      }
      Eigen::Vector3d p = best_t * ray_c;  // camera frame (ray_c has z = 1: p.z = depth)
      if (s.noise_sigma > 0) p *= 1.0 + s.noise_sigma * noise(rng) / p.z();
      out.cloud.x[i] = static_cast<float>(p.x());
      out.cloud.y[i] = static_cast<float>(p.y());
      out.cloud.z[i] = static_cast<float>(p.z());
      out.label[i] = wall ? 1 : 0;
    }
  }
  return out;
}

/// Whether the tests that run whole scans again and again run fewer or smaller ones:
/// GT_TEST_SMALL=1 in the environment. scripts/test_sanitized.sh sets it, as a sanitized
/// build runs a scan about ten times slower; the assertions stay the same.
inline bool small_runs() {
  const char* v = std::getenv("GT_TEST_SMALL");
  return v != nullptr && std::string(v) == "1";
}

/// The scan of the CLI tests that run whole scans over and over (kills, concurrent runs,
/// batches, robot programs): 640x480 at 0.4 m; with small_runs() 320x240 at 0.2 m, the
/// same 0.8 mm pixel pitch on a quarter of the plate.
inline VGrooveScene repeated_run_scene() {
  VGrooveScene s;
  if (small_runs()) {
    s.width = 320;
    s.height = 240;
    s.distance = 0.2;
  }
  return s;
}

}  // namespace groovetrace::test
