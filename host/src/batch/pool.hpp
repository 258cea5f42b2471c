#pragma once
// Worker processes for a batch: a scan that crashes or hangs takes its worker with it, never
// the batch.

#include <functional>
#include <groovetrace/params.hpp>
#include <string>
#include <vector>

#include "batch/jobs.hpp"
#include "batch/row.hpp"

namespace groovetrace::batch {

/// Runs every job in `workers` forked processes, each setting up its backend once and then
/// running scan after scan (run_scan). A worker that dies takes its scan with it (status
/// crashed) and is replaced; a scan that runs past `timeout_s` seconds has its worker killed
/// (status timeout). `on_row` is called in this process after each scan, in finishing order.
/// Call it from a process that has started no threads (fork copies only the calling thread).
void run_in_workers(const std::vector<ScanJob>& jobs, const Params& params,
                    const std::string& out_dir, int workers, double timeout_s,
                    const std::function<void(const ScanRow&)>& on_row);

/// Removes what killed batches on this host left in OUTDIR/.partial (their processes are gone).
void remove_stale_partials(const std::string& out_dir);

/// The name under OUTDIR/.partial for this process's temporary copy of `rel`.
std::string partial_name(const std::string& rel);

}  // namespace groovetrace::batch
