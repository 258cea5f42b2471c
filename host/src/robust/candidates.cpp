// Stage 1 of the robust method: concave-crease evidence at the groove's own scale.
//
// Normals at a few millimetres vary by 10-20 degrees on a D415 scan (correlated undulation,
// 1 mm depth steps), so the evidence here is a height, not an angle: how far a point lies
// below the upper envelope of everything within ~a groove width of it. A V of depth D scores
// about 0.7 D at its root, a flat the noise's spread (tenths of a mm), a convex edge or a
// pipe's crown about zero. Points are first merged on 1 mm voxels so that the measure sees
// surface area, not the sensor's uneven sampling (steep walls, distance).

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <groovetrace/features.hpp>

#include "core/eigen3.hpp"
#include "core/neighbor_grid.hpp"
#include "core/stats.hpp"
#include "robust/stages.hpp"

namespace groovetrace {
namespace {

// The top surface must hold only a fifth of the ball for the envelope to find it: a groove as
// wide as the scale leaves about a third.
constexpr float kEnvelopeQuantile = 0.8f;
// The point's own height is the mean over this fraction of the scale (3 mm at 10 mm).
constexpr double kOwnRadius = 0.3;

// Stable LSD radix sort of (key, index) pairs by key, 16 bits a pass, as many passes as the
// largest key needs (two for a scan's voxels): a comparison sort of a frame's points costs
// several times more.
void radix_sort(std::vector<std::pair<std::uint64_t, std::uint32_t>>& items) {
  std::uint64_t max_key = 0;
  for (const auto& e : items) max_key = std::max(max_key, e.first);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> out(items.size());
  std::vector<std::size_t> start(65537);
  for (int shift = 0; shift < 64 && (max_key >> shift) != 0; shift += 16) {
    std::fill(start.begin(), start.end(), 0);
    for (const auto& e : items) ++start[((e.first >> shift) & 0xFFFF) + 1];
    for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    for (const auto& e : items) out[start[(e.first >> shift) & 0xFFFF]++] = e;
    items.swap(out);
  }
}

// Where the voxel grid's planes lie, in cells from the origin. A depth camera quantizes depth
// (a D415 to 1 mm by default, 0.1 mm optionally), and a camera-frame cloud's z then sits
// exactly on the planes of a grid of 1 mm through the origin: which voxel a point falls in is
// decided by float rounding, half of them each way, and a change of depth far below the
// quantum (+-0.5 um, or a transform's rounding) moves half the points to the next voxel and
// changes the candidates, the nodes and the trajectory. Shifted by 0.45 cell, the planes lie
// 0.45 mm from every 1 mm level and 0.05 mm from every 0.1 mm level.
constexpr double kGridShift = 0.45;

// The valid points keyed by voxel: the voxel's index in the box of voxels around the cloud
// (x fastest, then y, then z), so that key order is spatial order and keys stay small.
std::vector<std::pair<std::uint64_t, std::uint32_t>> voxel_keys(const Cloud& cloud,
                                                                double inv_cell) {
  std::vector<std::array<std::int64_t, 3>> cells;
  std::vector<std::uint32_t> index;
  cells.reserve(cloud.size());
  index.reserve(cloud.size());
  std::array<std::int64_t, 3> lo{INT64_MAX, INT64_MAX, INT64_MAX},
      hi{INT64_MIN, INT64_MIN, INT64_MIN};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    const std::array<std::int64_t, 3> c{
        static_cast<std::int64_t>(std::floor(cloud.x[i] * inv_cell + kGridShift)),
        static_cast<std::int64_t>(std::floor(cloud.y[i] * inv_cell + kGridShift)),
        static_cast<std::int64_t>(std::floor(cloud.z[i] * inv_cell + kGridShift))};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], c[a]);
      hi[a] = std::max(hi[a], c[a]);
    }
    cells.push_back(c);
    index.push_back(static_cast<std::uint32_t>(i));
  }
  if (cells.empty()) return {};  // lo and hi are still INT64_MAX and INT64_MIN
  // Valid coordinates are finite floats, so each extent is below 2^21 voxels of 1 mm unless
  // the cloud spans kilometres; a key then still fits when the product does.
  const double nx = static_cast<double>(hi[0] - lo[0] + 1),
               ny = static_cast<double>(hi[1] - lo[1] + 1);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(cells.size());
  const bool dense = nx * ny * static_cast<double>(hi[2] - lo[2] + 1) < 1.8e19;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const auto& c = cells[k];
    std::uint64_t key;
    if (dense) {
      key = static_cast<std::uint64_t>(c[0] - lo[0]) +
            static_cast<std::uint64_t>(nx) *
                (static_cast<std::uint64_t>(c[1] - lo[1]) +
                 static_cast<std::uint64_t>(ny) * static_cast<std::uint64_t>(c[2] - lo[2]));
    } else {  // an absurd extent: 21 bits per axis, wrapping (voxels still grouped, not ordered)
      const std::uint64_t m = (1u << 21) - 1;
      key = (static_cast<std::uint64_t>(c[0]) & m) |
            ((static_cast<std::uint64_t>(c[1]) & m) << 21) |
            ((static_cast<std::uint64_t>(c[2]) & m) << 42);
    }
    keyed[k] = {key, index[k]};
  }
  return keyed;
}

