#pragma once
// Host memory for the buffers of a CPU device, recycled across calls. A CPU driver backs each
// buffer with fresh pages from the OS, and past the allocator's mmap threshold (32 MB, so
// from about 8M points) every call pays their page faults and zeroing again: 0.018 faults
// per point and call, 20-30 ns per point of a 16M-point cloud (bench_scaling). Blocks come
// back when the driver releases their buffer and are handed out again for a size that fits.

#include <cstddef>

namespace groovetrace::ocl {

/// Page-aligned host memory of at least `bytes` (at most 1/8 more), from the blocks given back
/// or new. Throws std::bad_alloc.
void* take_host_block(std::size_t bytes, std::size_t* capacity);

/// Returns a block from take_host_block (`capacity` as it reported). Kept for reuse while the
/// kept blocks total at most 2 GiB, else freed. Thread-safe: drivers release buffers from
/// their own threads.
void give_host_block(void* block, std::size_t capacity);

}  // namespace groovetrace::ocl
