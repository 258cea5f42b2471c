// groovetrace CLI: subcommands run, synth, eval, batch, report, send. Every failure ends as one
// line on stderr and the exit code of docs/design.md ("CLI contract").
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>
#include <groovetrace/opencl.hpp>
#include <groovetrace/version.hpp>
#include <iostream>

#include "commands.hpp"

namespace {

// A kernel build failure's compiler log runs to many lines: it goes to a new file in the
// temporary directory ($TMPDIR), named on the error's one line. The name is made unique and
// the file created exclusively (mkstemps: O_EXCL, mode 0600): a fixed name was written
// through whatever symlink another user had planted there. Returns the path, or "" when
// unwritable.
std::string save_build_log(const std::string& log) {
  std::error_code ec;
  const auto dir = std::filesystem::temp_directory_path(ec);
  if (ec) return "";
  std::string path = (dir / "groovetrace-opencl-build-XXXXXX.log").string();
  const int fd = ::mkstemps(path.data(), 4);
  if (fd < 0) return "";
  std::size_t done = 0;
  while (done < log.size()) {
    const ssize_t n = ::write(fd, log.data() + done, log.size() - done);
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  const bool ok = ::close(fd) == 0 && done == log.size();
  return ok ? path : "";
}

}  // namespace

int main(int argc, char** argv) {
  using groovetrace::ExitCode;
  CLI::App app{"groovetrace: find V-grooves in depth scans and write robot weld trajectories"};
  app.set_version_flag("--version", std::string("groovetrace ") + groovetrace::version());
  app.require_subcommand(1);
  std::vector<groovetrace::cli::Command> commands = {
      groovetrace::cli::add_run_command(app),    groovetrace::cli::add_synth_command(app),
      groovetrace::cli::add_eval_command(app),   groovetrace::cli::add_batch_command(app),
      groovetrace::cli::add_report_command(app), groovetrace::cli::add_send_command(app),
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
  } catch (const groovetrace::OpenClError& e) {
    const std::string log = e.build_log().empty() ? "" : save_build_log(e.build_log());
    std::cerr << "groovetrace: error: " << e.what()
              << (log.empty() ? "" : " (compiler output: " + log + ")") << "\n";
    return static_cast<int>(e.code());
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
