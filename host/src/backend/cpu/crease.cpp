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

}  // namespace

CreaseMeasure crease_cpu(const Cloud& cloud, const CreaseParams& params) {
  CreaseMeasure out;
  out.normals.resize(cloud.size());
  out.concavity.assign(cloud.size(), NAN);
  const NeighborGrid grid(cloud, params.radius);
  const int min_count = std::max(params.min_neighbors, 3);
  // In float, as the kernel compares: a neighbour at the rim of the own ball counts in both or
  // in neither (a 3 mm ball of ~30 voxels moves its mean height by ~13 um per voxel).
  const float own_r2 = params.own_radius * params.own_radius;
  const std::int64_t cells = static_cast<std::int64_t>(grid.cell_count());
  const float r2 = params.radius * params.radius;
#pragma omp parallel
  {
    // The candidates come per grid cell (all of a cell's points share them), so the distance
    // test is one tight loop over contiguous coordinates.
    NeighborGrid::CellBlock block;
    // The ball of one point, relative to it (m), compacted without branches.
    std::vector<float> bx, by, bz, bd2;
    std::vector<double> heights, bin;
#pragma omp for schedule(dynamic, 4)
    for (std::int64_t c = 0; c < cells; ++c) {
      grid.gather_cell(static_cast<std::size_t>(c), block);
      const std::size_t m = block.near.size();
      bx.resize(m + 1);
      by.resize(m + 1);
      bz.resize(m + 1);
      bd2.resize(m + 1);
      for (const std::uint32_t v : block.members) {
        const Eigen::Vector3f p = cloud.point(v);
        std::size_t found = 0;
        for (std::size_t k = 0; k < m; ++k) {
          const float ex = block.x[k] - p.x(), ey = block.y[k] - p.y(), ez = block.z[k] - p.z();
          const float d2 = ex * ex + ey * ey + ez * ez;
          bx[found] = ex;
          by[found] = ey;
          bz[found] = ez;
          bd2[found] = d2;
          found += d2 <= r2 ? 1 : 0;
        }
        if (found < static_cast<std::size_t>(min_count)) continue;
        double mx = 0, my = 0, mz = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
        for (std::size_t k = 0; k < found; ++k) {
          const double dx = bx[k], dy = by[k], dz = bz[k];
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
        const double count_d = static_cast<double>(found);
        const Eigen::Vector3d mean = Eigen::Vector3d(mx, my, mz) / count_d;
        Eigen::Matrix3d s2;
        s2 << xx, xy, xz, xy, yy, yz, xz, yz, zz;
        Eigen::Vector3d normal = smallest_eigenvector(s2 / count_d - mean * mean.transpose());
        if (normal.dot((cloud.viewpoint - p).cast<double>()) < 0) normal = -normal;
        // The envelope (a quantile of the heights along the normal) minus the point's own
        // height averaged over a small ball (its noise averaged out).
        heights.resize(found);
        double own_sum = 0;
        int own_count = 0;
        for (std::size_t k = 0; k < found; ++k) {
          const double h = normal.x() * bx[k] + normal.y() * by[k] + normal.z() * bz[k];
          heights[k] = h;
          const bool own = bd2[k] <= own_r2;
          own_sum += own ? h : 0.0;
          own_count += own ? 1 : 0;
        }
        const auto q = static_cast<std::size_t>(static_cast<double>(params.quantile) *
                                                static_cast<double>(found - 1));
        const double envelope = kth_smallest(heights, q, bin);
        out.normals.x[v] = static_cast<float>(normal.x());
        out.normals.y[v] = static_cast<float>(normal.y());
        out.normals.z[v] = static_cast<float>(normal.z());
        out.concavity[v] = static_cast<float>(envelope - own_sum / std::max(own_count, 1));
      }
    }
  }
  return out;
}

}  // namespace groovetrace
