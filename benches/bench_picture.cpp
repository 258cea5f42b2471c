// overview.png of a run (host/src/picture): the picture `run` writes beside its outputs and the
// batch's 240 px thumbnail, from the run's result to PNG bytes. Its cost counts against the
// default run's time budget.
#include <groovetrace/pipeline.hpp>

#include "bench_common.hpp"
#include "picture/overview.hpp"
#include "run/overview.hpp"

namespace bench {
namespace {

// The default run's result on the frame (robust method, cpu backend: the picture does not
// depend on the backend).
const RunResult& robust_result(int width) {
  static std::map<int, RunResult> results;
  auto it = results.find(width);
  if (it == results.end()) {
    auto backend = make_backend("cpu");
    it = results.emplace(width, run_pipeline(frame(width), Params{}, *backend)).first;
  }
  return it->second;
}

void BM_OverviewPng(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const RunResult& result = robust_result(width);
  for (auto _ : state) {
    benchmark::DoNotOptimize(run_overview_png(frame(width), result, Params{}, "frame.pcd", 0));
  }
  report_points(state, frame(width).size());
}

void BM_ThumbnailPng(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const RunResult& result = robust_result(width);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        run_overview_png(frame(width), result, Params{}, "frame.pcd", picture::kThumbnailSide));
  }
  report_points(state, frame(width).size());
}

BENCHMARK(BM_OverviewPng)->Arg(640)->Arg(1280)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ThumbnailPng)->Arg(640)->Arg(1280)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
