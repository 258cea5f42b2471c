#pragma once
// Accuracy of a detection and its trajectory against synthetic ground truth: the paper's IoU
// lambda, plus waypoint errors against the true root line (docs/synthetic-scans.md,
// "`groovetrace eval`").
//
// Frames: everything is compared in the scan's camera frame (metres). A trajectory written in
// the robot base frame (`run --hand-eye ...`) cannot be compared; evaluate_files notes it.

#include <Eigen/Geometry>
#include <cstdint>
#include <groovetrace/export.hpp>
#include <groovetrace/synth.hpp>
#include <groovetrace/trajectory.hpp>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace {

/// One torch pose of a trajectory, camera frame: tool z along the torch into the workpiece,
/// tool x along the travel direction.
struct ToolPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// The poses of a trajectory, in its order.
inline std::vector<ToolPose> tool_poses(const Trajectory& trajectory) {
  std::vector<ToolPose> poses;
  for (const Waypoint& w : trajectory.waypoints) poses.push_back({w.position, w.orientation});
  return poses;
}

/// A tack weld as a run reports it (report.json robust.seams[k].tacks): its centre's arc
/// length from the trajectory's first waypoint and its length along the seam (m).
struct ReportedTack {
  double position = 0.0;
  double length = 0.0;
};

/// The run's tacks against the truth's. A reported tack is placed on its trajectory at its arc
/// length and measured along the nearest true root line (within coverage_radius of it); it
/// matches a true tack of that seam when their extents along the root overlap (centres apart by
/// at most half the sum of their lengths), nearest pairs first, each used once.
struct TackScore {
  bool reported = false;     ///< report.json lists tacks (maybe none) for trajectory.csv's seam;
                             ///< set by evaluate_files
  std::size_t expected = 0;  ///< true tacks, over every seam
  std::size_t found = 0;     ///< true tacks matched by a reported one
  std::size_t extra = 0;     ///< reported tacks matching none
  double position_mean = 0;  ///< |centre error| along the root over the matches (m); NaN if none
  double position_max = 0;   ///< m; NaN if none
  double length_bias = 0;  ///< mean of reported minus true length over the matches (m); NaN if none
};

struct EvalOptions {
  double coverage_radius = 0.006;  ///< a root point is covered within this of the path (m)
  double coverage_step = 0.0005;   ///< the root line is sampled this finely for coverage (m)
};

/// The metrics. Distances in metres, angles in degrees, shares in percent; NaN where a metric
/// is undefined (no waypoints, no groove in truth or detection).
struct EvalMetrics {
  // Detection, over the points where the scan has a return.
  std::size_t points = 0;           ///< all points of the organized scan
  std::size_t valid_points = 0;     ///< points with a return
  std::size_t truth_points = 0;     ///< valid points labelled groove (n_gt)
  std::size_t detected_points = 0;  ///< valid points detected as groove (n_d)
  std::size_t overlap_points = 0;   ///< both (n_overlap)
  double iou_percent = 0;           ///< lambda = n_overlap / (n_d + n_gt - n_overlap) * 100
  double precision_percent = 0;     ///< n_overlap / n_d * 100
  double recall_percent = 0;        ///< n_overlap / n_gt * 100

  // Trajectory against the nearest point of the true root line(s). Lateral: across the seam
  // in the surface's tangent plane; depth: along the surface normal, + towards the camera.
  std::size_t waypoints = 0;
  double distance_mean = 0, distance_max = 0;  ///< |waypoint - nearest root point| (m)
  double lateral_mean = 0, lateral_max = 0;    ///< |lateral part| (m)
  double depth_mean = 0, depth_max = 0;        ///< |depth part| (m)
  double depth_bias = 0;  ///< mean signed depth part (m); > 0: waypoints above the root
  double tool_axis_mean_deg = 0, tool_axis_max_deg = 0;  ///< tool z vs -groove bisector
  /// Tool x vs the root tangent, the tangent signed along the order of the waypoints (a tool x
  /// pointing backwards is ~180 deg off).
  double travel_axis_mean_deg = 0, travel_axis_max_deg = 0;
  double coverage_percent = 0;     ///< in-view root length within coverage_radius of the path
  double seam_length_in_view = 0;  ///< m
  double coverage_radius = 0;      ///< m, as used

  // Runtime, from the run's report.json when available.
  double runtime_ms = 0;                                 ///< end to end; NaN if unknown
  double points_per_second = 0;                          ///< points / runtime; NaN if unknown
  std::vector<std::pair<std::string, double>> stage_ms;  ///< per stage, as reported

