// What stands between a trajectory and a program a cell runs (docs/robot.md): no program in
// camera coordinates unless asked, the guards (exit 7), warnings for implausible detections,
// and the weld parameters' bad values.
#include <gtest/gtest.h>

#include <groovetrace/cloud_io.hpp>
#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class ProgramSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    test::VGrooveScene s = test::repeated_run_scene();  // 10 mm wide, 4 mm deep
    s.tilt_deg = 10;
    s.noise_sigma = 0.0002;
    scan_ = dir_ / "scan.pcd";
    write_file_atomic(scan_.string(), pcd_bytes(test::render_vgroove(s).cloud));
  }
  test::CliResult run(const std::string& flags) {
    return test::run_cli(
        "run " + scan_.string() + " -o " + out().string() + " -q --backend cpu " + flags, dir_);
  }
  std::string calibration() const { return test::identity_calibration(dir_); }
  fs::path out() const { return dir_ / "out"; }
  json report() const { return json::parse(test::read_text(out() / "report.json")); }
  fs::path dir_, scan_;
};

bool has_warning(const json& report, const std::string& words) {
  for (const auto& w : report["warnings"]) {
    if (w.get<std::string>().find(words) != std::string::npos) return true;
  }
  return false;
}

TEST_F(ProgramSafety, CameraCoordinatesGiveNoProgramUnlessAsked) {
  auto r = run("");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(out() / "program.script"));
  EXPECT_TRUE(fs::exists(out() / "trajectory.csv"));
  EXPECT_NE(r.err.find("groovetrace: warning: no robot program written: the trajectory is in "
                       "camera coordinates"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(has_warning(report(), "no robot program written"));
  EXPECT_TRUE(report()["programs"][0]["file"].is_null());

  r = run("--camera-frame-program");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out() / "program.script"));
  EXPECT_NE(r.err.find("the robot program is in camera coordinates"), std::string::npos) << r.err;
  EXPECT_EQ(report()["programs"][0]["file"], "program.script");

  r = run(calibration());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out() / "program.script"));
  EXPECT_EQ(r.err.find("camera coordinates"), std::string::npos) << r.err;
}

// A guard that trips: exit 7, one line naming the limit, report.json alone (no program, no
// earlier program left behind).
TEST_F(ProgramSafety, AGuardThatTripsLeavesNoProgram) {
  ASSERT_EQ(run(calibration()).exit_code, 0);
  ASSERT_TRUE(fs::exists(out() / "program.script"));
  const auto r = run(calibration() + " --max-step 0.0005");  // waypoints are 2 mm apart
  EXPECT_EQ(r.exit_code, 7) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("unsafe program, no program written: pass 'seam', waypoint 1: a step of"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("(max_step 0.5 mm)"), std::string::npos) << r.err;
  test::expect_failure_report(out(), 7, r.err);
  EXPECT_EQ(report()["status"], "unsafe_program");
}

TEST_F(ProgramSafety, WorkspaceBoxInTheBaseFrame) {
  // The plate lies 0.2 or 0.4 m in front of the camera (= base): a box ending at 0.15 m refuses.
  auto r = run(calibration() + " --workspace=-1,-1,-1,1,1,0.15");
  EXPECT_EQ(r.exit_code, 7) << r.err;
  EXPECT_NE(r.err.find("lies outside the workspace"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out() / "program.script"));
  r = run(calibration() + " --workspace=-1,-1,-1,1,1,1");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out() / "program.script"));
  EXPECT_EQ(report()["parameters"]["workspace"], json({-1, -1, -1, 1, 1, 1}));
}

