#pragma once
// Rotation representations for robot programs: the UR rotation vector (axis * angle).

#include <Eigen/Geometry>
#include <groovetrace/export.hpp>

namespace groovetrace {

/// Axis-angle vector (rad) of q, angle in [0, pi].
GT_API Eigen::Vector3d rotation_vector(const Eigen::Quaterniond& q);

/// The rotation vector of q that is nearest to `previous` among the equivalent ones
/// (axis*angle and axis*(angle - 2 pi) for both signs of the axis). Keeps a path's vectors
/// continuous where the angle passes pi, which UR controllers need to interpolate sanely.
GT_API Eigen::Vector3d rotation_vector_near(const Eigen::Quaterniond& q,
                                            const Eigen::Vector3d& previous);

/// Quaternion of an axis-angle vector (rad).
GT_API Eigen::Quaterniond quaternion_from_rotation_vector(const Eigen::Vector3d& v);

}  // namespace groovetrace
