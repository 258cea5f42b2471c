// What a run may cost in memory (docs/design.md, "CLI contract"): a header that claims more
// points than its file holds is refused before anything is allocated, and a run's peak
// memory is bounded by a fixed part plus a stated amount per input point.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <groovetrace/cloud_io.hpp>
#include <utility>
#include <vector>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

// The memory documented for a run: 160 MiB (the process with PCL's and the OpenCL driver's
// libraries) plus 200 bytes per input point. AddressSanitizer's shadow memory and quarantine
// multiply what a process holds; the sanitizer build checks the same bound times four.
std::uint64_t documented_peak_bytes(std::uint64_t points) {
#if defined(__SANITIZE_ADDRESS__)
  constexpr std::uint64_t kSanitizer = 4;
#else
  constexpr std::uint64_t kSanitizer = 1;
#endif
  return kSanitizer * ((160ull << 20) + 200 * points);
}

struct Finished {
  int exit_code = -1;
  std::uint64_t peak_bytes = 0;  // the child's largest resident set
};

// Runs the CLI with `args` (stdout and stderr to /dev/null); its exit code and peak memory.
Finished run_measured(const std::vector<std::string>& args) {
  std::vector<char*> argv = {const_cast<char*>(GT_CLI_PATH)};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr)) {
      ::_exit(126);
    }
    ::execv(GT_CLI_PATH, argv.data());
    ::_exit(127);
  }
  int status = 0;
  rusage usage{};
  ::wait4(pid, &status, 0, &usage);
  Finished f;
  f.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  f.peak_bytes = static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // ru_maxrss is in KiB
  return f;
}

class Resources : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  fs::path dir_;
};

// 2^40 points in a PCD header and a billion PLY vertices, each over 12 bytes of data: read as
// claimed they would take 12 TB and 12 GB. Refused at once, within the fixed part of the bound.
TEST_F(Resources, HeadersClaimingHugeCloudsAreRefusedBeforeAllocating) {
  const std::string pcd =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
      "WIDTH 1099511627776\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1099511627776\n"
      "DATA binary\n0123456789ab";
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n0123456789ab";
  const std::string ply_ascii =
      "ply\nformat ascii 1.0\nelement vertex 100000000\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n";
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"huge.pcd", pcd},
                                   {"huge.ply", ply},
                                   {"huge_ascii.ply", ply_ascii}}) {
    SCOPED_TRACE(name);
    const fs::path out = dir_ / ("out_" + name);
    const auto r = test::run_cli(
        "run " + write(name, text).string() + " --backend cpu -o " + out.string(), dir_);
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_TRUE(r.err.find("too large") != std::string::npos ||
                r.err.find("truncated") != std::string::npos)
        << r.err;
    const Finished f =
        run_measured({"run", (dir_ / name).string(), "--backend", "cpu", "-o", out.string()});
    EXPECT_EQ(f.exit_code, 3);
    EXPECT_LT(f.peak_bytes, documented_peak_bytes(0));
  }
}

// Both methods on a 640x480 frame with either backend, and on a 1280x720 frame with the
// default backend: peak memory within the bound.
TEST_F(Resources, PeakMemoryOfARunIsBoundedByItsPoints) {
  std::vector<std::pair<int, int>> sizes = {{640, 480}, {1280, 720}};
  if (test::small_runs()) sizes.pop_back();  // sanitized: its bound is loose, its runs slow
  for (const auto& [w, h] : sizes) {
    test::VGrooveScene s;
    s.width = w;
    s.height = h;
    const fs::path scan = dir_ / ("scan" + std::to_string(w) + ".pcd");
    write_file_atomic(scan.string(), pcd_bytes(test::render_vgroove(s).cloud));
    for (const char* method : {"robust", "paper"}) {
      for (const char* backend : {"auto", "cpu"}) {
        if (w > 640 && std::string(backend) == "cpu") continue;  // 10-20 s, and no new memory
        SCOPED_TRACE(scan.filename().string() + " " + method + " " + backend);
        const Finished f = run_measured({"run", scan.string(), "-q", "--method", method,
                                         "--backend", backend, "-o", (dir_ / "out").string()});
        EXPECT_EQ(f.exit_code, 0);
        EXPECT_LT(f.peak_bytes, documented_peak_bytes(static_cast<std::uint64_t>(w) * h))
            << f.peak_bytes / (1 << 20) << " MiB";
      }
    }
  }
}

}  // namespace
}  // namespace groovetrace
