#pragma once
// Runs the built CLI as a child process and captures what a user would see.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace groovetrace::test {

struct CliResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A fresh empty directory under the test temp dir.
inline std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / ("groovetrace_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Runs a shell command line, capturing its exit code, stdout and stderr.
inline CliResult run_cli_command(const std::string& command, const std::filesystem::path& scratch) {
  const auto out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string cmd = command + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

/// `args` is appended to the CLI path as shell words (quote paths with spaces yourself);
/// `env` (e.g. "VAR=value") is put before the command.
inline CliResult run_cli(const std::string& args, const std::filesystem::path& scratch,
                         const std::string& env = "") {
  return run_cli_command(env + " " + std::string(GT_CLI_PATH) + " " + args, scratch);
}

}  // namespace groovetrace::test
