#include "batch/scan_dir.hpp"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/pipeline.hpp>
#include <sstream>

#include "batch/pool.hpp"
#include "picture/overview.hpp"
#include "run/overview.hpp"

namespace groovetrace::batch {
namespace {

namespace fs = std::filesystem;

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The counts of a finished run.
void fill_counts(ScanRow& row, const Cloud& cloud, const RunResult& result) {
  row.points = cloud.size();
  row.valid_points = cloud.count_valid();
  for (std::uint8_t g : result.groove) row.groove_points += g;
  row.seams =
      result.method == Method::paper
          ? static_cast<int>(result.paper.detection.components)
          : static_cast<int>(std::count_if(result.robust.seams.begin(), result.robust.seams.end(),
                                           [](const SeamCandidate& s) { return s.accepted; }));
  row.exported = static_cast<int>(result.trajectories.size());
  row.waypoints = result.trajectories.front().waypoints.size();
  row.length_m = result.trajectories.front().length;
  row.stages_ms = result.timings_ms;
  if (!result.warnings.empty()) row.message = "warning: " + result.warnings.front();
}

bool named_by(const char* variable, const std::string& path) {
  const char* needle = std::getenv(variable);
  return needle && *needle && path.find(needle) != std::string::npos;
}

// Tests make a worker fail on purpose, as a reader or kernel bug would: a scan whose path
// contains GROOVETRACE_TEST_CRASH_SCAN raises SIGSEGV, one that contains
// GROOVETRACE_TEST_HANG_SCAN never finishes.
void test_hooks(const std::string& path) {
  if (named_by("GROOVETRACE_TEST_CRASH_SCAN", path)) {
    std::signal(SIGSEGV, SIG_DFL);  // a runtime's own handler must not swallow it
    std::raise(SIGSEGV);
  }
  while (named_by("GROOVETRACE_TEST_HANG_SCAN", path)) ::pause();
}

std::vector<std::pair<std::string, std::string>> run_files(const ScanJob& job, const Params& p,
                                                           FeatureBackend& backend, ScanRow& row) {
  const auto t0 = std::chrono::steady_clock::now();
  ReadOptions ro;
  ro.units_scale = p.units_scale;
  ro.intrinsics_path = p.intrinsics_file;
  const Cloud cloud = read_cloud(job.path, ro);
  const double load_ms = ms_since(t0);
  RunResult result = run_pipeline(cloud, p, backend);
  result.timings_ms.insert(result.timings_ms.begin(), {"load", load_ms});
  if (!backend.warning().empty())
    result.warnings.insert(result.warnings.begin(), backend.warning());
  auto files = render_outputs(cloud, result, p, job.path, ms_since(t0));
  files.emplace_back("thumbnail.png",
                     run_overview_png(cloud, result, p, job.path, picture::kThumbnailSide));
  fill_counts(row, cloud, result);
  return files;
}

}  // namespace

Params job_params(const Params& batch, const ScanJob& job) {
  Params p = batch;
  if (!job.flange_pose.empty()) p.flange_pose_file = job.flange_pose;
  if (!job.hand_eye.empty()) p.hand_eye_file = job.hand_eye;
  if (job.viewpoint) p.viewpoint = job.viewpoint;
  return p;
}

std::string params_hash(const Params& params) { return hex64(fnv1a64(params_json(params))); }

ScanRow run_scan(const ScanJob& job, const Params& batch_params, FeatureBackend& backend,
                 const std::string& out_dir) {
  const auto t0 = std::chrono::steady_clock::now();
  const Params p = job_params(batch_params, job);
  ScanRow row;
  row.scan = job.path;
  row.dir = job.rel;
  row.params_hash = params_hash(p);
  std::vector<std::pair<std::string, std::string>> files;
  try {
    row.input_hash = file_hash(job.path);
    test_hooks(job.path);
    files = run_files(job, p, backend, row);
    row.status = "ok";
  } catch (const Error& e) {
    row.status = status_name(e.code());
    row.exit_code = static_cast<int>(e.code());
    row.message = e.what();
    files.clear();
  } catch (const std::exception& e) {
    row.status = "error";
    row.exit_code = static_cast<int>(ExitCode::kInternal);
    row.message = std::string("internal error: ") + e.what();
    files.clear();
  }
  row.total_ms = ms_since(t0);
  files.emplace_back("scan.json", row_json(row));
  write_scan_dir(out_dir, job.rel, files);
  return row;
}

ScanRow failure_row(const ScanJob& job, const std::string& status, int exit_code,
                    const std::string& message) {
  ScanRow row;
  row.scan = job.path;
  row.dir = job.rel;
  row.status = status;
  row.exit_code = exit_code;
  row.message = message;
  return row;
}

void write_failure(const ScanRow& row, const std::string& out_dir) {
  write_scan_dir(out_dir, row.dir, {{"scan.json", row_json(row)}});
}

void write_scan_dir(const std::string& out_dir, const std::string& rel,
                    const std::vector<std::pair<std::string, std::string>>& files) {
  const fs::path partial = fs::path(out_dir) / ".partial";
  const std::string tag = partial_name(rel);
  const fs::path tmp = partial / tag, old = partial / (tag + "-old");
  const fs::path final_dir = fs::path(out_dir) / rel;
  std::error_code ec;
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp, ec);
  if (ec) throw InputError("cannot create " + tmp.string() + ": " + ec.message());
  for (const auto& [name, bytes] : files) write_file_atomic((tmp / name).string(), bytes);
  fs::create_directories(final_dir.parent_path(), ec);
  fs::remove_all(old, ec);
  if (fs::exists(final_dir)) fs::rename(final_dir, old, ec);
  if (ec) throw InputError("cannot replace " + final_dir.string() + ": " + ec.message());
  fs::rename(tmp, final_dir, ec);
  if (ec) throw InputError("cannot write " + final_dir.string() + ": " + ec.message());
  fs::remove_all(old, ec);
}

bool read_row(const std::string& out_dir, const std::string& rel, ScanRow& row) {
  const fs::path path = fs::path(out_dir) / rel / "scan.json";
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    row = row_from_json(ss.str(), path.string());
  } catch (const InputError&) {
    return false;
  }
  return true;
}

}  // namespace groovetrace::batch
