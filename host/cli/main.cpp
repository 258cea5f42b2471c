// groovetrace CLI: subcommands run, synth, eval. Every failure ends as one line on stderr
// and the exit code of DESIGN.md.
#include <groovetrace/error.hpp>
#include <groovetrace/pipeline.hpp>

#include <iostream>

#include "commands.hpp"

int main(int argc, char** argv) {
  using groovetrace::ExitCode;
  CLI::App app{"groovetrace: find V-grooves in depth scans and write robot weld trajectories"};
  app.set_version_flag("--version", std::string("groovetrace ") + groovetrace::version());
  app.require_subcommand(1);
  std::vector<groovetrace::cli::Command> commands = {
      groovetrace::cli::add_run_command(app),
      groovetrace::cli::add_synth_command(app),
      groovetrace::cli::add_eval_command(app),
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "groovetrace: error: " << e.what() << " (see --help)\n";
    return static_cast<int>(ExitCode::kUsage);
  }
  try {
    for (auto& c : commands) {
      if (c.app->parsed()) return c.run();
    }
  } catch (const groovetrace::Error& e) {
    std::cerr << "groovetrace: error: " << e.what() << "\n";
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    std::cerr << "groovetrace: error: out of memory\n";
    return static_cast<int>(ExitCode::kInternal);
  } catch (const std::exception& e) {
    std::cerr << "groovetrace: error: internal: " << e.what() << "\n";
    return static_cast<int>(ExitCode::kInternal);
  }
  return static_cast<int>(ExitCode::kUsage);
}
