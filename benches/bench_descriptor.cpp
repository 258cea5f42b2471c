// The GFH descriptor (r = 3 mm) from given normals: the OpenCL and CPU backends and the same
// descriptor over pcl::search::KdTree; and the fused normals + u_b + descriptor call.
#include "pcl_peers.hpp"

namespace bench {
namespace {

void BM_OpenClDescriptor(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  const Prepared& p = prepared(state.range(0));
  backend->descriptor(p.smoothed, p.normals, kRadius, p.u_b);  // warm-up (see bench_common.hpp)
  for (auto _ : state) {
    benchmark::DoNotOptimize(backend->descriptor(p.smoothed, p.normals, kRadius, p.u_b));
  }
  report_points(state, p.smoothed.size());
}

void BM_OpenClDescriptorUnorganized(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  const Prepared& p = prepared(state.range(0));
  Cloud c = p.smoothed;
  c.width = static_cast<std::uint32_t>(c.size());
  c.height = 1;
  backend->descriptor(c, p.normals, kRadius, p.u_b);  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->descriptor(c, p.normals, kRadius, p.u_b));
  report_points(state, c.size());
}

// Normals, u_b and descriptor in one call, the cloud staying on the device.
void BM_OpenClFeatures(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  const Prepared& p = prepared(state.range(0));
  backend->features(p.smoothed, kRadius, 5);  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->features(p.smoothed, kRadius, 5));
  report_points(state, p.smoothed.size());
}

void BM_CpuDescriptor(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  auto backend = make_cpu_backend();
  for (auto _ : state) {
    benchmark::DoNotOptimize(backend->descriptor(p.smoothed, p.normals, kRadius, p.u_b));
  }
  report_points(state, p.smoothed.size());
}

void BM_PclGfhKdTree(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  auto cloud = to_pcl(p.smoothed);
  pcl::PointCloud<pcl::Normal> normals;
  normals.resize(p.normals.size());
  for (std::size_t i = 0; i < p.normals.size(); ++i) {
    normals[i].normal_x = p.normals.x[i];
    normals[i].normal_y = p.normals.y[i];
    normals[i].normal_z = p.normals.z[i];
  }
  for (auto _ : state) benchmark::DoNotOptimize(pcl_gfh(cloud, normals, kRadius, p.u_b));
  report_points(state, cloud->size());
}

STAGE(BM_OpenClDescriptor);
STAGE(BM_OpenClDescriptorUnorganized);
STAGE(BM_OpenClFeatures);
STAGE(BM_CpuDescriptor);
STAGE(BM_PclGfhKdTree);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
