// `groovetrace eval`: metrics of a `run` output against a synthetic scan's ground truth.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/eval.hpp>
#include <memory>
#include <string>

#include "commands.hpp"

namespace groovetrace::cli {
namespace {

struct EvalCliOptions {
  std::string truth, result, output, coverage_radius;
};

}  // namespace

Command add_eval_command(CLI::App& app) {
  auto o = std::make_shared<EvalCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "eval", "Compare a run's detection and trajectory with a synthetic scan's ground truth");
  sub->add_option("--truth", o->truth, "The synthetic scan SCAN.pcd (its truth files beside it)")
      ->required();
  sub->add_option("--result", o->result, "Output directory of `groovetrace run` on that scan")
      ->required();
  sub->add_option("-o,--output", o->output, "metrics.json path (default RESULT/metrics.json)");
  sub->add_option("--coverage-radius", o->coverage_radius,
                  "Root points within this of the trajectory count as covered, m (default 0.006)");

  return {sub, [o]() {
            EvalOptions options;
            if (!o->coverage_radius.empty()) {
              char* end = nullptr;
              options.coverage_radius = std::strtod(o->coverage_radius.c_str(), &end);
              if (*end != '\0' || !std::isfinite(options.coverage_radius) ||
                  options.coverage_radius <= 0.0)
                throw UsageError("eval: --coverage-radius expects a positive length in m, got '" +
                                 o->coverage_radius + "'");
            }
            const EvalMetrics m = evaluate_files(o->truth, o->result, options);
            const std::string out = o->output.empty() ? o->result + "/metrics.json" : o->output;
            write_file_atomic(out, metrics_json(m, o->truth, o->result));
            std::fputs(metrics_summary(m).c_str(), stdout);
            std::printf("wrote %s\n", out.c_str());
            return 0;
          }};
}

}  // namespace groovetrace::cli
