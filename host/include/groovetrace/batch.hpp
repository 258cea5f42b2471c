#pragma once
// `groovetrace batch`: many stored scans through `run`, in worker processes that survive bad
// scans, with a resumable output tree and a summary of the night (docs/batch.md).

#include <cstddef>
#include <groovetrace/export.hpp>
#include <groovetrace/params.hpp>
#include <string>
#include <vector>

namespace groovetrace {

/// How a batch shows its progress (on stderr).
enum class BatchProgress {
  automatic,  ///< a bar on a terminal, else one line per scan
  bar,        ///< one line rewritten in place: done/total, frames per second, ETA
  lines,      ///< one line per finished scan
  none,
};

/// What a batch runs and where.
struct BatchOptions {
  /// Directories (searched recursively for .pcd and .ply, in sorted order), scan files, or
  /// manifest CSVs (header `scan[,flange_pose][,hand_eye][,viewpoint]`, paths relative to the
  /// manifest, viewpoint as "X Y Z" in metres).
  std::vector<std::string> inputs;
  std::string out_dir;  ///< per scan: out_dir/<path relative to its input root, no extension>/
  Params params;        ///< every scan's; a manifest row's calibration and viewpoint win
  bool resume = false;  ///< skip scans already done with the same input and parameters
  int shard_index = 0;  ///< take every shard_count-th scan of the sorted list, from this one
  int shard_count = 1;
  int jobs = 0;                 ///< worker processes; 0 = default_batch_jobs()
  double scan_timeout_s = 300;  ///< a scan running longer is killed and recorded as timeout
  BatchProgress progress = BatchProgress::automatic;
};

/// Counts of a finished batch.
struct BatchTotals {
  std::size_t scans = 0;         ///< this shard's scans (a report: every row in out_dir)
  std::size_t ok = 0;            ///< of those, status ok (run now or kept)
  std::size_t failed = 0;        ///< of those, any other status
  std::size_t skipped = 0;       ///< done before and kept (--resume)
  double seconds = 0;            ///< wall time of this call
  double frames_per_second = 0;  ///< scans run (not skipped) per wall second
};

/// Sets options.shard_index and shard_count from "K/N" (0 <= K < N). Throws UsageError.
GT_API void set_shard(BatchOptions& options, const std::string& k_of_n);

/// Sets the shard from the environment: SLURM_ARRAY_TASK_ID of SLURM_ARRAY_TASK_COUNT (ids
/// counted from SLURM_ARRAY_TASK_MIN), else JOB_COMPLETION_INDEX of `count_given` (Kubernetes
/// indexed jobs). Returns false, leaving options as they are, when neither is set.
GT_API bool set_shard_from_environment(BatchOptions& options, int count_given);

/// The worker count when none is asked for: one per core up to 2 (measured in
/// docs/benchmarks.md: the crease kernel and OpenMP already share a scan among the cores).
GT_API int default_batch_jobs();

/// Runs the batch and then writes out_dir's summary.csv, summary.json and index.html for every
/// scan directory in out_dir (all shards). Throws UsageError for bad options, InputError when
/// no scan is found or out_dir cannot be written. A scan that fails is a row, never a throw.
GT_API BatchTotals run_batch(const BatchOptions& options);

/// Rebuilds summary.csv, summary.json and index.html from the scan directories in out_dir
/// (e.g. after the shards of a Slurm array). Throws InputError when out_dir holds none.
GT_API BatchTotals write_batch_report(const std::string& out_dir);

}  // namespace groovetrace
