// `run --robot ur|abb|kuka` and `--dry-run` end to end: the chosen controller's program and
// no other, the trajectory files (CSV, JSON, ROS YAML) whatever the robot, and one line with
// exit 2 for a robot or setting that is wrong.
#include <gtest/gtest.h>

#include <groovetrace/cloud_io.hpp>
#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

class CliRobot : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    test::VGrooveScene s = test::repeated_run_scene();  // 10 mm wide, 4 mm deep groove
    s.tilt_deg = 10;
    scan_ = dir_ / "scan.pcd";
    write_file_atomic(scan_.string(), pcd_bytes(test::render_vgroove(s).cloud));
  }
  test::CliResult run(const fs::path& out, const std::string& flags) {
    return test::run_cli("run " + scan_.string() + " -o " + out.string() +
                             " --backend cpu -q --camera-frame-program " + flags,
                         dir_);
  }
  /// One line on stderr, exit 2, and no program: OUTDIR holds the failure's report.json
  /// alone (a value refused), or is not made (a command line CLI11 refuses).
  void expect_usage_error(const std::string& flags, const std::string& says) {
    const fs::path out = dir_ / "out_bad";
    fs::remove_all(out);
    const auto r = run(out, flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    if (fs::exists(out)) test::expect_failure_report(out, 2, r.err);
  }
  fs::path dir_, scan_;
};

bool has_name(const nlohmann::json& outputs, const std::string& name) {
  for (const auto& o : outputs)
    if (o["file"] == name) return true;
  return false;
}

TEST_F(CliRobot, AbbWritesItsModuleThenUrReplacesIt) {
  const fs::path out = dir_ / "out";
  const auto r = run(out, "--robot abb");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(test::entries(out),
            (std::vector<std::string>{"annotated.pcd", "overview.png", "program.mod", "report.json",
                                      "trajectory.csv", "trajectory.json", "trajectory.ros.yaml"}));
  const std::string mod = test::read_text(out / "program.mod");
  EXPECT_EQ(mod.rfind("MODULE program\n", 0), 0u);
  EXPECT_NE(mod.find("SetDO doArc0, 1;"), std::string::npos);
  EXPECT_NE(mod.find("! frame: camera"), std::string::npos);  // no calibration given
  EXPECT_NE(test::read_text(out / "trajectory.ros.yaml").find("  frame_id: camera\n"),
            std::string::npos);
  auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["parameters"]["robot"], "abb");
  EXPECT_EQ(report["parameters"]["dry_run"], false);
  EXPECT_TRUE(has_name(report["outputs"], "program.mod"));
  EXPECT_TRUE(has_name(report["outputs"], "trajectory.ros.yaml"));

  // The same OUTDIR again for UR, dry: program.mod is an earlier run's file, replaced whole.
  const auto r2 = run(out, "--dry-run");
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  EXPECT_FALSE(fs::exists(out / "program.mod"));
  const std::string script = test::read_text(out / "program.script");
  EXPECT_NE(script.find("# DRY RUN"), std::string::npos);
  EXPECT_EQ(script.find(", True)"), std::string::npos);
  EXPECT_NE(script.find("set_standard_digital_out(0, False)"), std::string::npos);
  report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["parameters"]["robot"], "ur");
  EXPECT_EQ(report["parameters"]["dry_run"], true);
}

TEST_F(CliRobot, KukaDryRunFromAConfigFile) {
  const fs::path out = dir_ / "out";
  const fs::path cfg = dir_ / "cfg.yaml";
  std::ofstream(cfg) << "robot: kuka\ndry_run: true\narc_output: 12\n";
  const auto r = run(out, "--config " + cfg.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "program.script"));
  const std::string src = test::read_text(out / "program.src");
  EXPECT_NE(src.find("DEF program( )"), std::string::npos);
  EXPECT_NE(src.find("$OUT[12] = FALSE"), std::string::npos);
  EXPECT_EQ(src.find("$OUT[12] = TRUE"), std::string::npos);
  EXPECT_NE(test::read_text(out / "program.dat").find("DEFDAT program"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "trajectory.csv"));
}

TEST_F(CliRobot, WrongRobotOrSettingIsOneLineAndExitTwo) {
  expect_usage_error("--robot fanuc", "robot: expected one of ur, abb, kuka, got 'fanuc'");
  expect_usage_error("--robot kuka", "KUKA output $OUT[1..4096]: give --arc-output N");
  expect_usage_error("--arc-output 8", "standard digital output 0..7 (got 8)");
  const fs::path cfg = dir_ / "bad.yaml";
  std::ofstream(cfg) << "dry_run: maybe\n";
  expect_usage_error("--config " + cfg.string(), "dry_run: expected true or false, got 'maybe'");
  // --dry-run is a switch: a value after it is no value of it.
  expect_usage_error("--dry-run false", "false");
}

}  // namespace
}  // namespace groovetrace
