#pragma once
// Torch poses and paths, shared by both methods and by every writer of robot programs.

#include <Eigen/Geometry>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <groovetrace/export.hpp>
#include <string>
#include <vector>

namespace groovetrace {

/// One torch pose. Tool frame: z along the torch into the workpiece (robust method: the
/// negated bisector of the two fitted walls; paper method: the negated mean surface normal of
/// the slice), x along the travel direction, y = z cross x.
struct Waypoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< metres, in the trajectory's frame
  /// Rotation of the tool frame in the trajectory's frame.
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// UR axis-angle (rad), continuous along the path.
  Eigen::Vector3d rotation_vector = Eigen::Vector3d::Zero();
  /// Yaw, pitch, roll (deg): R = Rz(yaw) Ry(pitch) Rx(roll).
  Eigen::Vector3d euler_zyx_deg = Eigen::Vector3d::Zero();
  int support = 0;  ///< paper method: groove points in this waypoint's slice; robust: 0
};

/// An ordered torch path.
struct Trajectory {
  std::string frame = "camera";  ///< "camera" (the scan's frame) or "base"
  /// Unit overall travel direction: paper: the groove points' first principal axis; robust:
  /// the chord from the first to the last waypoint.
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  /// m: paper: the groove's extent along `direction`; robust: the arc length of the path.
  double length = 0.0;
  std::vector<Waypoint> waypoints;
};

/// Tool orientation from an outward direction n (out of the workpiece, towards the sensor:
/// the surface normal or the walls' bisector) and the travel direction t: z = -n, x = t made
/// orthogonal to z.
GT_API Eigen::Quaterniond tool_orientation(const Eigen::Vector3d& normal,
                                           const Eigen::Vector3d& travel);

/// The fastest turn of the torch along a path: the largest rotation angle between consecutive
/// waypoints divided by their distance, and where (arc length from the first waypoint to the
/// pair's midpoint, along the waypoints). Pairs closer than 1 um are skipped; zero for fewer
/// than two waypoints.
struct RotationRate {
  double deg_per_mm = 0.0;
  double at_m = 0.0;
};
GT_API RotationRate max_rotation_rate(const Trajectory& trajectory);

/// Fills rotation_vector (continuous along the path) and euler_zyx_deg from orientation.
GT_API void fill_rotation_representations(Trajectory& trajectory);

}  // namespace groovetrace
