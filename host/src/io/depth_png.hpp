#pragma once
// Depth images as RealSense users store them: a 16-bit grey PNG of raw depth units plus the
// depth stream's intrinsics in JSON (docs/design.md, "Depth PNG scans").

#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace::io {

/// The largest depth image accepted, per side (pixels).
constexpr std::uint32_t kMaxDepthSide = 16384;

/// A depth stream's pinhole model (librealsense's rs2_intrinsics names) and depth unit.
struct DepthIntrinsics {
  double fx = 0, fy = 0;    ///< focal lengths (pixels)
  double ppx = 0, ppy = 0;  ///< principal point (pixels; pixel centres at integer coordinates)
  double depth_scale = 0;   ///< metres per depth unit (D4xx default 0.001)
  std::uint32_t width = 0, height = 0;  ///< 0 = not given; else must match the image
};

/// The raw depth units of a 16-bit grey PNG, row-major (index = row * width + col).
struct DepthImage {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint16_t> depth;  ///< 0 = no depth
};

/// Parses the intrinsics JSON `text` (read from `path`). Required: fx, fy, ppx, ppy,
/// depth_scale (positive, finite); optional: width, height (positive integers), model and
/// coeffs (five numbers): any distortion other than none, or a Brown-Conrady model with all
/// coefficients zero (what D4xx depth streams report), is refused. Throws InputError.
DepthIntrinsics parse_depth_intrinsics(const std::string& text, const std::string& path);

/// The intrinsics file of the depth PNG `png`: `given` when not empty, else STEM.json beside
/// it (scan.png: scan.json), else intrinsics.json in its folder; "" when none exists.
std::string find_depth_intrinsics(const std::string& png, const std::string& given);

/// The image's width and height (pixels) from its header, after the header checks of
/// decode_depth_png. Throws InputError.
std::pair<std::uint32_t, std::uint32_t> depth_png_size(const std::string& bytes,
                                                       const std::string& path);

/// Decodes `bytes` (the file `path`) through libpng. Throws InputError for anything but a
/// 16-bit grey PNG, a header larger than kMaxDepthSide per side or than the file can hold,
/// and truncated or corrupt data.
DepthImage decode_depth_png(const std::string& bytes, const std::string& path);

/// The organized cloud of a depth image in its camera frame (x right, y down, z forward,
/// metres): pixel (col, row) with depth d > 0 is z = d * depth_scale,
/// x = (col - ppx) z / fx, y = (row - ppy) z / fy; d = 0 is a NaN point. Viewpoint: origin.
Cloud depth_to_cloud(const DepthImage& image, const DepthIntrinsics& intrinsics);

/// read_cloud's reader of a .png scan (`content` is the file): the intrinsics found as
/// find_depth_intrinsics says, the image decoded, checked against them and deprojected.
/// Throws InputError, one line, naming the file at fault.
Cloud read_depth_png(const std::string& path, const std::string& content,
                     const std::string& intrinsics_path, std::size_t min_valid);

}  // namespace groovetrace::io
