#include <groovetrace/error.hpp>
#include <groovetrace/features.hpp>
#include <groovetrace/opencl.hpp>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace {
namespace {

// The backend "auto" returns: the OpenCL backend while it works, else the CPU reference and
// the reason. A device error during a call (a cloud too large for the device's memory, a failed
// allocation) reruns that call on the CPU, which returns it whole, and later calls stay there:
// one run does not switch back and forth, and the backend named at its end is the one that
// finished it.
class AutoBackend final : public FeatureBackend {
 public:
  explicit AutoBackend(std::unique_ptr<FeatureBackend> opencl) : opencl_(std::move(opencl)) {}
  explicit AutoBackend(const std::string& why)
      : cpu_(make_cpu_backend()), warning_("OpenCL unavailable, using the cpu backend: " + why) {}

  std::string name() const override { return active().name(); }
  std::string device() const override { return active().device(); }
  std::string warning() const override { return warning_; }
  Cloud smooth(const Cloud& cloud, const SmoothParams& params) override {
    return call([&](FeatureBackend& b) { return b.smooth(cloud, params); });
  }
  Normals normals(const Cloud& cloud, float radius, int min_neighbors) override {
    return call([&](FeatureBackend& b) { return b.normals(cloud, radius, min_neighbors); });
  }
  std::vector<float> descriptor(const Cloud& cloud, const Normals& normals, float radius,
                                const Eigen::Vector3f& u_b) override {
    return call([&](FeatureBackend& b) { return b.descriptor(cloud, normals, radius, u_b); });
  }
  FeatureSet features(const Cloud& cloud, float radius, int min_neighbors) override {
    return call([&](FeatureBackend& b) { return b.features(cloud, radius, min_neighbors); });
  }
  CreaseMeasure crease(const Cloud& cloud, const CreaseParams& params) override {
    return call([&](FeatureBackend& b) { return b.crease(cloud, params); });
  }

 private:
  FeatureBackend& active() const { return opencl_ ? *opencl_ : *cpu_; }

  template <typename Fn>
  auto call(Fn&& fn) -> decltype(fn(std::declval<FeatureBackend&>())) {
    if (opencl_) {
      try {
        return fn(*opencl_);
      } catch (const OpenClError& e) {
        warning_ = std::string("OpenCL failed, using the cpu backend: ") + e.what();
        opencl_.reset();  // its buffers and queue go before the CPU's run
        cpu_ = make_cpu_backend();
      }
    }
    return fn(*cpu_);
  }

  std::unique_ptr<FeatureBackend> opencl_;  // null once the CPU has taken over
  std::unique_ptr<FeatureBackend> cpu_;
  std::string warning_;
};

}  // namespace

Eigen::Vector3f benchmark_normal(const Normals& normals) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < normals.size(); ++i) {
    if (normals.valid(i)) sum += normals.normal(i).cast<double>();
  }
  const double len = sum.norm();
  if (!(len > 0)) return Eigen::Vector3f::Constant(NAN);
  return (sum / len).cast<float>();
}

FeatureSet FeatureBackend::features(const Cloud& cloud, float radius, int min_neighbors) {
  FeatureSet out;
  out.normals = normals(cloud, radius, min_neighbors);
  out.benchmark_normal = benchmark_normal(out.normals);
  if (out.benchmark_normal.allFinite()) {
    out.descriptor = descriptor(cloud, out.normals, radius, out.benchmark_normal);
  } else {
    out.descriptor.assign(cloud.size(), NAN);
  }
  return out;
}

std::unique_ptr<FeatureBackend> make_backend(const std::string& name, const std::string& device) {
  if (name == "cpu") return make_cpu_backend();
  if (name == "opencl") return make_opencl_backend(device);
  if (name == "auto") {
    // No driver, no device, a kernel that does not compile on this device, or a device error
    // in a call (AutoBackend) is not fatal here; a selector that names no device is
    // (UsageError passes through).
    try {
      return std::make_unique<AutoBackend>(make_opencl_backend(device));
    } catch (const OpenClError& e) {
      return std::make_unique<AutoBackend>(std::string(e.what()));
    }
  }
  throw UsageError("unknown backend '" + name + "' (expected auto, cpu or opencl)");
}

#ifndef GROOVETRACE_WITH_OPENCL
std::vector<OpenClDevice> list_opencl_devices() { return {}; }

std::size_t opencl_program_builds() { return 0; }

OpenClMemory opencl_memory(bool) { return {}; }

std::unique_ptr<FeatureBackend> make_opencl_backend(const std::string&) {
  throw OpenClError("this groovetrace was built without OpenCL (WITH_OPENCL=OFF)", 0);
}
#endif

}  // namespace groovetrace
