#pragma once
// overview.png: one picture of a run that a welding engineer reads at a glance. The scan
// shaded (an organized frame as its depth image, anything else as a top view along the
// viewpoint), the groove points tinted orange, every exported seam drawn in its own colour
// with its path, waypoints and short tool-axis ticks, a scale bar, and a caption line.

#include <Eigen/Geometry>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <groovetrace/trajectory.hpp>
#include <optional>
#include <string>
#include <vector>

#include "picture/raster.hpp"

namespace groovetrace::picture {

constexpr int kThumbnailSide = 240;  ///< pixels on the long side of a thumbnail

/// What the overview shows. The picture is drawn in the cloud's frame.
struct OverviewInput {
  OverviewInput(const Cloud& c, const std::vector<std::uint8_t>& g,
                const std::vector<Trajectory>& t)
      : cloud(c), groove(g), trajectories(t) {}

  const Cloud& cloud;                           ///< metres, in the cloud's own frame
  const std::vector<std::uint8_t>& groove;      ///< per point, 1 = groove (other size: none)
  const std::vector<Trajectory>& trajectories;  ///< the exported seams, best first
  /// Maps the trajectories' positions (m) into the cloud's frame: identity when they are in
  /// it, T_base_camera.inverse() when run moved them into the robot base.
  Eigen::Isometry3d T_cloud_trajectory = Eigen::Isometry3d::Identity();
  /// The sensor origin (m, cloud frame) that the top view looks from; unset: cloud.viewpoint.
  std::optional<Eigen::Vector3f> viewpoint;
  std::string caption;  ///< one line under the picture (caption_line)
};

/// The colour of the k-th exported seam (0 = trajectory.csv), distinct from the groove tint.
Rgb seam_colour(std::size_t k);

/// "scan.pcd  robust  2 seams  98.4 + 41.0 mm  ok": the file's name, the method, the number
/// of seams and their lengths (mm; Trajectory::length), and `status`.
std::string caption_line(const std::string& file, const std::string& method,
                         const std::vector<Trajectory>& trajectories, const std::string& status);

/// The picture with its caption bar. `max_side` is the picture's long side (pixels; 0: the
/// organized frame's own size, or 800 for a top view; kThumbnailSide for a thumbnail).
Raster render_overview(const OverviewInput& input, int max_side = 0);

/// render_overview as PNG bytes (8-bit RGB, encode_png).
std::string overview_png(const OverviewInput& input, int max_side = 0);

}  // namespace groovetrace::picture
