// PLY scans through read_cloud: our structural checks (io/ply.cpp: element counts against the
// file size, obj_info grids, range_grid refused) and then PCL's PLYReader, which reads the
// file again by path. Anything the checks let through that PCL then mishandles is a finding.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <groovetrace/cloud_io.hpp>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = groovetrace::fuzz::write_input("scan.ply", data, size);
  groovetrace::fuzz::expect_answer([&] {
    const groovetrace::Cloud cloud = groovetrace::read_cloud(path);
    groovetrace::fuzz::require(cloud.count_valid() > 0 && cloud.viewpoint.allFinite(),
                               "read_cloud returns valid points and a finite viewpoint");
  });
  return 0;
}
