// Uses groovetrace as a library: builds a small V-groove cloud in memory, runs the feature
// backend and detection stages, and prints what was found. Exit 0 when a groove is found.
#include <cmath>
#include <cstdio>
#include <groovetrace/features.hpp>
#include <groovetrace/paper.hpp>
#include <groovetrace/pipeline.hpp>

int main() {
  using namespace groovetrace;
  // A 200 x 200 grid of 0.5 mm pitch at 0.4 m depth with a 10 mm wide, 4 mm deep V along y.
  Cloud cloud;
  cloud.width = 200;
  cloud.height = 200;
  cloud.resize(200 * 200);
  for (int r = 0; r < 200; ++r) {
    for (int c = 0; c < 200; ++c) {
      const float x = (c - 100) * 0.0005f, y = (r - 100) * 0.0005f;
      const float groove = std::max(0.0f, 0.004f * (1 - std::abs(x) / 0.005f));
      const std::size_t i = r * 200 + c;
      cloud.x[i] = x;
      cloud.y[i] = y;
      cloud.z[i] = 0.4f + groove;
    }
  }
  auto backend = make_backend("cpu");
  bool found = true;
  for (const Method method : {Method::robust, Method::paper}) {
    Params params;
    params.method = method;
    params.paper.slices = 10;
    const RunResult result = run_pipeline(cloud, params, *backend);
    const Trajectory& path = result.trajectories.front();
    std::printf("groovetrace %s, %s method: %zu groove points, %zu waypoints, %.1f mm long\n",
                version(), to_string(method),
                static_cast<std::size_t>(std::count(result.groove.begin(), result.groove.end(), 1)),
                path.waypoints.size(), path.length * 1000);
    found = found && path.waypoints.size() >= 2;
  }
  return found ? 0 : 1;
}