// Median and 1.4826 * MAD of the finite values (NaN for none).
std::pair<double, double> robust_location_scale(const std::vector<float>& values) {
  std::vector<float> v;
  v.reserve(values.size());
  for (float x : values) {
    if (std::isfinite(x)) v.push_back(x);
  }
  if (v.empty()) return {NAN, NAN};
  const double median = upper_median(v);
  return {median, mad_sigma(std::move(v), median)};
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

// The candidate voxels (concavity above the threshold): their indices and centroids (m).
struct Candidates {
  std::vector<std::int32_t> voxel;
  std::vector<Eigen::Vector3f> points;
};

Candidates candidates_of(const CreaseMap& map) {
  Candidates cand;
  for (std::size_t v = 0; v < map.points.size(); ++v) {
    if (std::isfinite(map.concavity[v]) && map.concavity[v] > map.threshold) {
      cand.voxel.push_back(static_cast<std::int32_t>(v));
      cand.points.push_back(map.points[v]);
    }
  }
  return cand;
}

// The seam direction `t` (unit) at candidate k: the long axis of the candidates within
// `radius` (m), weighted by how far above the threshold they are (the deep core near the root
// is a line even where the band is wide), in the tangent plane. False when none weighs.
bool seam_direction(const CreaseMap& map, const Candidates& cand, const NeighborGrid& grid,
                    float radius, std::int64_t k, Eigen::Vector3d& t) {
  const Eigen::Vector3f p = cand.points[k];
  const Eigen::Vector3d n = map.normals[cand.voxel[k]].cast<double>();
  double sw = 0;
  Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
  grid.for_each_within(p, radius, [&](std::uint32_t j, float) {
    const double w = map.concavity[cand.voxel[j]] - map.threshold;
    Eigen::Vector3d d = (cand.points[j] - p).cast<double>();
    d -= d.dot(n) * n;
    sw += w;
    s1 += w * d;
    s2 += w * d * d.transpose();
  });
  if (sw <= 0) return false;
  const Eigen::Vector3d mean = s1 / sw;
  const SymEigen3 eig = eigen_sym3(s2 / sw - mean * mean.transpose());
  t = eig.vectors.col(2);
  return true;
}

// Whether candidate k is the deepest across the seam: no candidate within `radius` (m) and
// `half` (m) of it along `t` is deeper (ties: the lower index wins).
bool deepest_across(const CreaseMap& map, const Candidates& cand, const NeighborGrid& grid,
                    float radius, double half, std::int64_t k, const Eigen::Vector3d& t) {
  const Eigen::Vector3f p = cand.points[k];
  const double ck = map.concavity[cand.voxel[k]];
  bool is_max = true;
  grid.for_each_within(p, radius, [&](std::uint32_t j, float) {
    if (!is_max || static_cast<std::int64_t>(j) == k) return;
    if (std::abs((cand.points[j] - p).cast<double>().dot(t)) > half) return;
    const double cj = map.concavity[cand.voxel[j]];
    if (cj > ck || (cj == ck && static_cast<std::int64_t>(j) < k)) is_max = false;
  });
  return is_max;
}

}  // namespace

