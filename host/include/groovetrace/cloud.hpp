#pragma once
// A point cloud as plain structure-of-arrays data, the unit every stage consumes.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <groovetrace/export.hpp>
#include <vector>

namespace groovetrace {

/// Points in one frame (camera frame for sensor scans, or a robot base frame), in metres.
/// Invalid returns are NaN and stay in place, so index i always means the same input point.
/// Organized frames keep the sensor's row-major layout: index = row * width + col.
struct GT_API Cloud {
  std::vector<float> x, y, z;  ///< metres, in the cloud's frame
  std::uint32_t width = 0;     ///< points per row (== size() when unorganized)
  std::uint32_t height = 1;    ///< rows; 1 means unorganized
  /// Sensor origin in the cloud's frame (metres); normals are oriented towards it.
  Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();

  std::size_t size() const { return x.size(); }
  bool organized() const { return height > 1; }
  bool valid(std::size_t i) const {
    return std::isfinite(x[i]) && std::isfinite(y[i]) && std::isfinite(z[i]);
  }
  Eigen::Vector3f point(std::size_t i) const { return {x[i], y[i], z[i]}; }
  void resize(std::size_t n) {
    x.resize(n);
    y.resize(n);
    z.resize(n);
  }
  std::size_t count_valid() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < size(); ++i) n += valid(i) ? 1 : 0;
    return n;
  }
};

/// The farthest a scan's point may lie from its frame's origin in any coordinate (m). A depth
/// camera's returns end within ten metres and a robot cell within a few; beyond a kilometre a
/// coordinate is a corrupt file or a wrong unit, and its voxel keys would overflow the
/// integers the grids index with (a point at 1e8 m crashed the OpenCL crease kernel).
constexpr double kMaxCoordinate = 1000.0;

/// Whether a point lies beyond +-kMaxCoordinate in any coordinate (an infinity does, NaN not).
inline bool beyond_max_coordinate(float x, float y, float z) {
  return std::abs(x) > kMaxCoordinate || std::abs(y) > kMaxCoordinate ||
         std::abs(z) > kMaxCoordinate;
}

/// Throws InputError (exit 3) naming the first valid point of `cloud` with a coordinate beyond
/// +-kMaxCoordinate, and how many there are. Every entry that grids a cloud calls it: the
/// readers, detect_robust and the backends.
GT_API void require_in_range(const Cloud& cloud);

/// Unit surface normals per point, in the cloud's frame; NaN where a point has too few
/// neighbours (such points are never groove).
struct GT_API Normals {
  std::vector<float> x, y, z;
  std::size_t size() const { return x.size(); }
  bool valid(std::size_t i) const { return std::isfinite(x[i]); }
  Eigen::Vector3f normal(std::size_t i) const { return {x[i], y[i], z[i]}; }
  void resize(std::size_t n) {
    x.assign(n, NAN);
    y.assign(n, NAN);
    z.assign(n, NAN);
  }
};

}  // namespace groovetrace
