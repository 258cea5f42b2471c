// Unorganized clouds of 1M, 4M and 16M points: a wavy plate (4 mm waves, 0.2 mm noise)
// sampled at the density of the 1280x720 frame, about 6 points per mm^2. "Scan" clouds come in
// acquisition order (a raster sweep with jittered samples, as a scanner writes them),
// "Shuffled" ones in random order, the worst case for memory locality. Reported: time per
// point of the OpenCL backend's grid search as the cloud grows, and bytes_per_point = the most
// OpenCL buffer memory held at once during the call (host memory under PoCL) plus the host
// result arrays, per point: the memory beyond the input.
#include <random>
#include <string>

#include "bench_common.hpp"

namespace bench {
namespace {

const Cloud& plate(std::size_t n, bool shuffled) {
  static std::map<std::pair<std::size_t, bool>, Cloud> cache;
  const auto key = std::make_pair(n, shuffled);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  cache.clear();                                                // one large cloud at a time
  const double side = std::sqrt(static_cast<double>(n) / 6e6);  // m, 6 points per mm^2
  const std::size_t cols = static_cast<std::size_t>(std::sqrt(static_cast<double>(n)));
  const std::size_t rows = (n + cols - 1) / cols;
  std::mt19937_64 rng(n);
  std::uniform_real_distribution<double> jitter(0.0, 1.0);
  std::normal_distribution<double> noise(0, 0.0002);
  Cloud c;
  c.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = side * ((static_cast<double>(i % cols) + jitter(rng)) / cols - 0.5);
    const double y = side * ((static_cast<double>(i / cols) + jitter(rng)) / rows - 0.5);
    c.x[i] = static_cast<float>(x);
    c.y[i] = static_cast<float>(y);
    c.z[i] =
        static_cast<float>(0.5 + 0.004 * std::sin(x * 125.0) * std::cos(y * 90.0) + noise(rng));
  }
  if (shuffled) {
    for (std::size_t i = n - 1; i > 0; --i) {
      const std::size_t j = std::uniform_int_distribution<std::size_t>(0, i)(rng);
      std::swap(c.x[i], c.x[j]);
      std::swap(c.y[i], c.y[j]);
      std::swap(c.z[i], c.z[j]);
    }
  }
  c.width = static_cast<std::uint32_t>(n);
  return cache.emplace(key, std::move(c)).first->second;
}

// Memory of one call beyond its input: the most OpenCL buffer bytes held at once (counted by
// the backend as it allocates and releases) plus the host arrays of the result.
template <typename Fn>
double bytes_per_point(std::size_t n, std::size_t result_bytes, Fn&& fn) {
  const std::uint64_t before = opencl_memory(true).current;
  fn();
  const std::uint64_t peak = opencl_memory().peak;
  return static_cast<double>(peak - before + result_bytes) / static_cast<double>(n);
}

void report(benchmark::State& state, std::size_t n, double bytes) {
  report_points(state, n);
  state.counters["bytes_per_point"] = bytes;
}

void features(benchmark::State& state, bool shuffled) {
  REQUIRE_OPENCL(backend);
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const Cloud& c = plate(n, shuffled);
  // Result: normals (3 floats) and descriptor (1 float) per point.
  const double bytes = bytes_per_point(n, 16 * n, [&] { backend->features(c, kRadius, 5); });
  for (auto _ : state) benchmark::DoNotOptimize(backend->features(c, kRadius, 5));
  report(state, n, bytes);
}

void smooth(benchmark::State& state, bool shuffled) {
  REQUIRE_OPENCL(backend);
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const Cloud& c = plate(n, shuffled);
  // Result: the smoothed cloud (3 floats per point).
  const double bytes = bytes_per_point(n, 12 * n, [&] { backend->smooth(c, SmoothParams{}); });
  for (auto _ : state) benchmark::DoNotOptimize(backend->smooth(c, SmoothParams{}));
  report(state, n, bytes);
}

// Normals, u_b and descriptor (the fused call), and MLS smoothing.
void BM_OpenClScalingFeaturesScan(benchmark::State& state) { features(state, false); }
void BM_OpenClScalingFeaturesShuffled(benchmark::State& state) { features(state, true); }
void BM_OpenClScalingSmoothScan(benchmark::State& state) { smooth(state, false); }
void BM_OpenClScalingSmoothShuffled(benchmark::State& state) { smooth(state, true); }

#define SCALING(fn)                   \
  BENCHMARK(fn)                       \
      ->Arg(1 << 20)                  \
      ->Arg(1 << 22)                  \
      ->Arg(1 << 24)                  \
      ->Unit(benchmark::kMillisecond) \
      ->UseRealTime()                 \
      ->MinTime(1.0)

SCALING(BM_OpenClScalingFeaturesScan);
SCALING(BM_OpenClScalingFeaturesShuffled);
SCALING(BM_OpenClScalingSmoothScan);
SCALING(BM_OpenClScalingSmoothShuffled);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
