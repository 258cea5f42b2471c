// The GFH descriptor on the CPU backend.
#include "bench_common.hpp"

namespace bench {
namespace {

void BM_CpuDescriptor(benchmark::State& state) {
  const Prepared& p = prepared(state.range(0));
  auto backend = make_cpu_backend();
  for (auto _ : state) {
    benchmark::DoNotOptimize(backend->descriptor(p.smoothed, p.normals, kRadius, p.u_b));
  }
  report_points(state, p.smoothed.size());
}

STAGE(BM_CpuDescriptor);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
