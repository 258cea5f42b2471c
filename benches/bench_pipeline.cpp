// End to end as `groovetrace run --method paper` does it, on the 1280x720 (and 640x480) frame
// written as a binary PCD: read the file, smooth, normals, descriptor, detection, trajectory, and
// the five output files rendered and written. The OpenCL and CPU backends, and the paper's pipeline
// built from PCL (loadPCDFile, MovingLeastSquares, NormalEstimationOMP and the GFH over a
// kd-tree, then the same detection, trajectory and outputs).
#include <pcl/io/pcd_io.h>

#include <cstdlib>
#include <filesystem>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/pipeline.hpp>

#include "pcl_peers.hpp"

namespace bench {
namespace {

namespace fs = std::filesystem;

fs::path bench_dir() {
  const char* env = std::getenv("GT_BENCH_DIR");
  fs::path dir = env ? fs::path(env) : fs::temp_directory_path() / "groovetrace-bench";
  fs::create_directories(dir);
  return dir;
}

// The frame as a PCD file (written once per run; scripts/bench.sh also times the CLI on it).
const std::string& frame_pcd(int width) {
  static std::map<int, std::string> paths;
  auto it = paths.find(width);
  if (it == paths.end()) {
    const fs::path path = bench_dir() / ("frame" + std::to_string(width) + ".pcd");
    write_file_atomic(path.string(), pcd_bytes(frame(width)));
    it = paths.emplace(width, path.string()).first;
  }
  return it->second;
}

void run_groovetrace(const std::string& backend_name, int width) {
  const std::string& path = frame_pcd(width);
  const Cloud cloud = read_cloud(path);
  auto backend = make_backend(backend_name);
  Params params;
  params.method = Method::paper;  // the method whose features the backends compute
  params.backend = backend_name;
  const RunResult result = run_pipeline(cloud, params, *backend);
  write_outputs((bench_dir() / ("out-" + backend_name)).string(),
                render_outputs(cloud, result, params, path, 0.0));
}

void BM_RunOpenCl(benchmark::State& state) {
  REQUIRE_OPENCL(warm);
  run_groovetrace("opencl", static_cast<int>(state.range(0)));  // warm-up (bench_common.hpp)
  for (auto _ : state) run_groovetrace("opencl", static_cast<int>(state.range(0)));
  report_points(state, frame(state.range(0)).size());
}

void BM_RunCpu(benchmark::State& state) {
  for (auto _ : state) run_groovetrace("cpu", static_cast<int>(state.range(0)));
  report_points(state, frame(state.range(0)).size());
}

void BM_RunPcl(benchmark::State& state) {
  const std::string& path = frame_pcd(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto input = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    pcl::io::loadPCDFile(path, *input);
    auto smoothed = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>(pcl_mls(input, kRadius));
    const auto normals = pcl_normals(smoothed, kRadius, false, Eigen::Vector3f::Zero());
    const Eigen::Vector3f u_b = pcl_benchmark_normal(normals);
    RunResult r;
    r.method = Method::paper;
    r.score = pcl_gfh(smoothed, normals, kRadius, u_b);
    r.score_unit = "deg^2";
    // Detection, trajectory and outputs are groovetrace's: PCL has no counterpart.
    Cloud& cloud = r.paper.smoothed;
    cloud.resize(smoothed->size());
    r.normals.resize(smoothed->size());
    for (std::size_t i = 0; i < smoothed->size(); ++i) {
      cloud.x[i] = (*smoothed)[i].x;
      cloud.y[i] = (*smoothed)[i].y;
      cloud.z[i] = (*smoothed)[i].z;
      r.normals.x[i] = normals[i].normal_x;
      r.normals.y[i] = normals[i].normal_y;
      r.normals.z[i] = normals[i].normal_z;
    }
    cloud.width = static_cast<std::uint32_t>(smoothed->size());
    Params params;
    params.method = Method::paper;
    const PaperParams& pp = params.paper;
    r.paper.detection = detect_groove(cloud, r.score, pp.threshold, pp.min_component, kRadius);
    r.groove = r.paper.detection.groove;
    std::vector<std::uint8_t> largest(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      largest[i] = r.paper.detection.component_label[i] == 0 ? 1 : 0;
    }
    r.trajectories.push_back(paper_trajectory(cloud, r.normals, largest, pp.slices));
    r.backend = "pcl";
    write_outputs((bench_dir() / "out-pcl").string(), render_outputs(cloud, r, params, path, 0.0));
  }
  report_points(state, frame(state.range(0)).size());
}

STAGE(BM_RunOpenCl);
STAGE(BM_RunCpu);
STAGE(BM_RunPcl);

}  // namespace
}  // namespace bench

BENCHMARK_MAIN();
