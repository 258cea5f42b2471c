// MLS smoothing: the CPU backend and pcl::MovingLeastSquares at the same radius.
#include <pcl/search/kdtree.h>
#include <pcl/surface/mls.h>

#include "bench_common.hpp"

namespace bench {
namespace {

void BM_CpuSmooth(benchmark::State& state) {
  const Cloud& c = frame(state.range(0));
  auto backend = make_cpu_backend();
  for (auto _ : state) benchmark::DoNotOptimize(backend->smooth(c, SmoothParams{}));
  report_points(state, c.size());
}

void BM_PclMls(benchmark::State& state) {
  auto cloud = to_pcl(frame(state.range(0)));
  for (auto _ : state) {
    pcl::MovingLeastSquares<pcl::PointXYZ, pcl::PointXYZ> mls;
    mls.setInputCloud(cloud);
    mls.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    mls.setSearchRadius(kRadius);
    mls.setPolynomialOrder(2);
    mls.setNumberOfThreads(2);
    pcl::PointCloud<pcl::PointXYZ> out;
    mls.process(out);
    benchmark::DoNotOptimize(out.points.data());
  }
  report_points(state, cloud->size());
}

STAGE(BM_CpuSmooth);
STAGE(BM_PclMls);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
