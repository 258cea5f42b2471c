// Stage 1 of the robust method: concave-crease evidence at the groove's own scale.
//
// Normals at a few millimetres vary by 10-20 degrees on a D415 scan (correlated undulation,
// 1 mm depth steps), so the evidence here is a height, not an angle: how far a point lies
// below the upper envelope of everything within ~a groove width of it. A V of depth D scores
// about 0.7 D at its root, a flat the noise's spread (tenths of a mm), a convex edge or a
// pipe's crown about zero. Points are first merged on 1 mm voxels so that the measure sees
// surface area, not the sensor's uneven sampling (steep walls, distance).

#include <algorithm>
#include <cmath>
#include <groovetrace/eigen3.hpp>
#include <groovetrace/robust.hpp>
#include <unordered_map>

#include "neighbor_grid.hpp"

namespace groovetrace {
namespace {

// The top surface must hold only a fifth of the ball for the envelope to find it: a groove as
// wide as the scale leaves about a third.
constexpr double kEnvelopeQuantile = 0.8;
// The point's own height is the mean over this fraction of the scale (3 mm at 10 mm).
constexpr double kOwnRadius = 0.3;

std::uint64_t voxel_key(const Eigen::Vector3f& p, double inv_cell) {
  const std::uint64_t m = (1u << 21) - 1;
  auto c = [&](float v) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v * inv_cell))) & m;
  };
  return c(p.x()) | (c(p.y()) << 21) | (c(p.z()) << 42);
}

// Median and 1.4826 * MAD of the finite values (NaN for none).
std::pair<double, double> robust_location_scale(const std::vector<float>& values) {
  std::vector<float> v;
  v.reserve(values.size());
  for (float x : values) {
    if (std::isfinite(x)) v.push_back(x);
  }
  if (v.empty()) return {NAN, NAN};
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  const double median = v[mid];
  for (float& x : v) x = static_cast<float>(std::abs(x - median));
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return {median, 1.4826 * v[mid]};
}

Cloud as_cloud(const std::vector<Eigen::Vector3f>& points) {
  Cloud c;
  c.resize(points.size());
  c.width = static_cast<std::uint32_t>(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    c.x[i] = points[i].x();
    c.y[i] = points[i].y();
    c.z[i] = points[i].z();
  }
  return c;
}

}  // namespace

CreaseMap crease_map(const Cloud& cloud, const RobustParams& params) {
  CreaseMap map;
  const double inv_cell = 1.0 / params.cell;
  map.voxel.assign(cloud.size(), -1);
  std::unordered_map<std::uint64_t, std::int32_t> index;
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    const Eigen::Vector3f p = cloud.point(i);
    const auto [it, fresh] = index.emplace(voxel_key(p, inv_cell), static_cast<int>(sums.size()));
    if (fresh) {
      sums.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    sums[it->second] += p.cast<double>();
    ++counts[it->second];
    map.voxel[i] = it->second;
  }
  const std::size_t n = sums.size();
  map.points.resize(n);
  for (std::size_t v = 0; v < n; ++v) map.points[v] = (sums[v] / counts[v]).cast<float>();
  map.normals.assign(n, Eigen::Vector3f::Constant(NAN));
  map.concavity.assign(n, NAN);

  const Cloud voxels = as_cloud(map.points);
  const float radius = static_cast<float>(params.scale);
  const NeighborGrid grid(voxels, radius);
  // A plane through fewer voxels than a tenth of a flat disc's is an edge or a speck.
  const double disc = 3.14159 * params.scale * params.scale / (params.cell * params.cell);
  const int min_count = std::max(10, static_cast<int>(0.1 * disc));
  const double own_r2 = std::pow(kOwnRadius * params.scale, 2);
  const std::int64_t count = static_cast<std::int64_t>(n);
#pragma omp parallel
  {
    std::vector<double> heights, own;
#pragma omp for schedule(dynamic, 256)
    for (std::int64_t v = 0; v < count; ++v) {
      const Eigen::Vector3f p = map.points[v];
      Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
      Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
      int found = 0;
      grid.for_each_within(p, radius, [&](std::uint32_t j, float) {
        const Eigen::Vector3d d = (map.points[j] - p).cast<double>();
        s1 += d;
        s2 += d * d.transpose();
        ++found;
      });
      if (found < min_count) continue;
      const Eigen::Vector3d mean = s1 / found;
      Eigen::Vector3d normal = smallest_eigenvector(s2 / found - mean * mean.transpose());
      if (normal.dot((cloud.viewpoint - p).cast<double>()) < 0) normal = -normal;
      // Upper envelope of the neighbourhood (a high quantile of the heights along the normal)
      // minus the point's own height averaged over a small ball (its noise averaged out).
      heights.clear();
      own.clear();
      grid.for_each_within(p, radius, [&](std::uint32_t j, float d2) {
        const double h = normal.dot((map.points[j] - p).cast<double>());
        heights.push_back(h);
        if (d2 <= own_r2) own.push_back(h);
      });
      const std::size_t q = static_cast<std::size_t>(kEnvelopeQuantile * (heights.size() - 1));
      std::nth_element(heights.begin(), heights.begin() + q, heights.end());
      double own_mean = 0;
      for (double h : own) own_mean += h;
      own_mean /= std::max<std::size_t>(own.size(), 1);
      map.normals[v] = normal.cast<float>();
      map.concavity[v] = static_cast<float>(heights[q] - own_mean);
    }
  }
  const auto [median, sigma] = robust_location_scale(map.concavity);
  map.median = median;
  map.sigma = sigma;
  // The floor keeps noise-free scans, whose flats have sigma ~ 0, from turning float rounding
  // into candidates; 1% of the scale is far below any groove the scale is meant for.
  map.threshold = median + std::max(params.threshold_k * sigma, 0.01 * params.scale);
  return map;
}

