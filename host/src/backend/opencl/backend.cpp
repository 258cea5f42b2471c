// The OpenCL backend: uploads a cloud, sets up its neighbour search (pixel windows for pinhole
// frames, a hashed grid built on the device otherwise) and runs the kernels of kernels/*.cl.
// Results come back in input order, as the CPU reference returns them. Environment, for
// experiments: GROOVETRACE_OPENCL_PROFILE (kernel times and the host side of grid downloads on
// stderr), GROOVETRACE_OPENCL_SEARCH=grid (grid search for organized frames too),
// GROOVETRACE_OPENCL_VW and GROOVETRACE_OPENCL_OPTIONS (see device_program.cpp).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <groovetrace/opencl.hpp>
#include <map>
#include <utility>

#include "cl_api.hpp"
#include "core/frame_intrinsics.hpp"
#include "device_program.hpp"
#include "host_blocks.hpp"
#include "memory_need.hpp"

namespace groovetrace::ocl {
namespace {

constexpr std::size_t kPad = kPointPad;
// Elements per work-item in the scan and reduction kernels.
constexpr int kScanChunk = 256;
constexpr int kSumChunk = 1024;
// The grid build's partition: at most this many buckets of consecutive slots (the streams a
// chunk of input appends to; a 16M-point cloud's bucket, about 0.6 MB, stays in a core's cache
// while it is sorted), and at most this many chunks of input, each a work-item (enough work
// groups to occupy a CPU's cores), of at least kMinChunk points.
constexpr std::uint32_t kMaxBuckets = 1024;
constexpr std::size_t kMaxChunks = 512;
constexpr std::size_t kMinChunk = 1024;
// The crease kernel brackets its quantile to this fraction of the radius (2 um at 10 mm).
constexpr float kCreaseTolerance = 2e-4f;

// The kernels' Grid (kernels/neighbors.cl), passed as its seven kernel arguments.
struct GridArgs {
  float inv_cell = 0;     // 1/m
  cl_uint slot_mask = 0;  // hashed: table size - 1; 0: dense box
  cl_int x0 = 0, y0 = 0, z0 = 0, nx = 0, ny = 0;
};

// A cloud on the device together with its neighbour search. The search kernels walk the
// input arrays of an organized frame (pixel order), else the valid points sorted by grid slot;
// "search order" below means that order.
struct Frame {
  std::size_t n = 0;  // input points
  bool organized = false;
  int width = 0, height = 0;
  float fx = 0, fy = 0, slack = 0;  // pixels (see FrameIntrinsics)
  cl::Buffer x, y, z;               // input order; released once the grid is built
  // Grid only.
  cl::Buffer sx, sy, sz;  // sorted valid points
  cl::Buffer order;       // sorted position -> input index
  cl::Buffer slot_start;  // slot s holds sorted positions [start[s], start[s + 1])
  GridArgs grid;
  int count = 0;  // valid points

