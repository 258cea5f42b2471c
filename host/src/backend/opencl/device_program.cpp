#include "device_program.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <mutex>
#include <sstream>

namespace groovetrace::ocl {
namespace {

// Kernel sources in dependency order: one program, one compile per device.
constexpr const char* kSources[] = {"common.cl",  "eigen3.cl",     "neighbors.cl", "grid_build.cl",
                                    "normals.cl", "descriptor.cl", "mls.cl",       "crease.cl"};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "gpu";
  if (t & CL_DEVICE_TYPE_CPU) return "cpu";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

std::string label(const cl::Device& d) {
  const cl::Platform p(d.getInfo<CL_DEVICE_PLATFORM>());
  return p.getInfo<CL_PLATFORM_NAME>() + ": " + d.getInfo<CL_DEVICE_NAME>();
}

// Lanes per work-item (kernels/common.cl). GPUs vectorize across work-items themselves. On a
// CPU, 16 lanes measured fastest with PoCL (1280x720 frame, r = 3 mm, AVX-512): normals 2.2x,
// descriptor 2.5x, smoothing 1.7x faster than 8 lanes, as the per-candidate loop overhead is
// shared by more queries. GROOVETRACE_OPENCL_VW overrides it for experiments.
int vector_width_for(const cl::Device& d) {
  if (const char* env = std::getenv("GROOVETRACE_OPENCL_VW")) {
    const int v = std::atoi(env);
    if (v == 1 || v == 2 || v == 4 || v == 8 || v == 16) return v;
  }
  return (d.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) ? 16 : 1;
}

// The first line of a build log that looks like an error, for a one-line message.
std::string first_error_line(const std::string& log) {
  std::istringstream in(log);
  std::string line, first;
  while (std::getline(in, line)) {
    if (first.empty() && !line.empty()) first = line;
    if (line.find("error") != std::string::npos) return line;
  }
  return first.empty() ? "(empty build log)" : first;
}

// Why no device was found, for the one line: no platform at all (no driver installed), or
// platforms that list no device (a driver without its hardware, or devices hidden from this
// process, e.g. by POCL_DEVICES).
std::string no_device_message() {
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    platforms.clear();
  }
  if (platforms.empty()) return "no OpenCL platform found (is an OpenCL driver installed?)";
  std::string names;
  for (const auto& p : platforms) {
    try {
      names += (names.empty() ? "" : ", ") + p.getInfo<CL_PLATFORM_NAME>();
    } catch (const cl::Error&) {
      names += (names.empty() ? "" : ", ") + std::string("(unnamed)");
    }
  }
  const bool one = platforms.size() == 1;
  return std::string("no OpenCL device found: the platform") + (one ? " " : "s ") + names +
         (one ? " lists" : " list") + " no device";
}

std::mutex g_mutex;
// Keyed by device and build options: a changed GROOVETRACE_OPENCL_* setting builds anew.
std::map<std::pair<cl_device_id, std::string>, std::shared_ptr<const DeviceProgram>> g_programs;
std::size_t g_builds = 0;

}  // namespace

std::vector<cl::Device> all_devices() {
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return {};  // the ICD loader found no platform
  }
  std::vector<cl::Device> out;
  for (const auto& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices
    }
    out.insert(out.end(), devices.begin(), devices.end());
  }
  return out;
}

cl::Device select_device(const std::string& selector) {
  const std::vector<cl::Device> devices = all_devices();
  if (devices.empty()) throw OpenClError(no_device_message(), 0);
  if (selector.empty()) {
    for (const auto& d : devices) {
      if (d.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU) return d;
    }
    return devices.front();
  }
  std::string list;
  for (std::size_t k = 0; k < devices.size(); ++k) {
    list += (k ? ", " : "") + std::to_string(k) + " = " + label(devices[k]);
  }
  const bool numeric = std::all_of(selector.begin(), selector.end(),
                                   [](unsigned char c) { return std::isdigit(c) != 0; });
  if (numeric) {
    // At most 9 digits: stoul throws on an index past its range (exit 5, "stoul").
    const unsigned long k = selector.size() <= 9 ? std::stoul(selector) : devices.size();
    if (k < devices.size()) return devices[k];
    throw UsageError("device: no OpenCL device " + selector + " (devices: " + list + ")");
  }
  for (const auto& d : devices) {
    if (lower(label(d)).find(lower(selector)) != std::string::npos) return d;
  }
  throw UsageError("device: no OpenCL device matches '" + selector + "' (devices: " + list + ")");
}

