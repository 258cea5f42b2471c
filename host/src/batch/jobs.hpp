#pragma once
// The scans of a batch: inputs expanded into jobs with their output directories, and shards.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace groovetrace::batch {

/// One scan to run.
struct ScanJob {
  std::string path;  ///< the scan file as found (absolute or relative to the working dir)
  std::string rel;   ///< its directory under OUTDIR: path relative to its input root, no extension
  std::string flange_pose;  ///< manifest: T_base_flange file of this capture ("" = the batch's)
  std::string hand_eye;     ///< manifest: T_flange_camera file ("" = the batch's)
  std::optional<Eigen::Vector3f> viewpoint;  ///< manifest: sensor origin (cloud frame, m)
};

/// What a directory search needs to know besides the inputs.
struct ListOptions {
  std::string out_dir;            ///< the batch's OUTDIR: never searched when inside an input
  bool intrinsics_given = false;  ///< --intrinsics: every .png found is a depth scan
};

/// Expands directories (recursively, .pcd/.ply, and .png depth images whose intrinsics are
/// found: `options.intrinsics_given`, STEM.json or intrinsics.json beside them; never the
/// overview.png or thumbnail.png beside a run's report.json or a batch's scan.json; sorted),
/// scan files and manifest CSVs (.csv) into jobs sorted by `rel`. Two scans that would share a
/// directory (x.pcd and x.ply, or the same relative path under two inputs) get the extension and
/// then a counter appended, so no two jobs share one. Throws InputError for a missing input, a bad
/// manifest or no scan at all.
std::vector<ScanJob> list_jobs(const std::vector<std::string>& inputs,
                               const ListOptions& options = {});

/// Reads a manifest: header `scan[,flange_pose][,hand_eye][,viewpoint]` (any order, `scan`
/// required), one row per scan, paths relative to the manifest's folder, viewpoint "X Y Z".
std::vector<ScanJob> read_manifest(const std::string& path);

/// Every `count`-th job starting at `index` (0 <= index < count).
std::vector<ScanJob> shard(const std::vector<ScanJob>& jobs, int index, int count);

/// Parses "K/N" (0 <= K < N). Throws UsageError otherwise.
void parse_shard(const std::string& text, int& index, int& count);

/// The shard from the environment: SLURM_ARRAY_TASK_ID of SLURM_ARRAY_TASK_COUNT (task ids
/// counted from SLURM_ARRAY_TASK_MIN, default 0), else JOB_COMPLETION_INDEX with
/// `count_given` (Kubernetes indexed jobs). False when neither is set.
bool shard_from_environment(int count_given, int& index, int& count);

}  // namespace groovetrace::batch
