// `groovetrace batch INPUT... -o OUTDIR`: every scan through `run` in worker processes, and
// `groovetrace report OUTDIR`: the summary rebuilt from the scan directories (docs/batch.md).
#include <cstdio>
#include <groovetrace/batch.hpp>
#include <groovetrace/error.hpp>
#include <memory>

#include "commands.hpp"
#include "param_flags.hpp"

namespace groovetrace::cli {
namespace {

// Exit code of a batch in which some scan was not ok (docs/batch.md, "Exit codes").
constexpr int kSomeScansFailed = static_cast<int>(ExitCode::kNotAllOk);

struct BatchCli {
  std::vector<std::string> inputs;
  std::string out_dir, shard, progress = "auto";
  int shard_count = 0, jobs = 0;
  double scan_timeout_s = 300;
  bool resume = false;
  std::shared_ptr<ParamFlags> params = std::make_shared<ParamFlags>();
};

BatchProgress progress_mode(const std::string& text) {
  if (text == "auto") return BatchProgress::automatic;
  if (text == "bar") return BatchProgress::bar;
  if (text == "lines") return BatchProgress::lines;
  if (text == "none") return BatchProgress::none;
  throw UsageError("--progress: expected auto, bar, lines or none, got '" + text + "'");
}

BatchOptions options_of(const BatchCli& cli) {
  BatchOptions o;
  o.inputs = cli.inputs;
  o.out_dir = cli.out_dir;
  std::vector<std::string> warnings;
  o.params = parse_params(*cli.params, warnings);
  for (const auto& w : warnings) std::fprintf(stderr, "groovetrace: warning: %s\n", w.c_str());
  o.resume = cli.resume;
  if (!cli.shard.empty()) {
    set_shard(o, cli.shard);
  } else {
    set_shard_from_environment(o, cli.shard_count);
  }
  o.jobs = cli.jobs;
  o.scan_timeout_s = cli.scan_timeout_s;
  o.progress = progress_mode(cli.progress);
  return o;
}

int run_batch_command(const BatchCli& cli) {
  const BatchOptions o = options_of(cli);
  const BatchTotals t = run_batch(o);
  std::printf(
      "groovetrace: batch: %zu scans (shard %d/%d): %zu ok, %zu not ok, %zu of them kept "
      "from before; %.2f frames/s; summary in %s/index.html\n",
      t.scans, o.shard_index, o.shard_count, t.ok, t.failed, t.skipped, t.frames_per_second,
      o.out_dir.c_str());
  return t.failed > 0 ? kSomeScansFailed : 0;
}

}  // namespace

Command add_batch_command(CLI::App& app) {
  auto cli = std::make_shared<BatchCli>();
  CLI::App* sub = app.add_subcommand("batch", "run every scan of folders, files or manifests");
  sub->add_option("inputs", cli->inputs, "folders (searched for .pcd/.ply), scans or manifest CSVs")
      ->required();
  sub->add_option("-o,--output", cli->out_dir, "output directory (created if missing)")->required();
  sub->add_flag("--resume", cli->resume,
                "keep scans already done with the same input and parameters");
  sub->add_option("--shard", cli->shard,
                  "K/N: every N-th scan from the K-th (default: SLURM_ARRAY_TASK_ID/COUNT)");
  sub->add_option("--shard-count", cli->shard_count, "N with JOB_COMPLETION_INDEX (Kubernetes)");
  sub->add_option("--jobs", cli->jobs, "worker processes (default: one per core, up to 2)");
  sub->add_option("--scan-timeout", cli->scan_timeout_s, "seconds before a scan is killed (300)");
  sub->add_option("--progress", cli->progress, "auto, bar, lines or none (auto)");
  add_param_flags(sub, cli->params);
  return {sub, [cli] { return run_batch_command(*cli); }};
}

Command add_report_command(CLI::App& app) {
  auto out_dir = std::make_shared<std::string>();
  CLI::App* sub = app.add_subcommand("report", "rebuild summary.csv/json and index.html of OUTDIR");
  sub->add_option("outdir", *out_dir, "a batch's output directory")->required();
  return {sub, [out_dir] {
            const BatchTotals t = write_batch_report(*out_dir);
            std::printf("groovetrace: report: %zu scans, %zu ok, %zu failed; %s/index.html\n",
                        t.scans, t.ok, t.failed, out_dir->c_str());
            return t.failed > 0 ? kSomeScansFailed : 0;
          }};
}

}  // namespace groovetrace::cli
