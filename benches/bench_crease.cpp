// The robust method's crease measure (FeatureBackend::crease) on the 1 mm voxels of the
// frame, r = 10 mm as the method uses it: the OpenCL and CPU backends, and the same measure
// over pcl::search::KdTree (radiusSearch, PCL's covariance and 3x3 eigen-solver, the exact
// quantile by nth_element). The counters give the ball size and the candidates the kernel's
// grid walk visits per voxel, for the flop count in docs/benchmarks.md.
#include <pcl/common/centroid.h>
#include <pcl/common/eigen.h>
#include <pcl/search/kdtree.h>

#include "pcl_peers.hpp"
#include "robust/stages.hpp"

namespace bench {
namespace {

// The robust method's settings (host/src/robust/candidates.cpp): 10 mm, 3 mm, 80th percentile, 31
// voxels.
CreaseParams crease_params() {
  CreaseParams p;
  p.min_neighbors = 31;
  return p;
}

// The voxel centroids the robust method measures, per frame width.
const Cloud& voxels(int width) {
  static std::map<int, Cloud> cache;
  auto it = cache.find(width);
  if (it == cache.end()) {
    Cloud c = voxel_cloud(crease_map(frame(width), RobustParams{}));
    it = cache.emplace(width, std::move(c)).first;
  }
  return it->second;
}

// Per voxel: points within r, and the points of the 27 grid cells of edge r around its cell
// (what the kernel's walk visits when a work-item's voxels share a cell, the common case).
void walk_counters(benchmark::State& state, const Cloud& c, float r) {
  std::map<std::array<int, 3>, std::vector<std::uint32_t>> cells;
  auto cell_of = [&](std::size_t i) {
    return std::array<int, 3>{static_cast<int>(std::floor(c.x[i] / r)),
                              static_cast<int>(std::floor(c.y[i] / r)),
                              static_cast<int>(std::floor(c.z[i] / r))};
  };
  for (std::size_t i = 0; i < c.size(); ++i) cells[cell_of(i)].push_back(i);
  double candidates = 0, inside = 0;
  for (const auto& [cell, members] : cells) {
    std::vector<std::uint32_t> near;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          auto it = cells.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it != cells.end()) near.insert(near.end(), it->second.begin(), it->second.end());
        }
      }
    }
    candidates += static_cast<double>(near.size() * members.size());
    for (const std::uint32_t i : members) {
      for (const std::uint32_t j : near) {
        const float dx = c.x[j] - c.x[i], dy = c.y[j] - c.y[i], dz = c.z[j] - c.z[i];
        inside += dx * dx + dy * dy + dz * dz <= r * r ? 1 : 0;
      }
    }
  }
  state.counters["candidates_per_point"] = candidates / static_cast<double>(c.size());
  state.counters["neighbours_per_point"] = inside / static_cast<double>(c.size());
}

void BM_OpenClCrease(benchmark::State& state) {
  REQUIRE_OPENCL(backend);
  const Cloud& v = voxels(static_cast<int>(state.range(0)));
  backend->crease(v, crease_params());  // warm-up (see bench_common.hpp)
  for (auto _ : state) benchmark::DoNotOptimize(backend->crease(v, crease_params()));
  report_points(state, v.size());
  walk_counters(state, v, crease_params().radius);
}

void BM_CpuCrease(benchmark::State& state) {
  const Cloud& v = voxels(static_cast<int>(state.range(0)));
  auto backend = make_cpu_backend();
  for (auto _ : state) benchmark::DoNotOptimize(backend->crease(v, crease_params()));
  report_points(state, v.size());
}

// The same measure built from PCL: kd-tree radius search, computeMeanAndCovarianceMatrix and
// eigen33 for the plane, nth_element for the quantile.
std::vector<float> pcl_crease(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                              const Eigen::Vector3f& viewpoint, const CreaseParams& params) {
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  const auto n = static_cast<std::int64_t>(cloud->size());
  std::vector<float> out(cloud->size(), NAN);
  const float own2 = params.own_radius * params.own_radius;
#pragma omp parallel num_threads(kPclThreads)
  {
    std::vector<int> idx;
    std::vector<float> d2, heights;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t i = 0; i < n; ++i) {
      const pcl::PointXYZ& p = (*cloud)[i];
      const int found = tree.radiusSearch(p, params.radius, idx, d2);
      if (found < params.min_neighbors) continue;
      Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
      Eigen::Vector4f centroid = Eigen::Vector4f::Zero();
      pcl::computeMeanAndCovarianceMatrix(*cloud, idx, cov, centroid);
      float eigenvalue;
      Eigen::Vector3f normal;
      pcl::eigen33(cov, eigenvalue, normal);
      if (normal.dot(viewpoint - p.getVector3fMap()) < 0) normal = -normal;
      heights.resize(idx.size());
      double own = 0;
      int own_count = 0;
      for (std::size_t k = 0; k < idx.size(); ++k) {
        heights[k] = normal.dot((*cloud)[idx[k]].getVector3fMap() - p.getVector3fMap());
        if (d2[k] <= own2) {
          own += heights[k];
          ++own_count;
        }
      }
      const auto q = static_cast<std::size_t>(params.quantile * static_cast<float>(found - 1));
      std::nth_element(heights.begin(), heights.begin() + q, heights.end());
      out[i] = static_cast<float>(heights[q] - own / std::max(own_count, 1));
    }
  }
  return out;
}

void BM_PclCreaseKdTree(benchmark::State& state) {
  const Cloud& v = voxels(static_cast<int>(state.range(0)));
  auto cloud = to_pcl(v);
  for (auto _ : state) benchmark::DoNotOptimize(pcl_crease(cloud, v.viewpoint, crease_params()));
  report_points(state, v.size());
}

STAGE(BM_OpenClCrease);
STAGE(BM_CpuCrease);
STAGE(BM_PclCreaseKdTree);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
