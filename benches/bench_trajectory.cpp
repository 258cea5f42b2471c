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

STAGE(BM_Trajectory);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
