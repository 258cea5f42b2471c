#pragma once
// Rigid transforms from calibration files, and moving a trajectory into the robot base.

#include <Eigen/Geometry>
#include <groovetrace/export.hpp>
#include <groovetrace/trajectory.hpp>
#include <optional>
#include <string>

namespace groovetrace {

/// A transform read from a calibration file, and what the file said about it.
struct Calibration {
  /// T_a_b: maps point coordinates in frame b to frame a (translation in metres).
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  /// The layout it was read as: "groovetrace", "easy_handeye", "easy_handeye2",
  /// "ros_transform", "ros_pose", "opencv_yaml", "opencv_xml", "opencv_json", "matrix_text",
  /// "matrix_list" or "ur_pose" (docs/frames.md).
  std::string format;
  std::string parent_frame;  ///< frame a, when the file names it; else empty
  std::string child_frame;   ///< frame b, when the file names it; else empty
  /// easy_handeye(2): true for eye-in-hand (T_effector_camera), false for eye-on-base
  /// (T_base_camera); unset when the file does not say.
  std::optional<bool> eye_on_hand;
};

/// Reads a rigid transform T_a_b from a calibration file in any layout of docs/frames.md,
/// recognised by its content (the extension only picks JSON over YAML for a tree file):
/// groovetrace's own (translation [x, y, z] m, rotation [qx, qy, qz, qw]), easy_handeye and
/// easy_handeye2 YAML, OpenCV FileStorage R and t (YAML or XML), a 4x4 homogeneous matrix
/// (text or a list of 4 rows) and a UR pose p[x, y, z, rx, ry, rz] (m, rotation vector rad).
/// Quaternions must be unit within 1e-3 and matrices orthonormal within 1e-3 per entry of
/// R^T R - I (det > 0); both are then made exactly rigid. Throws InputError, one line naming
/// the file, for anything else: an unreadable file, a missing or non-numeric value, a
/// quaternion whose order (x, y, z, w or w, x, y, z) the file does not say, a translation
/// beyond kMaxCoordinate.
GT_API Calibration read_calibration(const std::string& path);

/// read_calibration(path).transform.
GT_API Eigen::Isometry3d read_transform(const std::string& path);

/// Re-expresses a trajectory given in the camera frame in the base frame:
/// T_base_camera = T_base_flange * T_flange_camera. Sets frame = "base".
GT_API void transform_trajectory(Trajectory& trajectory, const Eigen::Isometry3d& T_base_camera);

}  // namespace groovetrace
