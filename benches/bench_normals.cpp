// Normals: the OpenCL and CPU backends, and pcl::NormalEstimationOMP over a kd-tree and over
// OrganizedNeighbor, on the same smoothed frame with r = 3 mm.
#include "pcl_peers.hpp"

namespace bench {
namespace {

void BM_OpenClNormals(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  const Cloud& c = prepared(state.range(0)).smoothed;
  backend->normals(c, kRadius, 5);  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->normals(c, kRadius, 5));
  report_points(state, c.size());
}

// The same points as an unorganized cloud: the hashed-grid search instead of pixel windows.
void BM_OpenClNormalsUnorganized(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  Cloud c = prepared(state.range(0)).smoothed;
  c.width = static_cast<std::uint32_t>(c.size());
  c.height = 1;
  backend->normals(c, kRadius, 5);  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->normals(c, kRadius, 5));
  report_points(state, c.size());
}

void BM_CpuNormals(benchmark::State& state) {
  const Cloud& c = prepared(state.range(0)).smoothed;
  auto backend = make_cpu_backend();
  for (auto _ : state) benchmark::DoNotOptimize(backend->normals(c, kRadius, 5));
  report_points(state, c.size());
}

void BM_PclNormalsKdTree(benchmark::State& state) {
  auto cloud = to_pcl(prepared(state.range(0)).smoothed);
  for (auto _ : state) {
    const auto normals = pcl_normals(cloud, kRadius, false, Eigen::Vector3f::Zero());
    benchmark::DoNotOptimize(normals.points.data());
  }
  report_points(state, cloud->size());
}

void BM_PclNormalsOrganized(benchmark::State& state) {
  auto cloud = to_pcl(prepared(state.range(0)).smoothed);
  for (auto _ : state) {
    const auto normals = pcl_normals(cloud, kRadius, true, Eigen::Vector3f::Zero());
    benchmark::DoNotOptimize(normals.points.data());
  }
  report_points(state, cloud->size());
}

// Not timings: the organized walk's candidates and neighbours per point (16 lanes, as the
// kernels run on a CPU device), for the flop counts; on the smoothed frame (normals,
// descriptor) and on the raw one (smoothing).
void walk(benchmark::State& state, const Cloud& c) {
  WalkStats s;
  for (auto _ : state) s = organized_walk(c, kRadius, 16);
  state.counters["candidates_per_point"] = s.candidates_per_point;
  state.counters["neighbours_per_point"] = s.neighbours_per_point;
  state.counters["slack_px"] = s.slack_px;
  state.counters["active_fraction"] = s.active_fraction;
}
void BM_OrganizedWalk(benchmark::State& state) { walk(state, prepared(state.range(0)).smoothed); }
void BM_OrganizedWalkRaw(benchmark::State& state) { walk(state, frame(state.range(0))); }

BENCHMARK(BM_OrganizedWalk)->Arg(640)->Arg(1280)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OrganizedWalkRaw)->Arg(640)->Arg(1280)->Iterations(1)->Unit(benchmark::kMillisecond);
STAGE(BM_OpenClNormals);
STAGE(BM_OpenClNormalsUnorganized);
STAGE(BM_CpuNormals);
STAGE(BM_PclNormalsKdTree);
STAGE(BM_PclNormalsOrganized);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