  // The joint: the truth's (its first seam's; "V", "bevel", "fillet" or "lap") and the one the
  // run reports for its first exported seam (report.json robust.seams[k].joint of the entry
  // whose "file" is "trajectory.csv"); empty when the run reports none.
  std::string joint_expected;
  std::string joint_found;

  /// Every exported trajectory (trajectory.csv, trajectory_1.csv, ...) against every true seam
  /// on its own: the same waypoint and coverage metrics, but against that seam's root line
  /// alone (evaluate_files; empty from evaluate).
  struct SeamScore {
    std::string file;            ///< the trajectory file
    std::size_t truth_seam = 0;  ///< index into the truth's seams
    std::size_t waypoints = 0;
    double distance_mean = 0, lateral_mean = 0, depth_mean = 0;  ///< m
    double tool_axis_mean_deg = 0;
    double coverage_percent = 0;  ///< of that true seam's in-view root line
  };
  std::vector<SeamScore> seam_scores;

  /// The first exported seam's tacks (trajectory.csv, report.json) against the truth's
  /// (evaluate_files; from evaluate: none reported).
  TackScore tacks;

  std::vector<std::string> notes;  ///< caveats (frame, missing files)
};

/// Metrics from in-memory data. `detected` has one entry per scan point (1 = groove), in the
/// truth's point order; `poses` are in the camera frame, in travel order. Throws InputError if
/// `detected` does not match the truth's point count.
GT_API EvalMetrics evaluate(const SynthTruth& truth, const std::vector<std::uint8_t>& detected,
                            const std::vector<ToolPose>& poses, const EvalOptions& options = {});

/// Each trajectory in `trajectories` (file name, camera-frame poses) against each of the
/// truth's seams alone (EvalMetrics::SeamScore), in that order.
GT_API std::vector<EvalMetrics::SeamScore> score_seams(
    const SynthTruth& truth,
    const std::vector<std::pair<std::string, std::vector<ToolPose>>>& trajectories,
    const EvalOptions& options = {});

/// The tacks `reported` along `poses` (camera frame, in travel order) against the truth's tacks
/// (TackScore).
GT_API TackScore score_tacks(const SynthTruth& truth, const std::vector<ToolPose>& poses,
                             const std::vector<ReportedTack>& reported,
                             const EvalOptions& options = {});

/// What evaluate_files reads from a `groovetrace run` output directory.
struct RunOutput {
  std::uint32_t width = 0, height = 0;  ///< of annotated.pcd
  std::vector<std::uint8_t> groove;     ///< annotated.pcd field `groove`, per point
  std::vector<ToolPose> poses;          ///< trajectory.csv (empty if absent)
  bool has_trajectory = false;
  /// trajectory.csv, trajectory_1.csv, ... (the next seams of `run --max-seams`): file name and
  /// poses, until the first one missing.
  std::vector<std::pair<std::string, std::vector<ToolPose>>> trajectories;
  std::string frame = "camera";  ///< trajectory.json "frame" when present
  double total_ms = 0;           ///< report.json end-to-end time; NaN if absent
  std::vector<std::pair<std::string, double>> stage_ms;  ///< report.json stage timings
  std::string joint;  ///< report.json robust.seams[k].joint of trajectory.csv's seam; "" if none
  /// report.json robust.seams[k].tacks of trajectory.csv's seam; has_tacks: the key is there.
  std::vector<ReportedTack> tacks;
  bool has_tacks = false;
};

/// Reads annotated.pcd (a PCD of any DATA kind with a `groove` field), trajectory.csv (header
/// `idx,x_m,y_m,z_m,qx,qy,qz,qw,...`), and, when present, trajectory.json and report.json.
/// Throws InputError when annotated.pcd is missing or malformed, or trajectory.csv malformed.
GT_API RunOutput read_run_output(const std::string& result_dir);

/// Reads the truth of `scan_path` (read_synth_truth) and the run output, and evaluates.
GT_API EvalMetrics evaluate_files(const std::string& scan_path, const std::string& result_dir,
                                  const EvalOptions& options = {});

/// metrics.json contents (metres and degrees; NaN as null). `truth` and `result` are recorded.
GT_API std::string metrics_json(const EvalMetrics& metrics, const std::string& truth,
                                const std::string& result);
/// A short human summary (millimetres), several lines.
GT_API std::string metrics_summary(const EvalMetrics& metrics);

}  // namespace groovetrace
