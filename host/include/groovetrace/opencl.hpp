#pragma once
// The OpenCL backend: device discovery, device choice and its typed errors. The kernels are
// kernels/*.cl, compiled into the library; each device's program is built once per process.
// No OpenCL header is needed to use this API. Environment variables, for diagnosis:
// GROOVETRACE_OPENCL_PROFILE=1 prints each kernel's device time to stderr;
// GROOVETRACE_OPENCL_SEARCH=grid uses the grid search for organized frames too;
// GROOVETRACE_OPENCL_VW=1|2|4|8|16 sets the queries per work-item (default 16 on CPU devices,
// 1 on GPUs); GROOVETRACE_OPENCL_OPTIONS adds OpenCL compiler options;
// GROOVETRACE_OPENCL_MEMORY_LIMIT=BYTES lowers the device memory the backend believes it has
// (a test hook: a cloud too large for the device).

#include <cstdint>
#include <groovetrace/error.hpp>
#include <groovetrace/export.hpp>
#include <groovetrace/features.hpp>
#include <memory>
#include <string>
#include <vector>

namespace groovetrace {

/// One OpenCL device as the installed drivers report it.
struct OpenClDevice {
  int index = 0;          ///< position in list_opencl_devices(): what `--device N` selects
  std::string platform;   ///< platform name, e.g. "Portable Computing Language"
  std::string name;       ///< device name, e.g. "pthread-skylake-avx512-AMD EPYC"
  std::string type;       ///< "gpu", "cpu", "accelerator" or "other"
  std::string c_version;  ///< OpenCL C version, e.g. "OpenCL C 1.2 PoCL"
  unsigned compute_units = 0;
  std::uint64_t global_memory_bytes = 0;
};

/// Every device of every platform, platforms in driver order. Empty when no OpenCL driver is
/// installed or the build has no OpenCL; never throws.
GT_API std::vector<OpenClDevice> list_opencl_devices();

/// An OpenCL call or program build failed (exit code 5). what() is one line; for a failed
/// program build, build_log() holds the compiler's full output.
class GT_API OpenClError : public InternalError {
 public:
  OpenClError(const std::string& message, int status, std::string build_log = {})
      : InternalError(message), status_(status), build_log_(std::move(build_log)) {}
  /// The OpenCL status code (CL_...), 0 when there is none (e.g. no platform).
  int status() const { return status_; }
  const std::string& build_log() const { return build_log_; }

 private:
  int status_;
  std::string build_log_;
};

/// Programs built by this process so far: each device's kernels are built once, on its first
/// backend, and shared by every later one (a diagnostic for the cache).
GT_API std::size_t opencl_program_builds();

/// Bytes of OpenCL buffers held by this process's backends: now, and at most at once since the
/// last reset (a diagnostic for memory per point; host arrays not included). On a CPU device
/// the memory of released buffers is kept for later calls, up to 2 GiB per process, and not
/// counted here: a batch of large clouds then skips the OS's page zeroing on every call.
struct OpenClMemory {
  std::uint64_t current = 0, peak = 0;
};
/// The counters; with reset_peak, the peak restarts from the current bytes after reading.
GT_API OpenClMemory opencl_memory(bool reset_peak = false);

/// Creates the OpenCL backend on one device. `selector`: empty = the first GPU, else the
/// first device; a number N = list_opencl_devices()[N]; anything else = the first device
/// whose "platform: name" contains it (case-insensitive). Throws OpenClError when there is no
/// OpenCL device or the kernels do not build on it (build_log() says why), UsageError when
/// devices exist but none matches the selector. Its calls throw OpenClError for a cloud whose
/// buffers would not fit the device's memory (checked before any buffer is made) and for a
/// device that runs out of memory all the same. The backend is not thread-safe; create one
/// per thread (they share the built program).
GT_API std::unique_ptr<FeatureBackend> make_opencl_backend(const std::string& selector = "");

}  // namespace groovetrace
