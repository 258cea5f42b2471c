// Depth PNG scans (io/depth_png.cpp): the PNG's bytes through read_cloud with fixed intrinsics
// (GT_FUZZ_PART "png"), or the intrinsics JSON with a fixed small depth PNG ("intrinsics").
// Our header checks run before libpng sees the file; libpng's errors must come back as one
// InputError line, never a longjmp through C++ frames, and a huge header never allocates.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <groovetrace/cloud_io.hpp>
#include <string>

#include "depth_png_seed.hpp"
#include "fuzz_support.hpp"

namespace {

using groovetrace::fuzz::require;

constexpr const char* kIntrinsics =
    R"({"fx": 60, "fy": 55, "ppx": 3.5, "ppy": 2.5, "depth_scale": 0.001})";

void check_cloud(const groovetrace::Cloud& cloud) {
  require(cloud.organized() && static_cast<std::size_t>(cloud.width) * cloud.height == cloud.size(),
          "a depth image is an organized cloud, width x height");
  require(cloud.viewpoint.isZero(), "a depth image's viewpoint is the camera's origin");
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const bool nan = std::isnan(cloud.z[i]);
    require(nan == std::isnan(cloud.x[i]) && nan == std::isnan(cloud.y[i]),
            "a pixel without depth is all NaN");
    require(nan || cloud.z[i] > 0, "depth is in front of the camera");
    require(nan || !groovetrace::beyond_max_coordinate(cloud.x[i], cloud.y[i], cloud.z[i]),
            "no coordinate beyond 1000 m");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string part = GT_FUZZ_PART;
  std::string png, json;
  if (part == "png") {
    png = groovetrace::fuzz::write_input("scan.png", data, size);
    json =
        groovetrace::fuzz::write_input("k.json", reinterpret_cast<const std::uint8_t*>(kIntrinsics),
                                       std::string(kIntrinsics).size());
  } else {
    const std::string& bytes = groovetrace::fuzz::small_depth_png();
    png = groovetrace::fuzz::write_input(
        "scan.png", reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    json = groovetrace::fuzz::write_input("k.json", data, size);
  }
  groovetrace::ReadOptions options;
  options.intrinsics_path = json;
  options.min_valid_points = 1;
  groovetrace::fuzz::expect_answer([&] { check_cloud(groovetrace::read_cloud(png, options)); });
  return 0;
}