  // Points in search order.
  std::size_t queries() const { return organized ? n : static_cast<std::size_t>(count); }
};

// Three device arrays in search order. Every point array on the device has kPad NaNs before
// and after the points.
struct Vec3Buffers {
  cl::Buffer x, y, z;
};

// Bytes of live buffers and their peak, for opencl_memory(). Buffers report their release
// through a destructor callback, which the driver may call from its own thread.
std::atomic<std::uint64_t> g_buffer_bytes{0}, g_buffer_peak{0};

// What a buffer's release gives back: its bytes, and its host block when it has one.
struct Allocation {
  std::size_t bytes = 0;
  void* host = nullptr;
  std::size_t capacity = 0;
};

void CL_CALLBACK buffer_released(cl_mem, void* data) {
  const Allocation* a = static_cast<const Allocation*>(data);
  g_buffer_bytes -= a->bytes;
  if (a->host != nullptr) give_host_block(a->host, a->capacity);
  delete a;
}

void buffer_allocated(cl::Buffer& b, const Allocation& a) {
  b.setDestructorCallback(buffer_released, new Allocation(a));
  const std::uint64_t now = g_buffer_bytes += a.bytes;
  std::uint64_t peak = g_buffer_peak.load();
  while (now > peak && !g_buffer_peak.compare_exchange_weak(peak, now)) {
  }
}

std::size_t round_up(std::size_t v, std::size_t m) { return (v + m - 1) / m * m; }

// "12.5 MiB", for one-line messages.
std::string bytes_text(std::uint64_t bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1024 && u < 4) v /= 1024, ++u;
  char text[32];
  std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.1f %s", v, units[u]);
  return text;
}

// Statuses of a device (or its driver's host side) out of memory.
bool out_of_memory(cl_int status) {
  return status == CL_MEM_OBJECT_ALLOCATION_FAILURE || status == CL_OUT_OF_RESOURCES ||
         status == CL_OUT_OF_HOST_MEMORY || status == CL_INVALID_BUFFER_SIZE;
}

std::uint32_t next_pow2(std::size_t v) {
  std::uint32_t p = 1;
  while (p < v) p <<= 1;
  return p;
}

class OpenClBackend final : public FeatureBackend {
 public:
  explicit OpenClBackend(std::shared_ptr<const DeviceProgram> program)
      : dp_(std::move(program)),
        profile_(std::getenv("GROOVETRACE_OPENCL_PROFILE") != nullptr),
        search_(std::getenv("GROOVETRACE_OPENCL_SEARCH") ? std::getenv("GROOVETRACE_OPENCL_SEARCH")
                                                         : ""),
        memory_(device_memory(dp_->device)),
        queue_(dp_->context, dp_->device, profile_ ? CL_QUEUE_PROFILING_ENABLE : 0),
        host_blocks_((dp_->device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0) {}

  std::string name() const override { return "opencl"; }
  std::string device() const override { return dp_->description; }

  Cloud smooth(const Cloud& cloud, const SmoothParams& params) override {
    return guarded(cloud.size(), [&] {
      if (cloud.size() == 0) return cloud;
      const Frame f = upload(cloud, params.radius);
      const Vec3Buffers out = search_buffers(f);
      if (f.organized) {
        launch("mls_organized", search_items(f), f.x, f.y, f.z, f.width, f.height, f.fx, f.fy,
               f.slack, params.radius, params.order, params.min_neighbors, out.x, out.y, out.z);
      } else {
        launch("mls_grid", search_items(f), f.sx, f.sy, f.sz, f.count, f.slot_start, f.grid,
               params.radius, params.order, params.min_neighbors, out.x, out.y, out.z);
      }
      Cloud result = cloud;
      // Invalid points stay as they came (the grid path never touches them).
      download(f, {{&out.x, &result.x}, {&out.y, &result.y}, {&out.z, &result.z}});
      return result;
    });
  }

  Normals normals(const Cloud& cloud, float radius, int min_neighbors) override {
    return guarded(cloud.size(), [&] {
      Normals out;
      out.resize(cloud.size());
      if (cloud.size() == 0) return out;
      const Frame f = upload(cloud, radius);
      const Vec3Buffers n = compute_normals(f, cloud.viewpoint, radius, min_neighbors);
      download(f, {{&n.x, &out.x}, {&n.y, &out.y}, {&n.z, &out.z}});
      return out;
    });
  }

  std::vector<float> descriptor(const Cloud& cloud, const Normals& normals, float radius,
                                const Eigen::Vector3f& u_b) override {
    return guarded(cloud.size(), [&] {
      if (normals.size() != cloud.size()) {
        throw InternalError("descriptor: " + std::to_string(normals.size()) + " normals for " +
                            std::to_string(cloud.size()) + " points");
      }
      std::vector<float> out(cloud.size(), NAN);
      if (cloud.size() == 0) return out;
      const Frame f = upload(cloud, radius);
      Vec3Buffers n;
      if (f.organized) {
        n = {padded(normals.x), padded(normals.y), padded(normals.z)};
      } else {
        const Vec3Buffers input = {padded(normals.x), padded(normals.y), padded(normals.z)};
        n = search_buffers(f);
        launch("gather3", f.queries(), input.x, input.y, input.z, f.order, f.count, n.x, n.y, n.z);
      }
      const cl::Buffer d = compute_descriptor(f, n, radius, u_b);
      download(f, {{&d, &out}});
      return out;
    });
  }

  CreaseMeasure crease(const Cloud& cloud, const CreaseParams& params) override {
    return guarded(cloud.size(), [&] {
      CreaseMeasure out;
      out.normals.resize(cloud.size());
      out.concavity.assign(cloud.size(), NAN);
      if (cloud.size() == 0) return out;
      // The grid search whatever the cloud's shape: the measure's ball (10 mm) would be a
      // window of hundreds of pixels.
      const Frame f = upload(cloud, params.radius, true);
      const Vec3Buffers n = search_buffers(f);
      const cl::Buffer c = nan_buffer(f.queries());
      const Eigen::Vector3f& vp = cloud.viewpoint;
      launch("crease_grid", search_items(f), f.sx, f.sy, f.sz, f.count, f.slot_start, f.grid,
             params.radius, params.own_radius, params.quantile, params.min_neighbors,
             kCreaseTolerance * params.radius, vp.x(), vp.y(), vp.z(), n.x, n.y, n.z, c);
      download(f, {{&n.x, &out.normals.x},
                   {&n.y, &out.normals.y},
                   {&n.z, &out.normals.z},
                   {&c, &out.concavity}});
      return out;
    });
  }

  FeatureSet features(const Cloud& cloud, float radius, int min_neighbors) override {
    return guarded(cloud.size(), [&] {
      FeatureSet out;
      out.normals.resize(cloud.size());
      out.benchmark_normal = Eigen::Vector3f::Constant(NAN);
      out.descriptor.assign(cloud.size(), NAN);
      if (cloud.size() == 0) return out;
      const Frame f = upload(cloud, radius);
      const Vec3Buffers n = compute_normals(f, cloud.viewpoint, radius, min_neighbors);
      out.benchmark_normal = sum_normals(n, f.queries());
      if (out.benchmark_normal.allFinite()) {
        const cl::Buffer d = compute_descriptor(f, n, radius, out.benchmark_normal);
        download(f, {{&d, &out.descriptor}});
      }
      download(f, {{&n.x, &out.normals.x}, {&n.y, &out.normals.y}, {&n.z, &out.normals.z}});
      return out;
    });
  }

 private:
  // Runs fn on a cloud of `points` points once it fits the device, turning OpenCL failures
  // into OpenClError (exit code 5; `auto` reruns the call on the CPU). A device out of memory
  // all the same (other processes' buffers, a driver's own limit) says so in the same terms.
  template <typename Fn>
  auto guarded(std::size_t points, Fn&& fn) -> decltype(fn()) {
    require_fits(points);
    try {
      auto result = fn();
      if (profile_) print_profile();
      return result;
    } catch (const cl::Error& e) {
      const std::string failed = std::string(e.what()) + " failed with " + status_name(e.err());
      if (out_of_memory(e.err())) {
        throw OpenClError("OpenCL device " + dp_->description +
                              " ran out of memory or resources on " + std::to_string(points) +
                              " points (" + failed + "; " + memory_text(points) + ")",
                          e.err());
      }
      throw OpenClError("OpenCL error on " + dp_->description + ": " + failed, e.err());
    }
  }

  // What a call on `points` points needs (memory_need.hpp) against what the device offers.
  std::string memory_text(std::size_t points) const {
    const MemoryNeed need = memory_need(points);
    return "needs up to " + bytes_text(need.total) + ", " + bytes_text(need.largest) +
           " in one buffer; the device offers " + bytes_text(memory_.global) + ", " +
           bytes_text(memory_.max_alloc) + " in one buffer" +
           (memory_.limited ? " (GROOVETRACE_OPENCL_MEMORY_LIMIT)" : "");
  }

  // A cloud too large for the device is refused before any buffer is made, rather than failing
  // halfway or being cut into tiles: a depth camera's frame (1280x720: at most 60 MiB) fits any
  // OpenCL device, and `auto` runs a larger cloud on the CPU.
  void require_fits(std::size_t points) const {
    // Kernels index with 32-bit ints, and the grid table holds 2 slots per point.
    if (points >= (std::size_t{1} << 30)) {
      throw OpenClError("the OpenCL backend takes fewer than 2^30 points per cloud, not " +
                            std::to_string(points) + "; --backend cpu runs it",
                        0);
    }
    const MemoryNeed need = memory_need(points);
    if (need.total <= memory_.global && need.largest <= memory_.max_alloc) return;
    throw OpenClError("OpenCL device " + dp_->description + " has too little memory for " +
                          std::to_string(points) + " points: " + memory_text(points) +
                          "; --backend cpu runs it",
                      0);
  }

  static int as_int(std::size_t v) { return static_cast<int>(v); }

  cl::Kernel& kernel(const std::string& name) {
    auto it = kernels_.find(name);
    if (it == kernels_.end()) {
      it = kernels_.emplace(name, Launchable{cl::Kernel(dp_->program, name.c_str()), 0}).first;
      // The work-group size is the device's to say: the largest multiple of the preferred
      // size up to 128 (enough to amortise scheduling on a CPU, a few warps on a GPU).
      cl::Kernel& k = it->second.kernel;
      const std::size_t max_size = k.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(dp_->device);
      const std::size_t multiple = std::max<std::size_t>(
          1, k.getWorkGroupInfo<CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE>(dp_->device));
      std::size_t local = std::min<std::size_t>(max_size, 128);
      local = std::max(multiple, local / multiple * multiple);
      it->second.local = std::min(local, max_size);
    }
    return it->second.kernel;
  }

  template <typename T>
  static void set_arg(cl::Kernel& k, cl_uint& index, const T& value) {
    k.setArg(index++, value);
  }
  static void set_arg(cl::Kernel& k, cl_uint& index, const GridArgs& g) {
    k.setArg(index++, g.inv_cell);
    k.setArg(index++, g.slot_mask);
    k.setArg(index++, g.x0);
    k.setArg(index++, g.y0);
    k.setArg(index++, g.z0);
    k.setArg(index++, g.nx);
    k.setArg(index++, g.ny);
  }

  template <typename... Args>
  void launch(const std::string& name, std::size_t items, const Args&... args) {
    cl::Kernel& k = kernel(name);
    cl_uint index = 0;
    (set_arg(k, index, args), ...);
    if (items == 0) return;
    const std::size_t local = kernels_.at(name).local;
    cl::Event done;
    queue_.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(round_up(items, local)),
                                cl::NDRange(local), nullptr, profile_ ? &done : nullptr);
    if (profile_) profiled_.emplace_back(name, done);
  }

