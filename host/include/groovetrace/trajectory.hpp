#pragma once
// Waypoints along the groove (paper section IV): slices along the groove direction, one
// geometric median per slice, tool orientation from the slice's mean normal.

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

/// Geometric median (minimum sum of distances) of `points` by Weiszfeld's iteration, which
/// is gradient descent with the step that makes it monotone. Stops when a step moves less
/// than `tolerance` (same unit as the points) or after `max_iterations`.
/// Throws std::invalid_argument for an empty set.
Eigen::Vector3d geometric_median(const std::vector<Eigen::Vector3d>& points,
                                 int max_iterations = 1000, double tolerance = 1e-7);

/// Builds the paper's trajectory from the groove points (mask != 0 and a valid normal).
/// The direction is the first principal axis of those points, signed so that it points
/// along +x of the cloud's frame (+y if the axis is perpendicular to x); `slices` equal
/// slices along it each give one waypoint (empty slices give none).
/// Throws NoGrooveError if fewer than 2 waypoints result, UsageError for slices < 1.
Trajectory paper_trajectory(const Cloud& cloud, const Normals& normals,
                            const std::vector<std::uint8_t>& mask, int slices,
                            int median_max_iterations = 1000, double median_tolerance = 1e-7);

/// Tool orientation from the surface normal n (pointing out of the workpiece, towards the
/// sensor) and the travel direction t: z = -n, x = t made orthogonal to z.
Eigen::Quaterniond tool_orientation(const Eigen::Vector3d& normal,
                                    const Eigen::Vector3d& travel);

/// Fills rotation_vector (continuous along the path) and euler_zyx_deg from orientation.
void fill_rotation_representations(Trajectory& trajectory);

}  // namespace groovetrace
