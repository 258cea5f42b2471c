#pragma once
// The whole `run`: the chosen method's detection, the trajectories, frames, and the output
// files. Every 3-D quantity is in metres; per-point vectors are in input order.

#include <cstdint>
#include <functional>
#include <groovetrace/cloud.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/export.hpp>
#include <groovetrace/features.hpp>
#include <groovetrace/paper.hpp>
#include <groovetrace/params.hpp>
#include <groovetrace/program.hpp>
#include <groovetrace/robust.hpp>
#include <groovetrace/trajectory.hpp>
#include <groovetrace/version.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace {

/// What only the paper method computes.
struct PaperDetail {
  Cloud smoothed;       ///< the input after MLS (metres, cloud frame)
  Detection detection;  ///< threshold, kept components (D in deg^2)
};

/// Everything a run computed. The shared fields are filled by both methods; `paper` or
/// `robust` holds the chosen method's own results (the other stays empty).
struct RunResult {
  Method method = Method::robust;
  std::vector<std::uint8_t> groove;  ///< per input point: 1 = groove
  /// Per input point, unit, towards the viewpoint (cloud frame): paper: the PCA normal at
  /// `radius`; robust: the crease map's plane normal at the groove's scale. NaN = none.
  Normals normals;
  /// Per input point, in `score_unit`, NaN = none: paper: the descriptor D (deg^2); robust:
  /// the concavity (mm). Written as annotated.pcd's `descriptor` field.
  std::vector<float> score;
  std::string score_unit;  ///< "deg^2" or "mm"
  /// The exported seams' torch paths, best first (written as trajectory.csv, then
  /// trajectory_1.csv, ...); camera frame, or base frame when frames were given. Never empty
  /// after a successful run.
  std::vector<Trajectory> trajectories;
  /// The passes of each exported seam's robot program, in `trajectories`' order and frame: the
  /// path itself, or the planned multi-pass weld, woven and tilted as WeldParams say.
  std::vector<std::vector<WeldPass>> passes;
  /// The programs are written: the passes are in the base frame, or the camera-frame program
  /// was asked for (GuardParams::camera_frame_program). Either way they passed the guards.
  bool programs = false;
  /// Seams found: the robust method's accepted seams (of which `trajectories` holds at most
  /// max_seams), or 1 for the paper method.
  std::size_t seams_found = 0;
  /// The transform the trajectories were moved by (p_base = T_base_camera * p_camera, the
  /// camera frame being the cloud's) when calibration files were given; unset when the
  /// trajectories stay in the cloud's frame.
  std::optional<Eigen::Isometry3d> T_base_camera;
  std::vector<std::pair<std::string, double>> timings_ms;  ///< per stage, in order
  std::vector<std::string> warnings;
  std::string backend, device;  ///< the backend that ran and its device
  PaperDetail paper;            ///< --method paper only
  RobustDetection robust;       ///< --method robust only: candidates, seams and scores
};

/// Called after each stage with its name and duration (ms), e.g. to print progress.
using StageCallback = std::function<void(const std::string& stage, double ms)>;

/// Runs the method of `params` on `cloud` (metres): detection and trajectories, moved into the
/// base frame when calibration files are given, and each one's weld passes, checked by the
/// guards when a program is to be written. Throws NoGrooveError when no groove is found,
/// UsageError for bad parameters, InputError for unreadable calibration files,
/// UnsafeProgramError when a program would break a guard.
GT_API RunResult run_pipeline(const Cloud& cloud, const Params& params, FeatureBackend& backend,
                              const StageCallback& on_stage = {});

/// Checks parameter ranges; throws UsageError naming the offending parameter.
GT_API void validate(const Params& params);

/// The output files of a run, as bytes, keyed by file name (annotated.pcd, overview.png,
/// trajectory.csv, trajectory.json, trajectory.ros.yaml, the program of params.program.robot
/// (program.script, program.mod, or program.src and program.dat), report.json; with
/// --max-seams N > 1 also trajectory_K.* and program_K.* for the K-th next seam).
GT_API std::vector<std::pair<std::string, std::string>> render_outputs(
    const Cloud& input, const RunResult& result, const Params& params,
    const std::string& input_path, double total_ms);

/// True for the names a run writes into its output directory (render_outputs'), which is
/// what an existing OUTDIR may hold for a run to replace it.
GT_API bool is_run_output(const std::string& name);

/// Throws unless `out_dir` can take a run's outputs: UsageError for an empty path; InputError
/// when it is a file, holds a file a run does not write, or its folder is not writable.
GT_API void check_output_dir(const std::string& out_dir);

/// Replaces the directory `out_dir` by one holding exactly `files`, as one set: a reader, a
/// kill or a full disk leaves the earlier run's set or this one, never a mix (the set is built
/// beside `out_dir` and swapped in; docs/design.md, "CLI contract").
GT_API void write_outputs(const std::string& out_dir,
                          const std::vector<std::pair<std::string, std::string>>& files);

/// Replaces `out_dir`'s outputs by report.json alone with the failure's status, exit code and
/// one-line message, so no earlier program stays behind a failed run. If even that cannot be
/// written, removes the earlier outputs. Never throws.
GT_API void write_failure_report(const std::string& out_dir, const std::string& input_path,
                                 ExitCode code, const std::string& message);

}  // namespace groovetrace