DeviceMemory device_memory(const cl::Device& device) {
  DeviceMemory m;
  m.global = device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
  m.max_alloc = device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  if (const char* env = std::getenv("GROOVETRACE_OPENCL_MEMORY_LIMIT")) {
    char* end = nullptr;
    const unsigned long long limit = std::strtoull(env, &end, 10);
    if (end != env && *end == '\0' && limit > 0 && std::isdigit(static_cast<unsigned char>(*env))) {
      m.global = std::min<std::uint64_t>(m.global, limit);
      m.max_alloc = std::min<std::uint64_t>(m.max_alloc, limit);
      m.limited = true;
    }
  }
  return m;
}

std::shared_ptr<const DeviceProgram> program_for(const cl::Device& device) {
  const int vector_width = vector_width_for(device);
  // -w: a successful build prints nothing. PoCL's clang writes its count of warnings ("333
  // warnings generated.") straight to the process's stderr, past -q; on a CPU without AVX-512
  // every float16 argument draws -Wpsabi, harmless here as the kernels and PoCL's built-ins are
  // compiled for one target. A failed build's errors stay in its log.
  std::string options = "-cl-std=CL1.2 -w -DVW=" + std::to_string(vector_width) +
                        " -DPAD=" + std::to_string(kPointPad);
  // Extra compiler options, for experiments (e.g. -cl-mad-enable) and for the build-failure test.
  if (const char* extra = std::getenv("GROOVETRACE_OPENCL_OPTIONS")) {
    options += std::string(" ") + extra;
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  const auto key = std::make_pair(device(), options);
  auto it = g_programs.find(key);
  if (it != g_programs.end()) return it->second;

  auto dp = std::make_shared<DeviceProgram>();
  dp->device = device;
  dp->vector_width = vector_width;
  const cl::Platform platform(device.getInfo<CL_DEVICE_PLATFORM>());
  dp->description =
      device.getInfo<CL_DEVICE_NAME>() + " (" + platform.getInfo<CL_PLATFORM_NAME>() + ")";
  cl::Program::Sources sources;
  for (const char* file : kSources) {
    const char* text = embedded_kernel(file);
    if (text == nullptr) {
      throw OpenClError(std::string("kernel source ") + file + " is missing from this build", 0);
    }
    sources.emplace_back(text);
  }
  dp->context = cl::Context(device);
  dp->program = cl::Program(dp->context, sources);
  ++g_builds;
  try {
    dp->program.build({device}, options.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = dp->program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
    } catch (const cl::Error&) {
      log = "(no build log)";
    }
    throw OpenClError("OpenCL kernels failed to build on " + dp->description + " (" +
                          status_name(e.err()) + "): " + first_error_line(log),
                      e.err(), log);
  }
  g_programs.emplace(key, dp);
  return dp;
}

}  // namespace groovetrace::ocl

namespace groovetrace {

std::size_t opencl_program_builds() {
  std::lock_guard<std::mutex> lock(ocl::g_mutex);
  return ocl::g_builds;
}

std::vector<OpenClDevice> list_opencl_devices() {
  std::vector<OpenClDevice> out;
  try {
    const std::vector<cl::Device> devices = ocl::all_devices();
    for (std::size_t k = 0; k < devices.size(); ++k) {
      const cl::Device& d = devices[k];
      OpenClDevice info;
      info.index = static_cast<int>(k);
      info.platform = cl::Platform(d.getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_NAME>();
      info.name = d.getInfo<CL_DEVICE_NAME>();
      info.type = ocl::type_name(d.getInfo<CL_DEVICE_TYPE>());
      info.c_version = d.getInfo<CL_DEVICE_OPENCL_C_VERSION>();
      info.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      info.global_memory_bytes = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      out.push_back(std::move(info));
    }
  } catch (const cl::Error&) {
    // A driver that fails mid-query lists what it had.
  }
  return out;
}

}  // namespace groovetrace
