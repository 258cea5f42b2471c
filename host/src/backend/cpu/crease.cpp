// The crease measure on the CPU (see FeatureBackend::crease): per point a plane fit in double,
// then the exact quantile of the heights along its normal.

#include "backend/cpu/crease.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "core/eigen3.hpp"
#include "core/neighbor_grid.hpp"

namespace groovetrace {
namespace {

// The k-th smallest of `values` (k < size), exactly as std::nth_element finds it but without
// its unpredictable branches, which cost more than the rest of a point's work: count the
// values into 256 bins between their min and max, then select within the one bin that holds
// the k-th.
double kth_smallest(const std::vector<double>& values, std::size_t k, std::vector<double>& bin) {
  double lo = values[0], hi = values[0];
  for (const double v : values) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (!(hi > lo)) return lo;
  constexpr int kBins = 256;
  const double scale = kBins / (hi - lo);
  auto bin_of = [&](double v) { return std::min(kBins - 1, static_cast<int>((v - lo) * scale)); };
  std::array<std::uint32_t, kBins> counts{};
  for (const double v : values) ++counts[bin_of(v)];
  int b = 0;
  std::size_t below = 0;
  while (below + counts[b] <= k) below += counts[b++];
  bin.clear();
  for (const double v : values) {
    if (bin_of(v) == b) bin.push_back(v);
  }
  std::nth_element(bin.begin(), bin.begin() + (k - below), bin.end());
  return bin[k - below];
}

// The ball of one point: its neighbours within the radius, relative to it (m).
struct Ball {
  std::vector<float> x, y, z, d2;  // d2: squared distance to the point
  std::size_t size = 0;

  // Room for every candidate of a cell, and one more for the branch-free compaction.
  void reserve(std::size_t candidates) {
    x.resize(candidates + 1);
    y.resize(candidates + 1);
    z.resize(candidates + 1);
    d2.resize(candidates + 1);
  }

  // The block's candidates within sqrt(r2) of p, compacted without branches: every candidate
  // is written, and the slot advances only for those inside.
  void gather(const NeighborGrid::CellBlock& block, const Eigen::Vector3f& p, float r2) {
    size = 0;
    for (std::size_t k = 0; k < block.near.size(); ++k) {
      const float ex = block.x[k] - p.x(), ey = block.y[k] - p.y(), ez = block.z[k] - p.z();
      const float dd = ex * ex + ey * ey + ez * ez;
      x[size] = ex;
      y[size] = ey;
      z[size] = ez;
      d2[size] = dd;
      size += dd <= r2 ? 1 : 0;
    }
  }
};

// The ball's plane fit in double: the unit normal, turned towards `to_viewpoint`.
Eigen::Vector3d fit_normal(const Ball& ball, const Eigen::Vector3f& to_viewpoint) {
  double mx = 0, my = 0, mz = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  for (std::size_t k = 0; k < ball.size; ++k) {
    const double dx = ball.x[k], dy = ball.y[k], dz = ball.z[k];
    mx += dx;
    my += dy;
    mz += dz;
    xx += dx * dx;
    xy += dx * dy;
    xz += dx * dz;
    yy += dy * dy;
    yz += dy * dz;
    zz += dz * dz;
  }
  const double count_d = static_cast<double>(ball.size);
  const Eigen::Vector3d mean = Eigen::Vector3d(mx, my, mz) / count_d;
  Eigen::Matrix3d s2;
  s2 << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  Eigen::Vector3d normal = smallest_eigenvector(s2 / count_d - mean * mean.transpose());
  if (normal.dot(to_viewpoint.cast<double>()) < 0) normal = -normal;
  return normal;
}

// The envelope (a quantile of the heights along the normal) minus the point's own height
// averaged over a small ball (its noise averaged out). `heights` and `bin` are scratch.
float concavity(const Ball& ball, const Eigen::Vector3d& normal, const CreaseParams& params,
                std::vector<double>& heights, std::vector<double>& bin) {
  // In float, as the kernel compares: a neighbour at the rim of the own ball counts in both or
  // in neither (a 3 mm ball of ~30 voxels moves its mean height by ~13 um per voxel).
  const float own_r2 = params.own_radius * params.own_radius;
  heights.resize(ball.size);
  double own_sum = 0;
  int own_count = 0;
  for (std::size_t k = 0; k < ball.size; ++k) {
    const double h = normal.x() * ball.x[k] + normal.y() * ball.y[k] + normal.z() * ball.z[k];
    heights[k] = h;
    const bool own = ball.d2[k] <= own_r2;
    own_sum += own ? h : 0.0;
    own_count += own ? 1 : 0;
  }
  const auto q = static_cast<std::size_t>(static_cast<double>(params.quantile) *
                                          static_cast<double>(ball.size - 1));
  const double envelope = kth_smallest(heights, q, bin);
  return static_cast<float>(envelope - own_sum / std::max(own_count, 1));
}

}  // namespace

CreaseMeasure crease_cpu(const Cloud& cloud, const CreaseParams& params) {
  CreaseMeasure out;
  out.normals.resize(cloud.size());
  out.concavity.assign(cloud.size(), NAN);
  const NeighborGrid grid(cloud, params.radius);
  const std::size_t min_count = static_cast<std::size_t>(std::max(params.min_neighbors, 3));
  const std::int64_t cells = static_cast<std::int64_t>(grid.cell_count());
  const float r2 = params.radius * params.radius;
#pragma omp parallel
  {
    // The candidates come per grid cell (all of a cell's points share them), so the distance
    // test is one tight loop over contiguous coordinates.
    NeighborGrid::CellBlock block;
    Ball ball;
    std::vector<double> heights, bin;
#pragma omp for schedule(dynamic, 4)
    for (std::int64_t c = 0; c < cells; ++c) {
      grid.gather_cell(static_cast<std::size_t>(c), block);
      ball.reserve(block.near.size());
      for (const std::uint32_t v : block.members) {
        const Eigen::Vector3f p = cloud.point(v);
        ball.gather(block, p, r2);
        if (ball.size < min_count) continue;
        const Eigen::Vector3d normal = fit_normal(ball, cloud.viewpoint - p);
        out.normals.x[v] = static_cast<float>(normal.x());
        out.normals.y[v] = static_cast<float>(normal.y());
        out.normals.z[v] = static_cast<float>(normal.z());
        out.concavity[v] = concavity(ball, normal, params, heights, bin);
      }
    }
  }
  return out;
}

}  // namespace groovetrace
