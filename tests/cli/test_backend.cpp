// Backend choice from the CLI: `auto` (the default) takes the OpenCL device when there is one;
// when no OpenCL platform exists it falls back to the CPU backend and says so, and an explicit
// `opencl` is an error (exit 5), not a silent fallback.
#include <gtest/gtest.h>

#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/opencl.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

// The ICD loader finds platforms through the vendor files in this directory; an empty one
// means no OpenCL platform at all, as on a machine without a driver.
const char* kNoOpenCl = "OCL_ICD_VENDORS=/nonexistent-groovetrace-icd";

// A platform that exists but lists no device: an ICD directory holding only PoCL, whose
// POCL_DEVICES names a driver this PoCL does not have (cuda), so it finds no device. Returns
// the environment for run_cli.
std::string pocl_without_devices(const fs::path& dir) {
  const fs::path vendors = dir / "icd";
  fs::create_directories(vendors);
  std::ofstream(vendors / "pocl.icd") << "libpocl.so.2\n";
  return "OCL_ICD_VENDORS=" + vendors.string() + " POCL_DEVICES=cuda";
}

class CliBackend : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    test::VGrooveScene s;
    s.width = 320;
    s.height = 240;
    scan_ = dir_ / "scan.pcd";
    write_file_atomic(scan_.string(), pcd_bytes(test::render_vgroove(s).cloud));
    // In the base frame (= the camera's): no camera-frame warning among the backend's lines.
    calib_ = test::identity_calibration(dir_);
  }
  fs::path dir_, scan_;
  std::string calib_;
};

TEST_F(CliBackend, AutoFallsBackToCpuWithAWarning) {
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string() +
                                   " --backend auto --method paper",
                               dir_, kNoOpenCl);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("groovetrace: warning: OpenCL unavailable"), std::string::npos) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["backend"], "cpu");
  ASSERT_FALSE(report["warnings"].empty());
  EXPECT_NE(report["warnings"][0].get<std::string>().find("OpenCL unavailable"), std::string::npos);
}

TEST_F(CliBackend, ExplicitOpenClWithoutPlatformFails) {
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string() +
                                   " --backend opencl --method paper",
                               dir_, kNoOpenCl);
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("groovetrace: error: ", 0), 0u) << r.err;
  test::expect_failure_report(out, 5, r.err);
}

// No device, but a platform: auto runs on the CPU and says why; opencl is exit 5, one line
// that names the platform, and OUTDIR holds only report.json.
TEST_F(CliBackend, PlatformWithoutDeviceFallsBackUnderAuto) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path out = dir_ / "out";
  const auto r =
      test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string() + " -q", dir_,
                    pocl_without_devices(dir_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err,
            "groovetrace: warning: OpenCL unavailable, using the cpu backend: no OpenCL device "
            "found: the platform Portable Computing Language lists no device\n");
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["backend"], "cpu");
  ASSERT_FALSE(report["warnings"].empty());
  EXPECT_NE(report["warnings"][0].get<std::string>().find("lists no device"), std::string::npos);
}

TEST_F(CliBackend, PlatformWithoutDeviceFailsExplicitOpenCl) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli(
      "run " + scan_.string() + " " + calib_ + " -o " + out.string() + " --backend opencl", dir_,
      pocl_without_devices(dir_));
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_EQ(r.err,
            "groovetrace: error: no OpenCL device found: the platform Portable Computing Language "
            "lists no device\n");
  test::expect_failure_report(out, 5, r.err);
}

