#pragma once
// Running one scan of a batch into its directory, which appears whole or not at all.

#include <groovetrace/features.hpp>
#include <groovetrace/params.hpp>
#include <string>
#include <utility>
#include <vector>

#include "batch/jobs.hpp"
#include "batch/row.hpp"

namespace groovetrace::batch {

/// The parameters of one job: the batch's, with a manifest row's calibration and viewpoint.
Params job_params(const Params& batch, const ScanJob& job);

/// fnv1a64 of the parameters as report.json lists them, hex.
std::string params_hash(const Params& params);

/// Runs `job` like `groovetrace run` and writes its directory OUTDIR/job.rel with run's files
/// plus scan.json (its row). A scan that fails gets a directory with scan.json alone. Never
/// throws for the scan's own failures; throws InputError when OUTDIR cannot be written.
ScanRow run_scan(const ScanJob& job, const Params& batch_params, FeatureBackend& backend,
                 const std::string& out_dir);

/// The row of a scan that produced nothing: `status` with its exit code and one-line message.
ScanRow failure_row(const ScanJob& job, const std::string& status, int exit_code,
                    const std::string& message);

/// Writes a row for a scan whose worker died or ran out of time (scan.json alone).
void write_failure(const ScanRow& row, const std::string& out_dir);

/// Replaces OUTDIR/rel by a directory holding `files`, through a temporary directory under
/// OUTDIR/.partial renamed into place: a kill leaves the old directory, the new one, or none.
void write_scan_dir(const std::string& out_dir, const std::string& rel,
                    const std::vector<std::pair<std::string, std::string>>& files);

/// The row in OUTDIR/rel/scan.json, or false when there is none (or it cannot be parsed).
bool read_row(const std::string& out_dir, const std::string& rel, ScanRow& row);

}  // namespace groovetrace::batch
