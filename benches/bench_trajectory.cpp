// Slicing and geometric medians of the paper trajectory.
#include "bench_common.hpp"

namespace bench {
namespace {

void BM_Trajectory(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(paper_trajectory(p.smoothed, p.normals, p.detection.groove, 50));
  }
  report_points(state, p.smoothed.size());
}

pcl::PointCloud<pcl::PointXYZ>::Ptr to_pcl(const Cloud& c) {
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  out->width = c.width;
  out->height = c.height;
  out->is_dense = false;
  out->points.resize(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) out->points[i] = {c.x[i], c.y[i], c.z[i]};
  return out;
}

STAGE(BM_Trajectory);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
