#pragma once
// Reading scans (PCD, PLY) and writing the annotated cloud.

#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <groovetrace/export.hpp>
#include <optional>
#include <string>
#include <vector>

namespace groovetrace {

/// Options for read_cloud.
struct ReadOptions {
  double units_scale = 1.0;  ///< file coordinates * units_scale = metres (mm files: 0.001)
  std::size_t min_valid_points = 100;  ///< fewer finite points: InputError
  /// Depth PNG scans only: the intrinsics JSON (fx, fy, ppx, ppy in pixels, depth_scale in
  /// m per unit). Empty: SCAN_STEM.json beside the PNG, else intrinsics.json in its folder.
  std::string intrinsics_path;
};

/// Reads a PCD (ascii, binary, binary_compressed) or PLY file into a Cloud in metres, or a
/// 16-bit grey depth PNG with its intrinsics (ReadOptions::intrinsics_path) into an organized
/// Cloud in its camera frame (x right, y down, z forward, m; depth 0 is a NaN point; viewpoint
/// the origin; units_scale does not apply: depth_scale gives metres).
/// Organized PCDs (HEIGHT > 1) keep their layout; WIDTH N HEIGHT 1 and WIDTH 1 HEIGHT N are
/// unorganized. NaN points stay in place (a point with any NaN coordinate is all NaN). The
/// PCD VIEWPOINT translation becomes cloud.viewpoint (scaled); PLY scans get the origin.
/// Throws UsageError for a units_scale that is not positive and finite.
/// Throws InputError (one line) for: missing or unreadable file, unknown extension, a
/// malformed or truncated file, no x/y/z fields, no points, all points NaN, fewer than
/// min_valid_points finite points, or any infinite coordinate; for a PNG also: not 16-bit
/// grey, a header claiming more than 16384 pixels per side or than the file holds, intrinsics
/// missing, malformed, with a non-positive fx, fy or depth_scale, a size other than the
/// image's, or distortion.
GT_API Cloud read_cloud(const std::string& path, const ReadOptions& options = {});

/// Per-point annotations written beside the input points.
struct Annotations {
  const Normals* normals = nullptr;                   ///< cloud frame, unit, NaN = none
  const std::vector<float>* descriptor = nullptr;     ///< D (deg^2), NaN = none
  const std::vector<std::uint8_t>* groove = nullptr;  ///< 1 = groove
};

/// Binary PCD with fields `x y z normal_x normal_y normal_z descriptor groove` (groove as
/// uint8), the points of `cloud` in its order and shape (width, height, viewpoint).
/// Returns the file's bytes; write them with write_file_atomic. Throws InternalError when
/// the annotation sizes do not match the cloud or width * height != size.
GT_API std::string annotated_pcd_bytes(const Cloud& cloud, const Annotations& annotations);

/// Writes a plain XYZ binary PCD (organized if cloud is), e.g. for generated scans.
GT_API std::string pcd_bytes(const Cloud& cloud);

/// Writes `bytes` to `path` completely or not at all: a temporary file in the same
/// directory, flushed, then renamed over `path`. Throws InputError on failure.
GT_API void write_file_atomic(const std::string& path, const std::string& bytes);

}  // namespace groovetrace
