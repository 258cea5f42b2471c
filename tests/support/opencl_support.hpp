#pragma once
// What the OpenCL tests share: the backend on the default device (or none), the same with one
// query per work-item (the kernels' GPU form), the angle between two normals and a shuffled
// copy of a cloud, and an environment variable set for a scope.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <groovetrace/features.hpp>
#include <groovetrace/opencl.hpp>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace groovetrace::test {

/// Sets an environment variable for the life of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (had_) {
      setenv(name_, old_.c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

/// The OpenCL backend on the default device; nullptr when there is none.
inline std::unique_ptr<FeatureBackend> opencl_backend() {
  try {
    return make_opencl_backend();
  } catch (const OpenClError&) {
    return nullptr;
  }
}

/// The same with GROOVETRACE_OPENCL_VW=1 (one query per work-item, as on GPUs); the
/// environment is restored afterwards.
inline std::unique_ptr<FeatureBackend> one_lane_opencl_backend() {
  const char* old = std::getenv("GROOVETRACE_OPENCL_VW");
  const std::string saved = old ? old : "";
  setenv("GROOVETRACE_OPENCL_VW", "1", 1);
  auto backend = opencl_backend();
  if (old) {
    setenv("GROOVETRACE_OPENCL_VW", saved.c_str(), 1);
  } else {
    unsetenv("GROOVETRACE_OPENCL_VW");
  }
  return backend;
}

/// Angle between two directions (deg), accurate for small angles.
inline double angle_deg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  const Eigen::Vector3d ad = a.cast<double>(), bd = b.cast<double>();
  return std::atan2(ad.cross(bd).norm(), ad.dot(bd)) * 180.0 / M_PI;
}

/// The same points as an unorganized cloud in random order (same viewpoint).
inline Cloud shuffled(const Cloud& in, unsigned seed) {
  std::vector<std::size_t> order(in.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  Cloud out;
  out.resize(in.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    out.x[k] = in.x[order[k]];
    out.y[k] = in.y[order[k]];
    out.z[k] = in.z[order[k]];
  }
  out.width = static_cast<std::uint32_t>(in.size());
  out.height = 1;
  out.viewpoint = in.viewpoint;
  return out;
}

}  // namespace groovetrace::test

/// Skips the test when there is no OpenCL device; else `b` is the backend.
#define REQUIRE_OPENCL(b)          \
  auto b = test::opencl_backend(); \
  if (!b) GTEST_SKIP() << "no OpenCL device on this machine"
