#pragma once
// Text forms of a trajectory that other tools read.

#include <groovetrace/export.hpp>
#include <groovetrace/params.hpp>
#include <groovetrace/trajectory.hpp>
#include <string>

namespace groovetrace {

/// CSV with header `idx,x_m,y_m,z_m,qx,qy,qz,qw,rx,ry,rz`: positions (m) and orientation
/// (quaternion x,y,z,w and UR rotation vector, rad) of each waypoint in trajectory.frame.
GT_API std::string trajectory_csv(const Trajectory& trajectory);

/// JSON with the frame name, units, tool-frame convention, the parameters of the run and,
/// per waypoint: position_m, quaternion_xyzw, rotation_vector_rad, euler_zyx_deg, support.
GT_API std::string trajectory_json(const Trajectory& trajectory, const Params& params);

/// ROS nav_msgs/Path as YAML, the way ROS 2 `ros2 topic echo --once` prints it (without its
/// closing `---`, so the file is one YAML document): header (stamp 0, frame_id =
/// trajectory.frame, "base" or "camera") and per waypoint a geometry_msgs/PoseStamped with
/// the same header, position x, y, z (m) and orientation x, y, z, w (unit quaternion). Numbers
/// are fixed-point with up to 9 decimals and always a decimal point (YAML floats).
GT_API std::string trajectory_ros_yaml(const Trajectory& trajectory);

}  // namespace groovetrace