CreaseMap crease_map(const Cloud& cloud, const RobustParams& params) {
  const auto cpu = make_cpu_backend();
  return crease_map(cloud, params, *cpu);
}

CreaseMap crease_map(const Cloud& cloud, const RobustParams& params, FeatureBackend& backend) {
  CreaseMap map;
  const double inv_cell = 1.0 / params.cell;
  map.voxel.assign(cloud.size(), -1);
  // Voxels by sorting the points' voxel keys (a hash map costs an allocation per point); the
  // voxels come out in key order, x fastest, so neighbours in space are near in memory.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed = voxel_keys(cloud, inv_cell);
  radix_sort(keyed);
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  for (std::size_t k = 0; k < keyed.size(); ++k) {
    if (k == 0 || keyed[k].first != keyed[k - 1].first) {
      sums.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    const std::uint32_t i = keyed[k].second;
    sums.back() += cloud.point(i).cast<double>();
    ++counts.back();
    map.voxel[i] = static_cast<std::int32_t>(sums.size() - 1);
  }
  const std::size_t n = sums.size();
  map.points.resize(n);
  for (std::size_t v = 0; v < n; ++v) map.points[v] = (sums[v] / counts[v]).cast<float>();
  map.normals.resize(n);

  // The per-voxel work (a plane and a quantile over ~300 voxels each) is the backend's.
  map.viewpoint = cloud.viewpoint;
  const Cloud voxels = voxel_cloud(map);
  CreaseParams cp;
  cp.radius = static_cast<float>(params.scale);
  cp.own_radius = static_cast<float>(kOwnRadius * params.scale);
  cp.quantile = kEnvelopeQuantile;
  // A plane through fewer voxels than a tenth of a flat disc's is an edge or a speck.
  const double disc = 3.14159 * params.scale * params.scale / (params.cell * params.cell);
  cp.min_neighbors = std::max(10, static_cast<int>(0.1 * disc));
  CreaseMeasure measure = backend.crease(voxels, cp);
  map.concavity = std::move(measure.concavity);
  for (std::size_t v = 0; v < n; ++v) map.normals[v] = measure.normals.normal(v);
  const auto [median, sigma] = robust_location_scale(map.concavity);
  map.median = median;
  map.sigma = sigma;
  set_threshold(map, params);
  return map;
}

void set_threshold(CreaseMap& map, const RobustParams& params) {
  // The floor keeps noise-free scans, whose flats have sigma ~ 0, from turning float rounding
  // into candidates; 1% of the scale is far below any groove the scale is meant for.
  map.threshold = map.median + std::max(params.threshold_k * map.sigma, 0.01 * params.scale);
}

Cloud voxel_cloud(const CreaseMap& map) {
  Cloud c = as_cloud(map.points);
  c.viewpoint = map.viewpoint;
  return c;
}

CreaseNodes crease_nodes(const CreaseMap& map, const RobustParams& params) {
  CreaseNodes nodes;
  const Candidates cand = candidates_of(map);
  if (cand.voxel.empty()) return nodes;
  const float radius = static_cast<float>(params.scale);
  const NeighborGrid grid(as_cloud(cand.points), radius);
  const std::int64_t count = static_cast<std::int64_t>(cand.voxel.size());
  std::vector<std::uint8_t> keep(cand.voxel.size(), 0);
  std::vector<Eigen::Vector3d> tangent(cand.voxel.size(), Eigen::Vector3d::Zero());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t k = 0; k < count; ++k) {
    Eigen::Vector3d t;
    if (!seam_direction(map, cand, grid, radius, k, t)) continue;
    if (deepest_across(map, cand, grid, radius, params.cell, k, t)) {
      keep[k] = 1;
      tangent[k] = t;
    }
  }
  for (std::size_t k = 0; k < cand.voxel.size(); ++k) {
    if (!keep[k]) continue;
    nodes.voxel.push_back(cand.voxel[k]);
    nodes.tangent.push_back(tangent[k]);
  }
  return nodes;
}

}  // namespace groovetrace