TEST_F(ProgramSafety, WrongWeldAndGuardValuesAreUsageErrors) {
  for (const std::string& flags : std::vector<std::string>{
           "--workspace=-1,-1,-1,1,1,1", "--workspace 1,2,3 " + calibration(),
           "--workspace=1,-1,-1,-1,1,1 " + calibration(), "--weave spiral", "--travel-angle 75",
           "--work-angle=-61", "--max-step 0", "--max-step-rotation 200", "--weave-wavelength 0",
           "--bead-area=-1", "--multi-pass maybe", "--camera-frame-program=perhaps"}) {
    const auto r = run(flags);
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << flags << ": " << r.err;
    EXPECT_EQ(r.err.rfind("groovetrace: error: ", 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(out() / "program.script")) << flags;
  }
}

// A 10 mm wide, 4 mm deep V (20 mm^2) with 8 mm^2 beads: report.json lists the passes, the
// root first and the cap last, each as long as the seam.
TEST_F(ProgramSafety, MultiPassIsReportedPassByPass) {
  const auto r = run(calibration() + " --multi-pass --bead-area 8e-6");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json passes = report()["programs"][0]["passes"];
  ASSERT_GE(passes.size(), 3u) << passes.dump();
  EXPECT_EQ(passes.front()["name"], "root");
  EXPECT_EQ(passes.back()["name"].get<std::string>().rfind("cap", 0), 0u) << passes.dump();
  const double seam = report()["trajectory"]["length_m"];
  for (const auto& p : passes) EXPECT_NEAR(p["length_m"].get<double>(), seam, 0.01) << p.dump();
}

// A weave wider than the 10 mm opening is cut to it, and said; the pass has the weave's poses.
TEST_F(ProgramSafety, AWeaveIsBoundedByTheOpening) {
  const auto r = run(calibration() + " --weave zigzag --weave-amplitude 0.02");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("groovetrace: warning: weave: the amplitude is cut to half the fitted "
                       "opening"),
            std::string::npos)
      << r.err;
  const json pass = report()["programs"][0]["passes"][0];
  // Corners every 2 mm (a 4 mm wavelength) against waypoints every 2 mm, and each corner
  // lies up to 5 mm across: the woven pass is longer than the seam.
  EXPECT_GT(pass["length_m"].get<double>(), 1.5 * report()["trajectory"]["length_m"].get<double>());
}

// An easy_handeye eye-on-base file is T_base_camera already: with a flange pose that is not the
// identity it would be applied twice, so the run stops (exit 3, the file named); with an
// identity flange pose (a camera fixed in the cell) it runs.
TEST_F(ProgramSafety, AnEyeOnBaseCalibrationNeedsAnIdentityFlangePose) {
  std::ofstream(dir_ / "eye_on_base.yaml")
      << "parameters:\n  eye_on_hand: false\n  robot_base_frame: base_link\n"
         "  tracking_base_frame: camera_link\ntransformation:\n  qw: 1.0\n  qx: 0.0\n"
         "  qy: 0.0\n  qz: 0.0\n  x: 0.0\n  y: 0.0\n  z: 0.0\n";
  std::ofstream(dir_ / "moved.yaml") << "translation: [0.4, 0, 0.3]\nrotation: [0, 0, 0, 1]\n";
  const std::string hand_eye = "--hand-eye " + (dir_ / "eye_on_base.yaml").string();
  auto r = run(hand_eye + " --flange-pose " + (dir_ / "moved.yaml").string());
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("eye_on_base.yaml: an eye-on-base calibration"), std::string::npos) << r.err;
  calibration();  // writes the identity flange.yaml
  r = run(hand_eye + " --flange-pose " + (dir_ / "flange.yaml").string());
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// The paper method with a zero threshold marks every point: exit 0 as before, but warned.
TEST_F(ProgramSafety, AnImplausibleDetectionIsWarned) {
  const auto r = run("--method paper --threshold 0");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("groovetrace: warning: implausible detection: "), std::string::npos)
      << r.err;
  EXPECT_TRUE(has_warning(report(), "% of the valid points are marked groove"));
  const auto good = run("");
  ASSERT_EQ(good.exit_code, 0) << good.err;
  EXPECT_EQ(good.err.find("implausible"), std::string::npos) << good.err;
}

}  // namespace
}  // namespace groovetrace