  // GROOVETRACE_OPENCL_PROFILE set: each kernel's device time, then each grid download's host
  // time, on stderr after every call.
  void print_profile() {
    queue_.finish();
    for (const auto& [name, event] : profiled_) {
      const double ms = static_cast<double>(event.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                                            event.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
                        1e-6;
      std::fprintf(stderr, "groovetrace: opencl %-22s %9.2f ms\n", name.c_str(), ms);
    }
    profiled_.clear();
    for (const auto& [name, ms] : host_profiled_) {
      std::fprintf(stderr, "groovetrace: opencl %-22s %9.2f ms\n", name.c_str(), ms);
    }
    host_profiled_.clear();
  }

  cl::Buffer buffer(std::size_t elements, std::size_t element_size = sizeof(float)) {
    Allocation a;
    a.bytes = std::max<std::size_t>(elements, 1) * element_size;
    if (!host_blocks_) {
      cl::Buffer b(dp_->context, CL_MEM_READ_WRITE, a.bytes);
      buffer_allocated(b, a);
      return b;
    }
    a.host = take_host_block(a.bytes, &a.capacity);
    try {
      cl::Buffer b(dp_->context, CL_MEM_READ_WRITE | CL_MEM_USE_HOST_PTR, a.bytes, a.host);
      buffer_allocated(b, a);
      return b;
    } catch (...) {
      give_host_block(a.host, a.capacity);
      throw;
    }
  }

  // A device point array holding v.
  cl::Buffer padded(const std::vector<float>& v) {
    cl::Buffer b = buffer(v.size() + 2 * kPad);
    constexpr std::size_t pad_bytes = kPad * sizeof(float);
    queue_.enqueueFillBuffer(b, NAN, 0, pad_bytes);
    if (!v.empty()) {
      queue_.enqueueWriteBuffer(b, CL_FALSE, pad_bytes, v.size() * sizeof(float), v.data());
    }
    queue_.enqueueFillBuffer(b, NAN, pad_bytes + v.size() * sizeof(float), pad_bytes);
    return b;
  }

  // A device point array of `elements` NaNs.
  cl::Buffer nan_buffer(std::size_t elements) {
    cl::Buffer b = buffer(elements + 2 * kPad);
    queue_.enqueueFillBuffer(b, NAN, 0, (elements + 2 * kPad) * sizeof(float));
    return b;
  }

  // Work-items of a search kernel: each owns VW queries (a row's last one fewer).
  std::size_t search_items(const Frame& f) const {
    const std::size_t vw = static_cast<std::size_t>(dp_->vector_width);
    if (f.organized) return static_cast<std::size_t>(f.height) * ((f.width + vw - 1) / vw);
    return (static_cast<std::size_t>(f.count) + vw - 1) / vw;
  }

  Vec3Buffers search_buffers(const Frame& f) {
    const std::size_t m = f.queries();
    return {nan_buffer(m), nan_buffer(m), nan_buffer(m)};
  }

  // `grid`: the grid search even for a pinhole frame.
  Frame upload(const Cloud& cloud, float radius, bool grid = false) {
    require_in_range(cloud);  // the kernels' cell keys are 32-bit ints
    Frame f;
    f.n = cloud.size();
    f.x = padded(cloud.x);
    f.y = padded(cloud.y);
    f.z = padded(cloud.z);
    if (cloud.organized() && search_ != "grid" && !grid) {
      const FrameIntrinsics k = estimate_intrinsics(cloud);
      if (k.pinhole) {
        f.organized = true;
        f.width = static_cast<int>(cloud.width);
        f.height = static_cast<int>(cloud.height);
        f.fx = k.fx;
        f.fy = k.fy;
        f.slack = k.slack;
        return f;
      }
    }
    build_grid(f, radius);
    return f;
  }

  // Exclusive scan of in[0, n) into out[0, n], out[n] = total.
  void scan(const cl::Buffer& in, std::size_t n, const cl::Buffer& out) {
    if (n <= static_cast<std::size_t>(kScanChunk)) {
      launch("scan_serial", 1, in, as_int(n), out);
      return;
    }
    const std::size_t chunks = (n + kScanChunk - 1) / kScanChunk;
    const cl::Buffer sums = buffer(chunks, sizeof(cl_uint));
    const cl::Buffer offsets = buffer(chunks + 1, sizeof(cl_uint));
    launch("scan_chunk_sums", chunks, in, as_int(n), kScanChunk, sums);
    scan(sums, chunks, offsets);
    launch("scan_chunk_apply", chunks, in, as_int(n), kScanChunk, offsets, out);
  }

  // The grid's cell numbering: a dense box of cells when the cloud's bounding box holds no
  // more cells than points (a surface scan of any size), else a hash table with at least one
  // slot per point (a cloud spread over a large volume). Either way the table costs at most 8
  // bytes per point. Returns the table size.
  std::uint32_t plan_grid(Frame& f, float cell) {
    f.grid = GridArgs();
    f.grid.inv_cell = 1.0f / cell;
    constexpr int kChunk = 4096;
    const std::size_t chunks = (f.n + kChunk - 1) / kChunk;
    const cl::Buffer partial = buffer(6 * chunks);
    launch("bounds", chunks, f.x, f.y, f.z, as_int(f.n), kChunk, partial);
    std::vector<float> b(6 * chunks);
    queue_.enqueueReadBuffer(partial, CL_TRUE, 0, b.size() * sizeof(float), b.data());
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
    for (std::size_t c = 0; c < chunks; ++c) {
      lo = lo.cwiseMin(Eigen::Vector3f(b[6 * c], b[6 * c + 1], b[6 * c + 2]));
      hi = hi.cwiseMax(Eigen::Vector3f(b[6 * c + 3], b[6 * c + 4], b[6 * c + 5]));
    }
    const std::size_t budget = std::max<std::size_t>(f.n, 4096);
    if ((lo.array() <= hi.array()).all()) {
      // Cells as the kernels compute them (cell_of: floor of a float product), with a margin
      // of one cell on every side for the stencil.
      Eigen::Array3d cells;
      for (int a = 0; a < 3; ++a) {
        const double c_lo = std::floor(lo[a] * f.grid.inv_cell);
        const double c_hi = std::floor(hi[a] * f.grid.inv_cell);
        cells[a] = c_hi - c_lo + 3;
        (a == 0 ? f.grid.x0 : a == 1 ? f.grid.y0 : f.grid.z0) = static_cast<cl_int>(c_lo) - 1;
      }
      if (cells.prod() <= static_cast<double>(budget)) {
        f.grid.nx = static_cast<cl_int>(cells[0]);
        f.grid.ny = static_cast<cl_int>(cells[1]);
        return static_cast<std::uint32_t>(cells.prod());
      }
    }
    const std::uint32_t table = next_pow2(budget);
    f.grid.slot_mask = table - 1;
    f.grid.x0 = f.grid.y0 = f.grid.z0 = 0;
    return table;
  }

  // Sorts the valid points by the slots of the cells of edge `cell` (m) in two stable counting
  // sorts (kernels/grid_build.cl): into buckets of consecutive slots, then each bucket by slot.
  void build_grid(Frame& f, float cell) {
    const std::uint32_t table = plan_grid(f, cell);
    int bucket_shift = 0;
    while (((table - 1) >> bucket_shift) + 1 > kMaxBuckets) ++bucket_shift;
    const std::uint32_t buckets = ((table - 1) >> bucket_shift) + 1;
    const std::size_t chunks =
        std::clamp<std::size_t>((f.n + kMinChunk - 1) / kMinChunk, 1, kMaxChunks);
    const int chunk = as_int((f.n + chunks - 1) / chunks);
    const cl::Buffer offsets = buffer(chunks * buckets, sizeof(cl_uint));
    launch("grid_partition_count", chunks, f.x, f.y, f.z, as_int(f.n), chunk, f.grid, bucket_shift,
           as_int(buckets), offsets);
    const cl::Buffer totals = buffer(buckets, sizeof(cl_uint));
    launch("partition_offsets", buckets, offsets, as_int(chunks), as_int(buckets), totals);
    const cl::Buffer bucket_start = buffer(buckets + 1, sizeof(cl_uint));
    scan(totals, buckets, bucket_start);
    cl_uint count = 0;
    queue_.enqueueReadBuffer(bucket_start, CL_TRUE, buckets * sizeof(cl_uint), sizeof(cl_uint),
                             &count);
    f.count = static_cast<int>(count);
    const cl::Buffer partitioned = buffer(count, sizeof(cl_float4));
    launch("grid_partition", chunks, f.x, f.y, f.z, as_int(f.n), chunk, f.grid, bucket_shift,
           as_int(buckets), bucket_start, offsets, partitioned);
    // The search walks the sorted copy; the input order is only needed to build it. The driver
    // frees a buffer once the commands using it are done: waiting for them keeps the input,
    // the partitioned copy and the sorted copy from being held all at once.
    f.x = f.y = f.z = cl::Buffer();
    queue_.finish();
    const cl::Buffer slot_fill = buffer(table, sizeof(cl_uint));
    const cl::Buffer partitioned_slot = buffer(count, sizeof(cl_uint));
    f.slot_start = buffer(table + 1, sizeof(cl_uint));
    f.sx = nan_buffer(count);
    f.sy = nan_buffer(count);
    f.sz = nan_buffer(count);
    f.order = buffer(count, sizeof(cl_int));
    launch("grid_bucket_sort", buckets, partitioned, bucket_start, f.grid, bucket_shift,
           as_int(buckets), as_int(table), slot_fill, partitioned_slot, f.slot_start, f.sx, f.sy,
           f.sz, f.order);
    queue_.finish();
  }

  Vec3Buffers compute_normals(const Frame& f, const Eigen::Vector3f& vp, float radius,
                              int min_neighbors) {
    const Vec3Buffers n = search_buffers(f);
    if (f.organized) {
      launch("normals_organized", search_items(f), f.x, f.y, f.z, f.width, f.height, f.fx, f.fy,
             f.slack, radius, vp.x(), vp.y(), vp.z(), min_neighbors, n.x, n.y, n.z);
    } else {
      launch("normals_grid", search_items(f), f.sx, f.sy, f.sz, f.count, f.slot_start, f.grid,
             radius, vp.x(), vp.y(), vp.z(), min_neighbors, n.x, n.y, n.z);
    }
    return n;
  }

  // u_b = normalize(sum of the valid normals): per-chunk partial sums on the device, their
  // total in double here.
  Eigen::Vector3f sum_normals(const Vec3Buffers& n, std::size_t count) {
    const std::size_t chunks = std::max<std::size_t>(1, (count + kSumChunk - 1) / kSumChunk);
    const cl::Buffer partial = buffer(3 * chunks);
    launch("sum_normals", chunks, n.x, n.y, n.z, as_int(count), kSumChunk, partial);
    std::vector<float> host(3 * chunks, 0.0f);
    if (count > 0) {
      queue_.enqueueReadBuffer(partial, CL_TRUE, 0, host.size() * sizeof(float), host.data());
    }
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t c = 0; c < chunks; ++c) {
      sum += Eigen::Vector3d(host[3 * c], host[3 * c + 1], host[3 * c + 2]);
    }
    const double len = sum.norm();
    if (!(len > 0)) return Eigen::Vector3f::Constant(NAN);
    return (sum / len).cast<float>();
  }