// A kernel build failure on an explicit `--backend opencl`: exit 5, one line that names the
// file holding the compiler's full output, and no outputs.
TEST_F(CliBackend, KernelBuildFailureNamesTheCompilerLog) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path out = dir_ / "out";
  // The log's old fixed name, planted as a symlink to a file of someone else's: the log went
  // through it and overwrote that file.
  const fs::path victim = dir_ / "victim.txt";
  std::ofstream(victim) << "keep me\n";
  fs::create_symlink(victim, dir_ / "groovetrace-opencl-build.log");
  const std::string env =
      "TMPDIR=" + dir_.string() + " GROOVETRACE_OPENCL_OPTIONS=-DVW=3";  // common.cl refuses it
  const auto r = test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string() +
                                   " --backend opencl --method paper",
                               dir_, env);
  EXPECT_EQ(r.exit_code, 5) << r.err;
  // One line of ours; PoCL's compiler prints its own count of errors to stderr as well.
  std::istringstream lines(r.err);
  int ours = 0;
  for (std::string line; std::getline(lines, line);) ours += line.rfind("groovetrace:", 0) == 0;
  EXPECT_EQ(ours, 1) << r.err;
  EXPECT_NE(r.err.find("failed to build"), std::string::npos) << r.err;
  const std::string prefix = (dir_ / "groovetrace-opencl-build-").string();
  const std::size_t at = r.err.find(prefix);
  ASSERT_NE(at, std::string::npos) << r.err;
  const fs::path log = r.err.substr(at, r.err.find(')', at) - at);
  EXPECT_EQ(log.extension(), ".log") << log;
  EXPECT_NE(test::read_text(log).find("VW must be"), std::string::npos) << log;
  EXPECT_EQ(test::read_text(victim), "keep me\n");
  test::expect_failure_report(out, 5, r.err.substr(r.err.find("groovetrace: error: ")));
}

// The same build failure under `--backend auto` (the default): the run goes on on the CPU,
// exit 0, with the reason as a warning on stderr and in report.json.
TEST_F(CliBackend, KernelBuildFailureUnderAutoFallsBackToCpu) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path out = dir_ / "out";
  const std::string env = "TMPDIR=" + dir_.string() + " GROOVETRACE_OPENCL_OPTIONS=-DVW=3";
  const auto r = test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string() +
                                   " --backend auto --method paper -q",
                               dir_, env);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.err);
  std::vector<std::string> ours;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("groovetrace:", 0) == 0) ours.push_back(line);
  }
  ASSERT_EQ(ours.size(), 1u) << r.err;
  EXPECT_EQ(ours[0].rfind("groovetrace: warning: OpenCL unavailable, using the cpu backend: ", 0),
            0u)
      << r.err;
  EXPECT_NE(ours[0].find("failed to build"), std::string::npos) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["exit_code"], 0);
  EXPECT_EQ(report["backend"], "cpu");
  ASSERT_FALSE(report["warnings"].empty());
  EXPECT_NE(report["warnings"][0].get<std::string>().find("failed to build"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "program.script"));
}

// Failure 9: on a cold PoCL kernel cache, PoCL's compiler printed "333 warnings generated." on
// stderr past -q (-Wpsabi on every float16 argument, on a CPU without AVX-512). This CPU may
// draw none, so one warning is injected: kernels/common.cl defines GT_CAT_ again ("macro
// redefined") and keeps its own definition, so the kernels are unchanged.
TEST_F(CliBackend, ColdKernelCacheBuildPrintsNothingWithQuiet) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path cache = dir_ / "pocl-cache", out = dir_ / "out";
  fs::create_directories(cache);
  const auto r =
      test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string() + " -q", dir_,
                    "POCL_CACHE_DIR=" + cache.string() + " GROOVETRACE_OPENCL_OPTIONS=-DGT_CAT_");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, "");
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["backend"], "opencl");
  EXPECT_FALSE(fs::is_empty(cache)) << "the kernels were not compiled into the fresh cache";
}

// A cloud too large for the device's memory (lowered to 1 MiB by the backend's test hook; the
// 320x240 scan needs about 9 MiB): an explicit `--backend opencl` is exit 5 with one line
// naming both sizes and OUTDIR holding only report.json.
const char* kOneMiB = "GROOVETRACE_OPENCL_MEMORY_LIMIT=1048576";

TEST_F(CliBackend, CloudTooLargeForTheDeviceFailsExplicitOpenCl) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string() +
                                   " --backend opencl --method paper",
                               dir_, kOneMiB);
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("groovetrace: error: OpenCL device ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("has too little memory for 76800 points: needs up to "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("the device offers 1.0 MiB"), std::string::npos) << r.err;
  test::expect_failure_report(out, 5, r.err);
}