CreaseNodes crease_nodes(const CreaseMap& map, const RobustParams& params) {
  std::vector<std::int32_t> cand;
  std::vector<Eigen::Vector3f> cand_points;
  for (std::size_t v = 0; v < map.points.size(); ++v) {
    if (std::isfinite(map.concavity[v]) && map.concavity[v] > map.threshold) {
      cand.push_back(static_cast<std::int32_t>(v));
      cand_points.push_back(map.points[v]);
    }
  }
  CreaseNodes nodes;
  if (cand.empty()) return nodes;
  const Cloud cc = as_cloud(cand_points);
  const float radius = static_cast<float>(params.scale);
  const NeighborGrid grid(cc, radius);
  const double thr = map.threshold;
  const std::int64_t count = static_cast<std::int64_t>(cand.size());
  std::vector<std::uint8_t> keep(cand.size(), 0);
  std::vector<Eigen::Vector3d> tangent(cand.size(), Eigen::Vector3d::Zero());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t k = 0; k < count; ++k) {
    const Eigen::Vector3f p = cand_points[k];
    const Eigen::Vector3d n = map.normals[cand[k]].cast<double>();
    const double ck = map.concavity[cand[k]];
    // Seam direction: the long axis of the candidates around, weighted by how far above the
    // threshold they are (the deep core near the root is a line even where the band is wide),
    // in the tangent plane.
    double sw = 0;
    Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
    grid.for_each_within(p, radius, [&](std::uint32_t j, float) {
      const double w = map.concavity[cand[j]] - thr;
      Eigen::Vector3d d = (cand_points[j] - p).cast<double>();
      d -= d.dot(n) * n;
      sw += w;
      s1 += w * d;
      s2 += w * d * d.transpose();
    });
    if (sw <= 0) continue;
    const Eigen::Vector3d mean = s1 / sw;
    const SymEigen3 eig = eigen_sym3(s2 / sw - mean * mean.transpose());
    const Eigen::Vector3d t = eig.vectors.col(2);
    // Deepest across the seam: no candidate in a one-cell slab across t is deeper.
    bool is_max = true;
    const double half = params.cell;
    grid.for_each_within(p, radius, [&](std::uint32_t j, float) {
      if (!is_max || static_cast<std::int64_t>(j) == k) return;
      if (std::abs((cand_points[j] - p).cast<double>().dot(t)) > half) return;
      const double cj = map.concavity[cand[j]];
      if (cj > ck || (cj == ck && static_cast<std::int64_t>(j) < k)) is_max = false;
    });
    if (is_max) {
      keep[k] = 1;
      tangent[k] = t;
    }
  }
  for (std::size_t k = 0; k < cand.size(); ++k) {
    if (!keep[k]) continue;
    nodes.voxel.push_back(cand[k]);
    nodes.tangent.push_back(tangent[k]);
  }
  return nodes;
}

}  // namespace groovetrace
