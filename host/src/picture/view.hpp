#pragma once
// Where the overview looks from: the camera of an organized frame (a pinhole model recovered
// from the points), or an orthographic top view along the direction from the cloud to its
// viewpoint. Both map points of the cloud's frame (metres) to picture pixels (raster.hpp's
// coordinates), and both define a view frame: x right, y down, z away from the viewer.

#include <Eigen/Geometry>
#include <groovetrace/cloud.hpp>

namespace groovetrace::picture {

struct View {
  enum class Kind { pinhole, top };
  Kind kind = Kind::top;
  int width = 0, height = 0;  ///< the picture (pixels), without the caption bar
  /// Rotation from the cloud's frame into the view frame (identity for a pinhole view: the
  /// camera frame is the view frame).
  Eigen::Matrix3d R_view_cloud = Eigen::Matrix3d::Identity();
  /// Pinhole: the frame's intrinsics (pixels of the cloud's grid), and the picture's pixels
  /// per grid pixel.
  double fx = 0, fy = 0, cx = 0, cy = 0, scale = 1;
  /// Top view: the view-frame (x, y) at the picture's top-left corner (m), and pixels per
  /// metre.
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  double px_per_m = 1;

  /// The picture pixel of a point of the cloud's frame (m); NaN behind a pinhole camera.
  Eigen::Vector2d project(const Eigen::Vector3d& p_cloud) const;
  /// Pixels per metre at a point (m, cloud frame) for a length across the line of sight.
  double pixels_per_metre(const Eigen::Vector3d& p_cloud) const;
};

/// The mean of the valid points (m, cloud frame); zero when there are none.
Eigen::Vector3d valid_centroid(const Cloud& cloud);

/// The pinhole view of an organized frame at `max_side` pixels on its long side (0: the
/// frame's own size), or nothing (kind top, width 0) when the frame is not a pinhole image
/// (not organized, or moved out of its camera frame).
View pinhole_view(const Cloud& cloud, int max_side);

/// The orthographic view along `viewpoint` (cloud frame, m) minus the valid points' centroid,
/// so that the sensor looks at the picture; right and down follow the cloud's x and y as far
/// as the direction allows. Fitted to the valid points (0.1% to 99.9% on each axis, with a
/// margin) with `max_side` pixels (0: 800) on the long side.
View top_view(const Cloud& cloud, const Eigen::Vector3f& viewpoint, int max_side);

}  // namespace groovetrace::picture
