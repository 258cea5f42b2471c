#pragma once
// Runs the built CLI as a child process and captures what a user would see.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace groovetrace::test {

/// What the tests' time limits (a scan timeout, a deadline for progress) are multiplied by:
/// 5 in a sanitized build (GT_SANITIZE), whose code runs several times slower, else 1.
constexpr int kSlowdown = GT_TEST_SLOWDOWN;

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

/// Flags for identity calibration files written into `dir` (the base frame is the camera's):
/// a run with them writes its robot program without the camera-frame warning.
inline std::string identity_calibration(const std::filesystem::path& dir) {
  for (const char* f : {"hand_eye.yaml", "flange.yaml"}) {
    std::ofstream(dir / f) << "translation: [0, 0, 0]\nrotation: [0, 0, 0, 1]\n";
  }
  return "--hand-eye " + (dir / "hand_eye.yaml").string() + " --flange-pose " +
         (dir / "flange.yaml").string();
}

/// The names in a directory, sorted; hidden ones too.
inline std::vector<std::string> entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// The contract of a `run -o out` that failed after checking `out`: out holds report.json
/// alone, with the exit code and the message stderr showed, and nothing else is left beside
/// out (no temporaries). `err` is the run's stderr.
inline void expect_failure_report(const std::filesystem::path& out, int code,
                                  const std::string& err) {
  ASSERT_EQ(entries(out), std::vector<std::string>{"report.json"});
  const auto report = nlohmann::json::parse(read_text(out / "report.json"));
  EXPECT_EQ(report["exit_code"], code);
  EXPECT_EQ(report["status"], code == 3   ? "invalid_input"
                              : code == 4 ? "no_groove"
                              : code == 7 ? "unsafe_program"
                                          : "error");
  EXPECT_EQ(err.rfind("groovetrace: error: " + report["message"].get<std::string>(), 0), 0u) << err;
  for (const auto& name : entries(out.parent_path())) {
    EXPECT_EQ(name.find(".groovetrace-"), std::string::npos) << "left behind: " << name;
  }
}

}  // namespace groovetrace::test
