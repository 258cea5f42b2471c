// `groovetrace run SCAN -o OUTDIR`: the whole pipeline on one scan.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <future>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/pipeline.hpp>
#include <map>
#include <memory>

#include "commands.hpp"
#include "param_flags.hpp"
#include "pending_backend.hpp"

namespace groovetrace::cli {
namespace {

struct RunOptions {
  std::string scan, out_dir;
  bool quiet = false;
  std::shared_ptr<ParamFlags> params = std::make_shared<ParamFlags>();
};

int run_checked(const RunOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> param_warnings;
  const Params params = parse_params(*opt.params, param_warnings);
  auto say = [&](const char* fmt, auto... args) {
    if (!opt.quiet) {
      std::printf(fmt, args...);
      std::fflush(stdout);
    }
  };

  // The backend's set-up (about 0.1 s for PoCL) overlaps the read and whatever CPU work comes
  // before the first stage that needs it (the robust method's voxels).
  PendingBackend backend(
      std::async(std::launch::async,
                 [&params] { return make_backend(params.backend, params.device); }),
      [&](FeatureBackend& ready) {
        say("groovetrace: backend %s (%s)\n", ready.name().c_str(), ready.device().c_str());
      });
  ReadOptions ro;
  ro.units_scale = params.units_scale;
  ro.intrinsics_path = params.intrinsics_file;
  const Cloud cloud = read_cloud(opt.scan, ro);
  const double load_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  say("groovetrace: read %s: %zu points (%ux%u), %zu valid [%.0f ms]\n", opt.scan.c_str(),
      cloud.size(), cloud.width, cloud.height, cloud.count_valid(), load_ms);

  RunResult result = run_pipeline(cloud, params, backend, [&](const std::string& stage, double ms) {
    say("groovetrace: %-10s %8.0f ms\n", stage.c_str(), ms);
  });
  result.timings_ms.insert(result.timings_ms.begin(), {"load", load_ms});
  // A backend that fell back (auto without a usable OpenCL device) says why, in report.json too.
  result.warnings.insert(result.warnings.begin(), param_warnings.begin(), param_warnings.end());
  if (!backend.warning().empty())
    result.warnings.insert(result.warnings.begin(), backend.warning());
  for (const auto& w : result.warnings)
    std::fprintf(stderr, "groovetrace: warning: %s\n", w.c_str());

  const auto t_write = std::chrono::steady_clock::now();
  const double before_write_ms = std::chrono::duration<double, std::milli>(t_write - t0).count();
  auto files = render_outputs(cloud, result, params, opt.scan, before_write_ms);
  write_outputs(opt.out_dir, files);
  const double write_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_write).count();
  say("groovetrace: write      %8.0f ms\n", write_ms);
  const Trajectory& best = result.trajectories.front();
  say("groovetrace: %zu groove points, %zu waypoints (%s frame), %.1f mm long\n",
      static_cast<std::size_t>(std::count(result.groove.begin(), result.groove.end(), 1)),
      best.waypoints.size(), best.frame.c_str(), best.length * 1000);
  say("groovetrace: outputs in %s:", opt.out_dir.c_str());
  for (const auto& f : files) say(" %s", f.first.c_str());
  say("\n");
  return 0;
}

// OUTDIR is checked before any work, so a long run is not lost to it; once it is, any failure
// replaces the earlier outputs by a report.json that says why (no stale program stays).
int run(const RunOptions& opt) {
  check_output_dir(opt.out_dir);
  try {
    return run_checked(opt);
  } catch (const std::exception& e) {
    const auto* error = dynamic_cast<const Error*>(&e);
    write_failure_report(opt.out_dir, opt.scan, error ? error->code() : ExitCode::kInternal,
                         e.what());
    throw;
  }
}

}  // namespace

Command add_run_command(CLI::App& app) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* sub = app.add_subcommand("run", "detect the groove in SCAN and write the outputs");
  sub->add_option("scan", opt->scan, "input scan (.pcd, .ply, or a 16-bit depth .png)")->required();
  sub->add_option("-o,--output", opt->out_dir, "output directory (created if missing)")->required();
  sub->add_flag("-q,--quiet", opt->quiet, "print nothing but warnings and errors");
  add_param_flags(sub, opt->params);
  return {sub, [opt] { return run(*opt); }};
}

}  // namespace groovetrace::cli
