// run_batch: the jobs of this shard, minus what --resume finds done, through the worker pool,
// with progress on stderr, then the report over every scan directory in OUTDIR.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <groovetrace/batch.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/pipeline.hpp>

#include "batch/jobs.hpp"
#include "batch/pool.hpp"
#include "batch/report.hpp"
#include "batch/scan_dir.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Progress on stderr: a bar rewritten in place, or a line per scan.
class Progress {
 public:
  Progress(BatchProgress mode, std::size_t total) : total_(total) {
    if (mode == BatchProgress::automatic) {
      mode = ::isatty(STDERR_FILENO) ? BatchProgress::bar : BatchProgress::lines;
    }
    mode_ = mode;
  }
  void done(const batch::ScanRow& row) {
    ++done_;
    const double s = std::chrono::duration<double>(Clock::now() - start_).count();
    const double fps = s > 0 ? done_ / s : 0;
    if (mode_ == BatchProgress::lines) {
      std::fprintf(stderr, "groovetrace: [%zu/%zu] %s: %s (%.2f s)%s%s\n", done_, total_,
                   row.dir.c_str(), row.status.c_str(), row.total_ms / 1000,
                   row.status == "ok" ? "" : ": ", row.status == "ok" ? "" : row.message.c_str());
    } else if (mode_ == BatchProgress::bar) {
      const int width = 30,
                filled = static_cast<int>(width * done_ / std::max<std::size_t>(total_, 1));
      const double eta = fps > 0 ? (total_ - done_) / fps : 0;
      std::fprintf(stderr, "\r[%s%s] %zu/%zu  %.2f frames/s  ETA %d:%02d ",
                   std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(),
                   done_, total_, fps, static_cast<int>(eta) / 60, static_cast<int>(eta) % 60);
      if (done_ == total_) std::fprintf(stderr, "\n");
    }
    std::fflush(stderr);
  }

 private:
  BatchProgress mode_;
  std::size_t total_, done_ = 0;
  Clock::time_point start_ = Clock::now();
};

void check_options(const BatchOptions& o) {
  if (o.inputs.empty()) throw UsageError("batch: no INPUT given");
  if (o.out_dir.empty()) throw UsageError("batch: -o OUTDIR is required");
  if (o.shard_count < 1 || o.shard_index < 0 || o.shard_index >= o.shard_count) {
    throw UsageError("--shard: expected K/N with 0 <= K < N");
  }
  if (o.jobs < 0 || o.jobs > 256) throw UsageError("--jobs: expected 0 (default) to 256");
  if (!(o.scan_timeout_s > 0)) throw UsageError("--scan-timeout: expected seconds > 0");
  validate(o.params);
}

void make_out_dir(const std::string& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir) || ::access(out_dir.c_str(), W_OK) != 0) {
    throw InputError("cannot write the output directory " + out_dir +
                     (ec ? ": " + ec.message() : ""));
  }
}

// --resume: a scan whose directory holds a deterministic outcome for the same input and
// parameters is kept; crashed, timeout and error rows are run again.
bool already_done(const batch::ScanJob& job, const BatchOptions& o, batch::ScanRow& row) {
  if (!batch::read_row(o.out_dir, job.rel, row)) return false;
  if (row.status != "ok" && row.status != "no_groove" && row.status != "invalid_input") {
    return false;
  }
  if (row.params_hash != batch::params_hash(batch::job_params(o.params, job))) return false;
  try {
    return row.input_hash == batch::file_hash(job.path);
  } catch (const InputError&) {
    return false;
  }
}

BatchTotals totals_of(const std::vector<batch::ScanRow>& rows) {
  BatchTotals t;
  t.scans = rows.size();
  for (const batch::ScanRow& r : rows) (r.status == "ok" ? t.ok : t.failed) += 1;
  return t;
}

}  // namespace

void set_shard(BatchOptions& options, const std::string& k_of_n) {
  batch::parse_shard(k_of_n, options.shard_index, options.shard_count);
}

bool set_shard_from_environment(BatchOptions& options, int count_given) {
  return batch::shard_from_environment(count_given, options.shard_index, options.shard_count);
}

int default_batch_jobs() {
  const long cores = ::sysconf(_SC_NPROCESSORS_ONLN);
  return static_cast<int>(std::clamp(cores, 1L, 2L));
}

BatchTotals run_batch(const BatchOptions& o) {
  const auto t0 = Clock::now();
  check_options(o);
  const auto all = batch::list_jobs(o.inputs, {o.out_dir, !o.params.intrinsics_file.empty()});
  const auto mine = batch::shard(all, o.shard_index, o.shard_count);
  make_out_dir(o.out_dir);
  batch::remove_stale_partials(o.out_dir);
  std::vector<batch::ScanJob> todo;
  std::vector<batch::ScanRow> kept, ran;
  for (const batch::ScanJob& job : mine) {
    batch::ScanRow row;
    if (o.resume && already_done(job, o, row)) {
      kept.push_back(row);
    } else {
      todo.push_back(job);
    }
  }
  Progress progress(o.progress, todo.size());
  const int workers = o.jobs > 0 ? o.jobs : default_batch_jobs();
  batch::run_in_workers(todo, o.params, o.out_dir, workers, o.scan_timeout_s,
                        [&](const batch::ScanRow& row) {
                          ran.push_back(row);
                          progress.done(row);
                        });
  std::error_code ec;
  fs::remove(fs::path(o.out_dir) / ".partial", ec);  // only when empty: other shards may be busy
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  batch::write_report(o.out_dir, batch::collect_rows(o.out_dir),
                      {seconds, ran.size(), std::min<int>(workers, std::max<int>(1, todo.size()))});
  // This shard's rows, kept ones included: a kept no_groove is still not ok.
  std::vector<batch::ScanRow> rows = kept;
  rows.insert(rows.end(), ran.begin(), ran.end());
  BatchTotals t = totals_of(rows);
  t.skipped = kept.size();
  t.seconds = seconds;
  t.frames_per_second = seconds > 0 ? ran.size() / seconds : 0;
  return t;
}

BatchTotals write_batch_report(const std::string& out_dir) {
  const auto t0 = Clock::now();
  const auto rows = batch::collect_rows(out_dir);
  if (rows.empty()) throw InputError("no scan directory (scan.json) in " + out_dir);
  batch::write_report(out_dir, rows, {});
  BatchTotals t = totals_of(rows);
  t.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return t;
}

}  // namespace groovetrace
