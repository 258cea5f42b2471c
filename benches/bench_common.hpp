#pragma once
// Shared set-up of the per-stage benchmark programs: rendered V-groove frames (640x480 and
// 1280x720, 0.4 m, D415-like depth noise) and the inputs each stage consumes.
#include <benchmark/benchmark.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <groovetrace/detect.hpp>
#include <groovetrace/features.hpp>
#include <groovetrace/trajectory.hpp>
#include <map>

#include "../tests/scenes.hpp"

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

#define STAGE(fn) \
  BENCHMARK(fn)->Arg(640)->Arg(1280)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5)

}  // namespace bench
