// PCD scans, the file a user hands to `run` and `eval`: the one PCD codec (io/pcd.cpp: ascii,
// binary and binary_compressed) through both entry points, read_cloud (a scan) and
// read_pcd_fields (eval's labels and annotated.pcd). The strict checks in front of PCL's
// decoder are what this exercises: PCL itself trusts the header (io/decode.hpp).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <groovetrace/cloud_io.hpp>

#include "fuzz_support.hpp"
#include "io/pcd.hpp"

namespace {

using groovetrace::fuzz::require;

// What read_cloud promises of a cloud it returns (cloud_io.hpp).
void check_cloud(const groovetrace::Cloud& cloud) {
  require(cloud.size() > 0 && cloud.x.size() == cloud.size() && cloud.z.size() == cloud.size(),
          "read_cloud returns x, y, z of one size");
  require(
      !cloud.organized() || static_cast<std::size_t>(cloud.width) * cloud.height == cloud.size(),
      "an organized cloud is width x height");
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const bool nan = std::isnan(cloud.x[i]);
    require(nan == std::isnan(cloud.y[i]) && nan == std::isnan(cloud.z[i]),
            "a point with any NaN coordinate is all NaN");
    require(nan || !groovetrace::beyond_max_coordinate(cloud.x[i], cloud.y[i], cloud.z[i]),
            "no coordinate beyond 1000 m, none infinite");
  }
  require(cloud.viewpoint.allFinite(), "the viewpoint is finite");
}

void check_table(const groovetrace::io::PcdTable& table) {
  require(table.names.size() == table.columns.size(), "one column per name");
  for (const auto& column : table.columns) {
    require(column.size() == table.size(), "every column has width x height values");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = groovetrace::fuzz::write_input("scan.pcd", data, size);
  groovetrace::fuzz::expect_answer([&] { check_cloud(groovetrace::read_cloud(path)); });
  groovetrace::fuzz::expect_answer(
      [&] { check_table(groovetrace::io::read_pcd_fields(path, {})); });
  return 0;
}