  // D per point in search order, from normals in search order.
  cl::Buffer compute_descriptor(const Frame& f, const Vec3Buffers& n, float radius,
                                const Eigen::Vector3f& u_b) {
    const std::size_t m = f.queries();
    const cl::Buffer beta = nan_buffer(m);
    const std::size_t vw = static_cast<std::size_t>(dp_->vector_width);
    launch("global_angles", (m + vw - 1) / vw, n.x, n.y, n.z, as_int(m), u_b.x(), u_b.y(), u_b.z(),
           beta);
    const cl::Buffer d = nan_buffer(m);
    if (f.organized) {
      launch("descriptor_organized", search_items(f), f.x, f.y, f.z, n.x, n.y, n.z, beta, f.width,
             f.height, f.fx, f.fy, f.slack, radius, d);
    } else {
      launch("descriptor_grid", search_items(f), f.sx, f.sy, f.sz, n.x, n.y, n.z, beta, f.count,
             f.slot_start, f.grid, radius, d);
    }
    return d;
  }

  // Reads search-order arrays into input-order host arrays. Organized frames are in pixel
  // order already. For the grid, the sorted results are mapped (no copy on a CPU device) and
  // scattered through `order`; points outside the search keep their host values.
  void download(const Frame& f,
                const std::vector<std::pair<const cl::Buffer*, std::vector<float>*>>& arrays) {
    const std::size_t offset = kPad * sizeof(float);
    if (f.organized) {
      for (std::size_t a = 0; a < arrays.size(); ++a) {
        queue_.enqueueReadBuffer(*arrays[a].first, a + 1 == arrays.size() ? CL_TRUE : CL_FALSE,
                                 offset, f.n * sizeof(float), arrays[a].second->data());
      }
      return;
    }
    if (f.count == 0) return;
    if (profile_) queue_.finish();  // the kernels before are not the download's time
    const auto start = std::chrono::steady_clock::now();
    const std::size_t count = static_cast<std::size_t>(f.count);
    const int* order = static_cast<const int*>(
        queue_.enqueueMapBuffer(f.order, CL_TRUE, CL_MAP_READ, 0, count * sizeof(int)));
    for (const auto& [buffer, host] : arrays) {
      const float* sorted = static_cast<const float*>(
          queue_.enqueueMapBuffer(*buffer, CL_TRUE, CL_MAP_READ, offset, count * sizeof(float)));
      float* out = host->data();
      for (std::size_t k = 0; k < count; ++k) out[order[k]] = sorted[k];
      queue_.enqueueUnmapMemObject(*buffer, const_cast<float*>(sorted));
    }
    queue_.enqueueUnmapMemObject(f.order, const_cast<int*>(order));
    queue_.finish();
    if (profile_) {
      const std::chrono::duration<double, std::milli> ms = std::chrono::steady_clock::now() - start;
      host_profiled_.emplace_back("download_host", ms.count());
    }
  }

