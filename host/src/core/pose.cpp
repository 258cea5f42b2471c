// Torch poses: the tool frame from a surface normal and a travel direction, and the rotation
// representations (UR rotation vectors, ZYX Euler angles) written with every waypoint.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <groovetrace/rotation.hpp>
#include <groovetrace/trajectory.hpp>
#include <limits>
#include <string>

#include "core/stats.hpp"

namespace groovetrace {

namespace {

/// Yaw, pitch, roll (deg) with R = Rz(yaw) Ry(pitch) Rx(roll); pitch in [-90, 90].
Eigen::Vector3d euler_zyx_deg(const Eigen::Matrix3d& R) {
  // Row 2 of Rz Ry Rx is (-sin p, cos p sin r, cos p cos r); column 0 is
  // (cos y cos p, sin y cos p, -sin p).
  const double cos_pitch = std::hypot(R(0, 0), R(1, 0));
  const double pitch = std::atan2(-R(2, 0), cos_pitch);  // cos_pitch >= 0: in [-90, 90]
  double yaw = 0.0;
  double roll = 0.0;
  if (cos_pitch > 1e-9) {
    yaw = std::atan2(R(1, 0), R(0, 0));
    roll = std::atan2(R(2, 1), R(2, 2));
  } else {
    // Gimbal lock: only yaw -/+ roll is defined. Put it all in yaw (roll = 0), where
    // R(0,1) = -sin(yaw) and R(1,1) = cos(yaw).
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  return {rad_to_deg(yaw), rad_to_deg(pitch), rad_to_deg(roll)};
}

}  // namespace

Eigen::Quaterniond tool_orientation(const Eigen::Vector3d& normal, const Eigen::Vector3d& travel) {
  Eigen::Vector3d z = -normal;
  const double zn = z.norm();
  // A slice whose normals cancel has no surface direction; look along the frame's +z (the
  // camera's viewing axis) rather than produce NaN poses.
  z = (std::isfinite(zn) && zn > 1e-12) ? Eigen::Vector3d(z / zn) : Eigen::Vector3d::UnitZ();
  Eigen::Vector3d x = travel - travel.dot(z) * z;
  const double xn = x.norm();
  x = (std::isfinite(xn) && xn > 1e-9 * std::max(1.0, travel.norm()))
          ? Eigen::Vector3d(x / xn)
          : Eigen::Vector3d(z.unitOrthogonal());
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = z;
  return Eigen::Quaterniond(R).normalized();
}

void fill_rotation_representations(Trajectory& trajectory) {
  bool first = true;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (auto& w : trajectory.waypoints) {
    w.orientation.normalize();
    w.rotation_vector =
        first ? rotation_vector(w.orientation) : rotation_vector_near(w.orientation, previous);
    previous = w.rotation_vector;
    first = false;
    w.euler_zyx_deg = euler_zyx_deg(w.orientation.toRotationMatrix());
  }
}

RotationRate max_rotation_rate(const Trajectory& trajectory) {
  RotationRate worst;
  const std::vector<Waypoint>& w = trajectory.waypoints;
  double s = 0.0;
  for (std::size_t k = 1; k < w.size(); ++k) {
    const double d = (w[k].position - w[k - 1].position).norm();
    if (d >= 1e-6) {
      const double rate =
          rad_to_deg(w[k - 1].orientation.angularDistance(w[k].orientation)) / (1000.0 * d);
      if (rate > worst.deg_per_mm) worst = {rate, s + 0.5 * d};
    }
    s += d;
  }
  return worst;
}

}  // namespace groovetrace
