// MLS smoothing (quadric, r = 3 mm): the OpenCL and CPU backends and pcl::MovingLeastSquares.
#include "pcl_peers.hpp"

namespace bench {
namespace {

void BM_OpenClSmooth(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  const Cloud& c = frame(state.range(0));
  backend->smooth(c, SmoothParams{});  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->smooth(c, SmoothParams{}));
  report_points(state, c.size());
}

// Order 1: projection onto the weighted plane only (one pass over the neighbours).
void BM_OpenClSmoothPlane(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  const Cloud& c = frame(state.range(0));
  SmoothParams sp;
  sp.order = 1;
  backend->smooth(c, sp);  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->smooth(c, sp));
  report_points(state, c.size());
}

void BM_OpenClSmoothUnorganized(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  Cloud c = frame(state.range(0));
  c.width = static_cast<std::uint32_t>(c.size());
  c.height = 1;
  backend->smooth(c, SmoothParams{});  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->smooth(c, SmoothParams{}));
  report_points(state, c.size());
}

void BM_CpuSmooth(benchmark::State& state) {
  const Cloud& c = frame(state.range(0));
  auto backend = make_cpu_backend();
  for (auto _ : state) benchmark::DoNotOptimize(backend->smooth(c, SmoothParams{}));
  report_points(state, c.size());
}

void BM_PclMls(benchmark::State& state) {
  auto cloud = to_pcl(frame(state.range(0)));
  for (auto _ : state) {
    const auto out = pcl_mls(cloud, kRadius);
    benchmark::DoNotOptimize(out.points.data());
  }
  report_points(state, cloud->size());
}

STAGE(BM_OpenClSmooth);
STAGE(BM_OpenClSmoothPlane);
STAGE(BM_OpenClSmoothUnorganized);
STAGE(BM_CpuSmooth);
STAGE(BM_PclMls);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
