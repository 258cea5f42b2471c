// read_cloud: a PCD or PLY scan, decoded (io/pcd.cpp, io/ply.cpp), as a Cloud in metres.

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <mutex>
#include <string>
#include <vector>

#include "io/decode.hpp"
#include "io/depth_png.hpp"
#include "io/text.hpp"

namespace groovetrace {
namespace io {
namespace {

std::mutex& quiet_mutex() {
  static std::mutex m;
  return m;
}
int quiet_users = 0;  // guarded by quiet_mutex()
pcl::console::VERBOSITY_LEVEL quiet_saved = pcl::console::L_INFO;

Cloud to_cloud(const Decoded& decoded, double scale, std::size_t min_valid) {
  const pcl::PCLPointCloud2& blob = decoded.blob;
  std::vector<std::string> names;
  for (const auto& f : blob.fields) names.push_back(f.name);
  require_fields(names, {"x", "y", "z"});
  const std::size_t n = static_cast<std::size_t>(blob.width) * blob.height;
  if (n == 0) reject("has no points");

  const pcl::PCLPointField* fields[3] = {&blob_field(blob, "x"), &blob_field(blob, "y"),
                                         &blob_field(blob, "z")};
  Cloud cloud;
  cloud.resize(n);
  // A single column is a list of points, not an image one pixel wide.
  const bool organized = blob.height > 1 && blob.width > 1;
  cloud.width = organized ? blob.width : static_cast<std::uint32_t>(n);
  cloud.height = organized ? blob.height : 1;
  // The sensor's origin is bounded as the points are: a huge one (1e30 m, or 1e300 m, which
  // is inf as a float) turned every normal towards +-x and gave a garbage result, exit 0.
  const Eigen::Vector3d viewpoint = decoded.origin.head<3>().cast<double>() * scale;
  if ((viewpoint.array().abs() > kMaxCoordinate).any()) {
    reject(
        "has its VIEWPOINT beyond 1000 m of the frame's origin (a corrupt scan, or a wrong "
        "--units)");
  }
  cloud.viewpoint = viewpoint.cast<float>();

  std::vector<float>* out[3] = {&cloud.x, &cloud.y, &cloud.z};
  std::size_t infinite = 0, beyond = 0;
  // Both readers return rows back to back (the data sizes were checked), so point i of the
  // file is at i * point_step whatever row_step says.
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* point = blob.data.data() + i * blob.point_step;
    float v[3];
    for (int k = 0; k < 3; ++k) {
      v[k] =
          static_cast<float>(field_value(point + fields[k]->offset, fields[k]->datatype) * scale);
    }
    // Coordinates beyond float range become inf here and are rejected with the infinities.
    if (std::isinf(v[0]) || std::isinf(v[1]) || std::isinf(v[2])) {
      ++infinite;
    } else if (beyond_max_coordinate(v[0], v[1], v[2])) {
      ++beyond;
    }
    // A point missing any coordinate is no point at all; downstream tests x alone.
    if (std::isnan(v[0]) || std::isnan(v[1]) || std::isnan(v[2])) v[0] = v[1] = v[2] = NAN;
    for (int k = 0; k < 3; ++k) (*out[k])[i] = v[k];
  }
  if (infinite > 0) {
    reject("has " + count_of(infinite, "point") + " with infinite coordinates");
  }
  if (beyond > 0) {
    reject("has " + count_of(beyond, "point") + " beyond 1000 m of the frame's origin (a corrupt " +
           "scan, or a wrong --units)");
  }
  const std::size_t valid = cloud.count_valid();
  if (valid == 0) reject("has no valid points (all " + std::to_string(n) + " are NaN)");
  if (valid < min_valid) {
    reject("has only " + count_of(valid, "valid point") + " (at least " +
           std::to_string(min_valid) + " needed)");
  }
  return cloud;
}

}  // namespace

PclQuiet::PclQuiet() {
  std::lock_guard<std::mutex> lock(quiet_mutex());
  if (quiet_users++ == 0) {
    quiet_saved = pcl::console::getVerbosityLevel();
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  }
}

PclQuiet::~PclQuiet() {
  std::lock_guard<std::mutex> lock(quiet_mutex());
  if (--quiet_users == 0) pcl::console::setVerbosityLevel(quiet_saved);
}

double field_value(const std::uint8_t* p, std::uint8_t datatype) {
  auto get = [p](auto v) {
    std::memcpy(&v, p, sizeof(v));
    return static_cast<double>(v);
  };
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return get(std::int8_t{});
    case pcl::PCLPointField::UINT8:
      return get(std::uint8_t{});
    case pcl::PCLPointField::INT16:
      return get(std::int16_t{});
    case pcl::PCLPointField::UINT16:
      return get(std::uint16_t{});
    case pcl::PCLPointField::INT32:
      return get(std::int32_t{});
    case pcl::PCLPointField::UINT32:
      return get(std::uint32_t{});
    case pcl::PCLPointField::INT64:
      return get(std::int64_t{});
    case pcl::PCLPointField::UINT64:
      return get(std::uint64_t{});
    case pcl::PCLPointField::FLOAT32:
      return get(float{});
    default:
      return get(double{});
  }
}

const pcl::PCLPointField& blob_field(const pcl::PCLPointCloud2& blob, const std::string& name) {
  for (const auto& f : blob.fields) {
    if (f.name != name) continue;
    const int size = pcl::getFieldSize(f.datatype);
    if (size == 0 || f.count == 0 ||
        f.offset + static_cast<std::uint64_t>(size) > blob.point_step) {
      reject("field " + shown(name, 40) + " has an unsupported type or layout");
    }
    return f;
  }
  reject("has no " + shown(name, 40) + " field");  // callers check first; every path throws
}

}  // namespace io

Cloud read_cloud(const std::string& path, const ReadOptions& options) {
  if (!(std::isfinite(options.units_scale) && options.units_scale > 0)) {
    throw UsageError("units scale must be a positive number, got " +
                     std::to_string(options.units_scale));
  }
  const std::string ext = io::lower_extension(path);
  if (ext != ".pcd" && ext != ".ply" && ext != ".png") {
    const std::string what = ext.empty() ? "no file extension" : "'" + io::shown(ext, 20) + "'";
    throw InputError("cannot read " + io::shown(path) + ": unsupported file type (" + what +
                     "; expected .pcd, .ply or a 16-bit depth .png)");
  }
  const std::string content = io::read_all(path);
  // A depth image's unit is its intrinsics' depth_scale: units_scale does not apply.
  if (ext == ".png") {
    return io::read_depth_png(path, content, options.intrinsics_path, options.min_valid_points);
  }
  try {
    const io::Decoded decoded =
        ext == ".pcd" ? io::decode_pcd(content, {"x", "y", "z"}) : io::decode_ply(path, content);
    return io::to_cloud(decoded, options.units_scale, options.min_valid_points);
  } catch (const io::Rejected& r) {
    throw InputError(io::rejected_message(path, r));
  }
}

}  // namespace groovetrace
