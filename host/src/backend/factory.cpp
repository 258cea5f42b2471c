#include <groovetrace/error.hpp>
#include <groovetrace/features.hpp>
#include <groovetrace/opencl.hpp>
#include <utility>

namespace groovetrace {
namespace {

// The backend "auto" returns when OpenCL cannot run: the CPU reference, plus the reason.
class FallbackBackend final : public FeatureBackend {
 public:
  FallbackBackend(std::unique_ptr<FeatureBackend> inner, std::string warning)
      : inner_(std::move(inner)), warning_(std::move(warning)) {}
  std::string name() const override { return inner_->name(); }
  std::string device() const override { return inner_->device(); }
  std::string warning() const override { return warning_; }
  Cloud smooth(const Cloud& cloud, const SmoothParams& params) override {
    return inner_->smooth(cloud, params);
  }
  Normals normals(const Cloud& cloud, float radius, int min_neighbors) override {
    return inner_->normals(cloud, radius, min_neighbors);
  }
  std::vector<float> descriptor(const Cloud& cloud, const Normals& normals, float radius,
                                const Eigen::Vector3f& u_b) override {
    return inner_->descriptor(cloud, normals, radius, u_b);
  }
  FeatureSet features(const Cloud& cloud, float radius, int min_neighbors) override {
    return inner_->features(cloud, radius, min_neighbors);
  }
  CreaseMeasure crease(const Cloud& cloud, const CreaseParams& params) override {
    return inner_->crease(cloud, params);
  }

 private:
  std::unique_ptr<FeatureBackend> inner_;
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
    // A missing driver or a kernel that does not compile on this device is not fatal here;
    // a selector that names no device is (UsageError passes through).
    try {
      return make_opencl_backend(device);
    } catch (const OpenClError& e) {
      return std::make_unique<FallbackBackend>(make_cpu_backend(),
                                               std::string("OpenCL unavailable, using the cpu "
                                                           "backend: ") +
                                                   e.what());
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
