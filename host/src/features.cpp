#include <groovetrace/error.hpp>
#include <groovetrace/features.hpp>

namespace groovetrace {

Eigen::Vector3f benchmark_normal(const Normals& normals) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < normals.size(); ++i) {
    if (normals.valid(i)) sum += normals.normal(i).cast<double>();
  }
  const double len = sum.norm();
  if (!(len > 0)) return Eigen::Vector3f::Constant(NAN);
  return (sum / len).cast<float>();
}

std::unique_ptr<FeatureBackend> make_backend(const std::string& name) {
  // The OpenCL backend is not built yet; "auto" therefore means the CPU reference.
  if (name == "cpu" || name == "auto") return make_cpu_backend();
  if (name == "opencl") throw UsageError("backend 'opencl' is not available in this build");
  throw UsageError("unknown backend '" + name + "' (expected auto, cpu or opencl)");
}

}  // namespace groovetrace
