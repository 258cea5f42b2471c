// Threshold and connected components.
#include "bench_common.hpp"

namespace bench {
namespace {

void BM_Detect(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(detect_groove(p.smoothed, p.descriptor, 4.5, 50, kRadius));
  }
  report_points(state, p.smoothed.size());
}

STAGE(BM_Detect);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
