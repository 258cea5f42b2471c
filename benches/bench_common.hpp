#pragma once
// Shared set-up of the per-stage benchmark programs: rendered V-groove frames (640x480 and
// 1280x720, 0.4 m, D415-like depth noise) and the inputs each stage consumes.
#include <benchmark/benchmark.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <groovetrace/features.hpp>
#include <groovetrace/opencl.hpp>
#include <groovetrace/paper.hpp>
#include <groovetrace/trajectory.hpp>
#include <map>
#include <memory>

#include "support/scenes.hpp"

namespace bench {

using namespace groovetrace;
constexpr float kRadius = 0.003f;

// Frames are rendered once per resolution and shared by all benchmarks.
inline const Cloud& frame(int width) {
  static std::map<int, Cloud> cache;
  auto it = cache.find(width);
  if (it == cache.end()) {
    test::VGrooveScene s;
    s.width = width;
    s.height = width == 1280 ? 720 : 480;
    s.tilt_deg = 12;
    // D415 RMS at 0.4 m: Z^2 * 0.08 / (fx * 0.055).
    const double fx = 0.5 * width / std::tan(32.5 * M_PI / 180);
    s.noise_sigma = 0.4 * 0.4 * 0.08 / (fx * 0.055);
    it = cache.emplace(width, test::render_vgroove(s).cloud).first;
  }
  return it->second;
}

struct Prepared {
  Cloud smoothed;
  Normals normals;
  Eigen::Vector3f u_b;
  std::vector<float> descriptor;
  Detection detection;
};

inline const Prepared& prepared(int width) {
  static std::map<int, Prepared> cache;
  auto it = cache.find(width);
  if (it == cache.end()) {
    auto backend = make_cpu_backend();
    Prepared p;
    p.smoothed = backend->smooth(frame(width), SmoothParams{});
    p.normals = backend->normals(p.smoothed, kRadius, 5);
    p.u_b = benchmark_normal(p.normals);
    p.descriptor = backend->descriptor(p.smoothed, p.normals, kRadius, p.u_b);
    p.detection = detect_groove(p.smoothed, p.descriptor, 4.5, 50, kRadius);
    it = cache.emplace(width, std::move(p)).first;
  }
  return it->second;
}

inline void report_points(benchmark::State& state, std::size_t n) {
  state.counters["points"] = static_cast<double>(n);
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
}

inline pcl::PointCloud<pcl::PointXYZ>::Ptr to_pcl(const Cloud& c) {
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  out->width = c.width;
  out->height = c.height;
  out->is_dense = false;
  out->points.resize(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) out->points[i] = {c.x[i], c.y[i], c.z[i]};
  return out;
}

// What the organized kernels walk (kernels/neighbors.cl), replayed on the host for the flop
// counts of docs/benchmarks.md: per valid query point, the candidates tested (one per lane and
// window position, `lanes` queries per work-item sharing the widest ellipse) and the
// neighbours within r among them. The slack (how far points sit off their pixel rays: about 0
// for a rendered frame, a few tenths of a pixel after smoothing) is the 90th percentile of the
// projection residuals, as the backend estimates it, here from the frames' known intrinsics.
struct WalkStats {
  double candidates_per_point = 0, neighbours_per_point = 0, slack_px = 0;
  double active_fraction = 0;  // of window positions, those where some lane has a neighbour
};
inline WalkStats organized_walk(const Cloud& c, float r, int lanes) {
  const int w = static_cast<int>(c.width), h = static_cast<int>(c.height);
  const double f = 0.5 * w / std::tan(32.5 * M_PI / 180);  // the rendered frames' fx = fy
  std::vector<double> residual;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (!c.valid(i)) continue;
    const double du = static_cast<double>(i % w) - (f * c.x[i] / c.z[i] + 0.5 * w);
    const double dv = static_cast<double>(i / w) - (f * c.y[i] / c.z[i] + 0.5 * h);
    residual.push_back(std::max(std::abs(du), std::abs(dv)));
  }
  auto q = residual.begin() + static_cast<std::ptrdiff_t>(0.9 * (residual.size() - 1));
  std::nth_element(residual.begin(), q, residual.end());
  const float slack = static_cast<float>(*q);
  double candidates = 0, neighbours = 0, queries = 0, steps = 0, active_steps = 0;
  for (int row = 0; row < h; ++row) {
    for (int c0 = 0; c0 < w; c0 += lanes) {
      float rad = 0;
      int valid = 0;
      for (int q = c0; q < std::min(c0 + lanes, w); ++q) {
        const std::size_t i = static_cast<std::size_t>(row) * w + q;
        if (!c.valid(i)) continue;
        ++valid;
        const Eigen::Vector3f p = c.point(i);
        rad = std::max(rad, r * p.norm() / (p.z() * (p.z() - r)));
      }
      if (valid == 0) continue;
      queries += valid;
      const float rx = static_cast<float>(f) * rad * 1.001f + 1e-3f + 2 * slack, ry = rx;
      const int hy = static_cast<int>(std::ceil(ry));
      for (int rr = std::max(row - hy, 0); rr <= std::min(row + hy, h - 1); ++rr) {
        const float dv = static_cast<float>(rr - row) / ry;
        const int hw = static_cast<int>(std::ceil(rx * std::sqrt(std::max(0.0f, 1 - dv * dv))));
        const int t0 = std::max(-hw, -c0 - (lanes - 1)), t1 = std::min(hw, w - 1 - c0);
        if (t0 > t1) continue;
        candidates += static_cast<double>(t1 - t0 + 1) * lanes;
        for (int t = t0; t <= t1; ++t) {
          int found = 0;
          for (int q = c0; q < std::min(c0 + lanes, w); ++q) {
            const std::size_t i = static_cast<std::size_t>(row) * w + q;
            const int col = q + t;
            if (!c.valid(i) || col < 0 || col >= w) continue;
            const std::size_t j = static_cast<std::size_t>(rr) * w + col;
            if (c.valid(j) && (c.point(j) - c.point(i)).squaredNorm() <= r * r) ++found;
          }
          neighbours += found;
          steps += 1;
          active_steps += found > 0 ? 1 : 0;
        }
      }
    }
  }
  return {candidates / queries, neighbours / queries, slack, active_steps / steps};
}

// The OpenCL backend on the default device, created once (its program build is not what is
// measured); nullptr without a device. OpenCL benchmarks call their stage once before timing:
// PoCL compiles each kernel's work-group function on its first launch (and keeps it in its
// disk cache, so a new process does not pay it again).
inline FeatureBackend* opencl_backend() {
  static std::unique_ptr<FeatureBackend> backend = [] {
    try {
      return make_opencl_backend();
    } catch (const std::exception&) {
      return std::unique_ptr<FeatureBackend>();
    }
  }();
  return backend.get();
}

// Skips the benchmark (with a note in the output) when there is no OpenCL device.
#define REQUIRE_OPENCL(var)                  \
  FeatureBackend* var = opencl_backend();    \
  if (var == nullptr) {                      \
    state.SkipWithError("no OpenCL device"); \
    return;                                  \
  }

#define STAGE(fn) \
  BENCHMARK(fn)->Arg(640)->Arg(1280)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5)

}  // namespace bench