// The same under `--backend auto`, with either method: the stage that found the cloud too
// large runs on the CPU, and so does the rest; exit 0, one warning line, report.json says so.
TEST_F(CliBackend, CloudTooLargeForTheDeviceFallsBackUnderAuto) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  for (const char* method : {"robust", "paper"}) {
    const fs::path out = dir_ / (std::string("out-") + method);
    const auto r = test::run_cli(
        "run " + scan_.string() + " " + calib_ + " -o " + out.string() + " -q --method " + method,
        dir_, kOneMiB);
    ASSERT_EQ(r.exit_code, 0) << method << ": " << r.err;
    const std::string prefix = "groovetrace: warning: OpenCL failed, using the cpu backend: ";
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("too little memory"), std::string::npos) << r.err;
    const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
    EXPECT_EQ(report["backend"], "cpu") << method;
    ASSERT_FALSE(report["warnings"].empty()) << method;
    EXPECT_EQ("groovetrace: warning: " + report["warnings"][0].get<std::string>() + "\n", r.err);
    EXPECT_TRUE(fs::exists(out / "program.script")) << method;
  }
}

// In a batch, a worker whose backend fell back on one scan sets it up anew for the next: a
// scan that fits runs on the device again, without the other scan's warning. The limit (16
// MiB) lies between the 640x480 scan's need (about 23 MiB) and the 320x240 one's (9 MiB).
TEST_F(CliBackend, BatchGoesBackToTheDeviceAfterACloudTooLarge) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path in = dir_ / "scans", out = dir_ / "batch";
  fs::create_directories(in);
  test::VGrooveScene big;
  write_file_atomic((in / "a-big.pcd").string(), pcd_bytes(test::render_vgroove(big).cloud));
  fs::copy_file(scan_, in / "b-small.pcd");
  const auto r = test::run_cli("batch " + in.string() + " " + calib_ + " -o " + out.string() +
                                   " --jobs 1 --method paper --backend auto",
                               dir_, "GROOVETRACE_OPENCL_MEMORY_LIMIT=16777216");
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const auto a = nlohmann::json::parse(test::read_text(out / "a-big" / "report.json"));
  EXPECT_EQ(a["backend"], "cpu");
  ASSERT_FALSE(a["warnings"].empty());
  EXPECT_NE(a["warnings"][0].get<std::string>().find("too little memory for 307200 points"),
            std::string::npos)
      << a["warnings"];
  const auto b = nlohmann::json::parse(test::read_text(out / "b-small" / "report.json"));
  EXPECT_EQ(b["backend"], "opencl");
  EXPECT_TRUE(b["warnings"].empty()) << b["warnings"];
}

TEST_F(CliBackend, UnknownDeviceIsAUsageError) {
  const auto r =
      test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + (dir_ / "out").string() +
                        " --method paper --backend opencl --device no-such-device-name",
                    dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("no-such-device-name"), std::string::npos) << r.err;
}

TEST_F(CliBackend, DeviceIndexPastAnyNumberIsAUsageError) {
  if (list_opencl_devices().empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  // Past unsigned long, std::stoul threw: exit 5, "internal: stoul".
  const auto r =
      test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + (dir_ / "out").string() +
                        " --method paper --device 99999999999999999999",
                    dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("no OpenCL device 99999999999999999999"), std::string::npos) << r.err;
}

// The default run (--method robust, --backend auto) measures the creases with OpenCL on a
// machine that has a device, and report.json names it; without a platform it falls back to the
// cpu and says so.
TEST_F(CliBackend, DefaultRunUsesOpenClAndNamesTheDevice) {
  const std::vector<OpenClDevice> devices = list_opencl_devices();
  if (devices.empty()) GTEST_SKIP() << "no OpenCL device on this machine";
  const fs::path out = dir_ / "out";
  auto r = test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string(), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["method"], "robust");
  EXPECT_EQ(report["backend"], "opencl");
  EXPECT_NE(report["device"].get<std::string>().find(devices[0].name), std::string::npos)
      << report["device"];

  r = test::run_cli("run " + scan_.string() + " " + calib_ + " -o " + out.string(), dir_,
                    kNoOpenCl);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("groovetrace: warning: OpenCL unavailable"), std::string::npos) << r.err;
  report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["backend"], "cpu");
}

}  // namespace
}  // namespace groovetrace
