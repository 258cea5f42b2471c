#pragma once
// Subcommands of the `groovetrace` CLI. Each file adds one subcommand to the app and returns
// the action to run when it was chosen. Actions throw groovetrace::Error for failures;
// main() turns those into one stderr line and the exit code.

#include <CLI/CLI.hpp>
#include <functional>

namespace groovetrace::cli {

struct Command {
  CLI::App* app = nullptr;   ///< the subcommand (to know whether it was chosen)
  std::function<int()> run;  ///< returns the exit code on success paths
};

Command add_run_command(CLI::App& app);
Command add_synth_command(CLI::App& app);
Command add_eval_command(CLI::App& app);
Command add_batch_command(CLI::App& app);
Command add_report_command(CLI::App& app);
Command add_send_command(CLI::App& app);

}  // namespace groovetrace::cli