  struct Launchable {
    cl::Kernel kernel;
    std::size_t local;
  };

  std::shared_ptr<const DeviceProgram> dp_;
  bool profile_;
  // "grid" (GROOVETRACE_OPENCL_SEARCH): organized frames too use the grid search, to compare.
  std::string search_;
  DeviceMemory memory_;  // what the device offers, or GROOVETRACE_OPENCL_MEMORY_LIMIT
  cl::CommandQueue queue_;
  std::vector<std::pair<std::string, cl::Event>> profiled_;
  std::vector<std::pair<std::string, double>> host_profiled_;  // ms
  std::map<std::string, Launchable> kernels_;
  // A CPU device's buffers live in recycled host blocks (host_blocks.hpp); a GPU's stay the
  // driver's own device memory.
  bool host_blocks_;
};

}  // namespace
}  // namespace groovetrace::ocl

namespace groovetrace {

OpenClMemory opencl_memory(bool reset_peak) {
  OpenClMemory m;
  m.current = ocl::g_buffer_bytes.load();
  m.peak = std::max(ocl::g_buffer_peak.load(), m.current);
  if (reset_peak) ocl::g_buffer_peak = m.current;
  return m;
}

std::unique_ptr<FeatureBackend> make_opencl_backend(const std::string& selector) {
  try {
    const cl::Device device = ocl::select_device(selector);
    return std::make_unique<ocl::OpenClBackend>(ocl::program_for(device));
  } catch (const cl::Error& e) {
    throw OpenClError(
        std::string("OpenCL: ") + e.what() + " failed with " + ocl::status_name(e.err()), e.err());
  }
}

}  // namespace groovetrace
