#pragma once
// Torch poses and paths, shared by both methods and by every writer of robot programs.

#include <groovetrace/cloud.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace groovetrace {

/// One torch pose. Tool frame: z along the torch into the workpiece (= -mean surface
/// normal), x along the travel direction, y = z cross x.
struct Waypoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< metres, in the trajectory's frame
  /// Rotation of the tool frame in the trajectory's frame.
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// UR axis-angle (rad), continuous along the path.
  Eigen::Vector3d rotation_vector = Eigen::Vector3d::Zero();
  /// Yaw, pitch, roll (deg): R = Rz(yaw) Ry(pitch) Rx(roll).
  Eigen::Vector3d euler_zyx_deg = Eigen::Vector3d::Zero();
  int support = 0;                 ///< groove points in this waypoint's slice
};

/// An ordered torch path.
struct Trajectory {
  std::string frame = "camera";       ///< "camera" (the scan's frame) or "base"
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< unit groove direction (PCA)
  double length = 0.0;                ///< extent of the groove along `direction` (m)
  std::vector<Waypoint> waypoints;
};

/// Tool orientation from the surface normal n (pointing out of the workpiece, towards the
/// sensor) and the travel direction t: z = -n, x = t made orthogonal to z.
Eigen::Quaterniond tool_orientation(const Eigen::Vector3d& normal,
                                    const Eigen::Vector3d& travel);

/// Fills rotation_vector (continuous along the path) and euler_zyx_deg from orientation.
void fill_rotation_representations(Trajectory& trajectory);

}  // namespace groovetrace
