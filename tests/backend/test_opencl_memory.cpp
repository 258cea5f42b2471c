// The OpenCL backend against a device too small for the cloud: the bound on its buffers
// (backend/opencl/memory_need.hpp) holds the measured peak of every call, a cloud over the
// device's limits is refused before any buffer is made with one line naming both sizes, and
// `auto` reruns such a call on the CPU. The device's limits are lowered with
// GROOVETRACE_OPENCL_MEMORY_LIMIT. Skipped when no OpenCL device exists.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <groovetrace/features.hpp>
#include <groovetrace/opencl.hpp>
#include <random>
#include <string>
#include <thread>

#include "backend/opencl/memory_need.hpp"
#include "support/opencl_support.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

// A 320x240 pinhole frame of a V-groove (76,800 points).
Cloud frame() {
  test::VGrooveScene s;
  s.width = 320;
  s.height = 240;
  s.noise_sigma = 0.0002;
  return test::render_vgroove(s).cloud;
}

// Points strewn over a 20 m cube: far more cells than points, so the grid is a hash table.
Cloud spread(std::size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  Cloud c;
  c.resize(n);
  for (std::size_t i = 0; i < n; ++i) c.x[i] = u(rng), c.y[i] = u(rng), c.z[i] = u(rng);
  c.width = static_cast<std::uint32_t>(n);
  c.height = 1;
  return c;
}

// Runs fn and returns the peak of the OpenCL buffers it held at once (bytes). The driver
// releases buffers on its own threads: the earlier calls' are waited for, so that one released
// during fn does not hide as much of fn's own.
template <typename Fn>
std::uint64_t peak_of(Fn&& fn) {
  for (int k = 0; k < 500 && opencl_memory().current > 0; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::uint64_t before = opencl_memory(true).current;
  fn();
  return opencl_memory().peak - before;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Every call on an organized frame, the same points unorganized (a dense grid) and a spread
// cloud (a hashed grid) stays within the bound the backend checks against the device.
TEST(OpenClMemory, TheBoundHoldsEveryCallsMeasuredPeak) {
  REQUIRE_OPENCL(b);
  const Cloud organized = frame();
  const Cloud clouds[] = {organized, test::shuffled(organized, 3), spread(50000)};
  const char* kinds[] = {"organized", "unorganized", "spread"};
  const float r = 0.003f;
  for (int k = 0; k < 3; ++k) {
    const Cloud& c = clouds[k];
    const std::uint64_t bound = ocl::memory_need(c.size()).total;
    const FeatureSet f = b->features(c, r, 5);
    const std::uint64_t peaks[] = {
        peak_of([&] { b->smooth(c, SmoothParams{}); }),
        peak_of([&] { b->normals(c, r, 5); }),
        peak_of([&] { b->descriptor(c, f.normals, r, f.benchmark_normal); }),
        peak_of([&] { b->features(c, r, 5); }),
        peak_of([&] { b->crease(c, CreaseParams{}); }),
    };
    const char* calls[] = {"smooth", "normals", "descriptor", "features", "crease"};
    for (int call = 0; call < 5; ++call) {
      EXPECT_GT(peaks[call], 0u) << kinds[k] << " " << calls[call];
      EXPECT_LE(peaks[call], bound) << kinds[k] << " " << calls[call] << ": " << peaks[call]
                                    << " bytes for " << c.size() << " points";
      std::printf("%-11s %-10s %5.1f B/point (bound %5.1f)\n", kinds[k], calls[call],
                  static_cast<double>(peaks[call]) / static_cast<double>(c.size()),
                  static_cast<double>(bound) / static_cast<double>(c.size()));
    }
  }
}

TEST(OpenClMemory, ACloudTooLargeForTheDeviceIsRefusedBeforeAnyBuffer) {
  REQUIRE_OPENCL(unused);
  const Cloud c = frame();
  const ocl::MemoryNeed need = ocl::memory_need(c.size());
  {
    const test::ScopedEnv limit("GROOVETRACE_OPENCL_MEMORY_LIMIT",
                                std::to_string(need.total - 1).c_str());
    auto b = make_opencl_backend();
    const std::uint64_t before = opencl_memory(true).current;
    try {
      b->normals(c, 0.003f, 5);
      FAIL() << "a cloud over the limit ran";
    } catch (const OpenClError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.code(), ExitCode::kInternal);
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find("has too little memory for 76800 points: needs up to "),
                std::string::npos)
          << what;
      EXPECT_NE(what.find("the device offers "), std::string::npos) << what;
    }
    EXPECT_LE(opencl_memory().peak, before) << "a buffer was made";
  }
  // At the bound itself the cloud fits.
  const test::ScopedEnv limit("GROOVETRACE_OPENCL_MEMORY_LIMIT",
                              std::to_string(need.total).c_str());
  EXPECT_EQ(make_opencl_backend()->normals(c, 0.003f, 5).size(), c.size());
}

// `auto` reruns the refused call on the CPU, whose result it returns whole, and stays there.
TEST(OpenClMemory, AutoRerunsACallTheDeviceCannotHoldOnTheCpu) {
  REQUIRE_OPENCL(unused);
  const Cloud c = frame();
  const test::ScopedEnv limit("GROOVETRACE_OPENCL_MEMORY_LIMIT", "1048576");
  auto b = make_backend("auto");
  EXPECT_EQ(b->name(), "opencl");
  EXPECT_TRUE(b->warning().empty());
  const Normals got = b->normals(c, 0.003f, 5);
  const Normals want = make_cpu_backend()->normals(c, 0.003f, 5);
  EXPECT_TRUE(same_bits(got.x, want.x) && same_bits(got.y, want.y) && same_bits(got.z, want.z));
  EXPECT_EQ(b->name(), "cpu");
  EXPECT_EQ(b->warning().rfind("OpenCL failed, using the cpu backend: ", 0), 0u) << b->warning();
  EXPECT_NE(b->warning().find("too little memory"), std::string::npos) << b->warning();
  const CreaseMeasure later = b->crease(c, CreaseParams{});
  EXPECT_EQ(later.concavity.size(), c.size());
  EXPECT_EQ(b->name(), "cpu");
}

}  // namespace
}  // namespace groovetrace
