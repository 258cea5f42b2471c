#pragma once
// The device memory the OpenCL backend holds at most at once during one call, as a function of
// the cloud's size: the backend compares it with the device's limits before it makes any
// buffer. No OpenCL header, so the tests can check it against the buffers' measured peak
// (tests/backend/test_opencl_memory.cpp) in any build.

#include <cstddef>
#include <cstdint>

namespace groovetrace::ocl {

/// Bytes a call needs on the device.
struct MemoryNeed {
  std::uint64_t total = 0;    ///< every buffer alive at once
  std::uint64_t largest = 0;  ///< the largest single buffer
};

/// The bound for a cloud of `points` points (valid or not; backend.cpp's buffers, per point):
/// the sorted grid keeps x, y, z, the input index and up to 2 table slots (24 B); on top of it,
/// the descriptor holds the normals in input and in search order, the angles and D (32 B),
/// more than any other call. Building the grid holds the partitioned float4 copy, the sorted
/// copy, the slot table twice and each point's slot (52 B) and per-chunk counts (at most 512
/// chunks x 1024 buckets x 4 B = 2 MiB, the largest buffer of a small cloud). 64 B and 4 MiB
/// cover both with the arrays' pads, the partial sums and the smallest table (4096 slots).
constexpr MemoryNeed memory_need(std::size_t points) {
  if (points == 0) return {};
  const std::uint64_t n = points;
  constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
  return {64 * n + 4 * kMiB, 16 * n + 2 * kMiB};
}

}  // namespace groovetrace::ocl
