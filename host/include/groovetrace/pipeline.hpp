#pragma once
// The whole `run`: features, detection, trajectory, frames, and the output files.

#include <groovetrace/cloud.hpp>
#include <groovetrace/paper.hpp>
#include <groovetrace/features.hpp>
#include <groovetrace/params.hpp>
#include <groovetrace/robust.hpp>
#include <groovetrace/trajectory.hpp>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace {

/// Everything a run computed, in input order.
struct RunResult {
  Cloud smoothed;                  ///< after MLS (metres, cloud frame)
  Normals normals;                 ///< oriented to the viewpoint
  Eigen::Vector3f benchmark_normal = Eigen::Vector3f::Zero();  ///< u_b
  std::vector<float> descriptor;   ///< D (deg^2)
  Detection detection;
  Trajectory trajectory;           ///< camera frame, or base frame when frames were given
  /// --method robust: the seams after the best, up to max_seams - 1, same frame as trajectory
  /// (written as trajectory_1.csv, ...).
  std::vector<Trajectory> extra_trajectories;
  /// --method robust: candidates, seams and scores (descriptor then holds the concavity, mm).
  RobustDetection robust;
  std::vector<std::pair<std::string, double>> timings_ms;  ///< per stage, in order
  std::vector<std::string> warnings;
  std::string backend, device;
};

/// Called after each stage with its name and duration (ms), e.g. to print progress.
using StageCallback = std::function<void(const std::string& stage, double ms)>;

/// Runs smoothing, normals, descriptor, detection and trajectory on `cloud` (metres).
/// Throws NoGrooveError when no groove is found, UsageError for bad parameters.
RunResult run_pipeline(const Cloud& cloud, const Params& params, FeatureBackend& backend,
                       const StageCallback& on_stage = {});

/// Checks parameter ranges; throws UsageError naming the offending parameter.
void validate(const Params& params);

/// The output files of a run, as bytes, keyed by file name (annotated.pcd, trajectory.csv,
/// trajectory.json, program.script, report.json; with --max-seams N > 1 also
/// trajectory_K.csv, trajectory_K.json and program_K.script for the K-th next seam).
std::vector<std::pair<std::string, std::string>> render_outputs(
    const Cloud& input, const RunResult& result, const Params& params,
    const std::string& input_path, double total_ms);

/// Writes each rendered file into `out_dir` atomically (creating the directory).
void write_outputs(const std::string& out_dir,
                   const std::vector<std::pair<std::string, std::string>>& files);

/// Library version string.
const char* version();

}  // namespace groovetrace
