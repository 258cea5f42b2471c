// Normals: the CPU backend and pcl::NormalEstimationOMP over a kd-tree and over OrganizedNeighbor.
#include <pcl/features/normal_3d_omp.h>
#include <pcl/search/kdtree.h>
#include <pcl/search/organized.h>

#include "bench_common.hpp"

namespace bench {
namespace {

void BM_CpuNormals(benchmark::State& state) {
  const Cloud& c = prepared(state.range(0)).smoothed;
  auto backend = make_cpu_backend();
  for (auto _ : state) benchmark::DoNotOptimize(backend->normals(c, kRadius, 5));
  report_points(state, c.size());
}

void BM_PclNormalsKdTree(benchmark::State& state) {
  auto cloud = to_pcl(prepared(state.range(0)).smoothed);
  for (auto _ : state) {
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(2);
    ne.setInputCloud(cloud);
    ne.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    ne.setRadiusSearch(kRadius);
    pcl::PointCloud<pcl::Normal> normals;
    ne.compute(normals);
    benchmark::DoNotOptimize(normals.points.data());
  }
  report_points(state, cloud->size());
}

void BM_PclNormalsOrganized(benchmark::State& state) {
  auto cloud = to_pcl(prepared(state.range(0)).smoothed);
  for (auto _ : state) {
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(2);
    ne.setInputCloud(cloud);
    ne.setSearchMethod(pcl::make_shared<pcl::search::OrganizedNeighbor<pcl::PointXYZ>>());
    ne.setRadiusSearch(kRadius);
    pcl::PointCloud<pcl::Normal> normals;
    ne.compute(normals);
    benchmark::DoNotOptimize(normals.points.data());
  }
  report_points(state, cloud->size());
}

STAGE(BM_CpuNormals);
STAGE(BM_PclNormalsKdTree);
STAGE(BM_PclNormalsOrganized);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
