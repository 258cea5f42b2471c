#pragma once
// Rigid transforms from calibration files, and moving a trajectory into the robot base.

#include <Eigen/Geometry>
#include <groovetrace/export.hpp>
#include <groovetrace/trajectory.hpp>
#include <string>

namespace groovetrace {

/// Reads a rigid transform T_a_b (maps points in frame b to frame a) from a YAML or JSON
/// file (chosen by extension .yaml/.yml or .json):
///   translation: [x, y, z]          # metres
///   rotation: [qx, qy, qz, qw]      # unit quaternion (norm within 1e-3 of 1)
/// Throws InputError for an unreadable file, missing or non-numeric fields, or a
/// non-unit quaternion.
GT_API Eigen::Isometry3d read_transform(const std::string& path);

/// Re-expresses a trajectory given in the camera frame in the base frame:
/// T_base_camera = T_base_flange * T_flange_camera. Sets frame = "base".
GT_API void transform_trajectory(Trajectory& trajectory, const Eigen::Isometry3d& T_base_camera);

}  // namespace groovetrace
