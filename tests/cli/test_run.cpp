// `groovetrace run` end to end on a rendered 640x480 V-groove with known geometry.
#include <gtest/gtest.h>

#include <groovetrace/cloud_io.hpp>
#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

struct CsvPose {
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
};

std::vector<CsvPose> read_trajectory_csv(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "idx,x_m,y_m,z_m,qx,qy,qz,qw,rx,ry,rz");
  std::vector<CsvPose> poses;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    EXPECT_EQ(v.size(), 11u);
    poses.push_back(
        {Eigen::Vector3d(v[1], v[2], v[3]), Eigen::Quaterniond(v[7], v[4], v[5], v[6])});
  }
  return poses;
}

class CliRun : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    test::VGrooveScene s;  // 640x480 at 0.4 m, 10 mm wide, 4 mm deep groove
    s.tilt_deg = 12;
    s.yaw_deg = 8;
    s.noise_sigma = 0.0002;
    scene_ = test::render_vgroove(s);
    scene_params_ = s;
    scan_ = dir_ / "scan.pcd";
    write_file_atomic(scan_.string(), pcd_bytes(scene_.cloud));
  }
  fs::path dir_, scan_;
  test::RenderedScene scene_;
  test::VGrooveScene scene_params_;
};

TEST_F(CliRun, StraightGrooveProducesAllOutputsAlongTheGroove) {
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli("run " + scan_.string() + " -o " + out.string() +
                                   " --method paper --backend cpu --camera-frame-program",
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("outputs in"), std::string::npos) << r.out;
  for (const char* f : {"annotated.pcd", "overview.png", "trajectory.csv", "trajectory.json",
                        "program.script", "report.json"}) {
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  }

  // Waypoints follow the groove: the paper's geometric median sits between the walls, so
  // compare with the groove's centre line at half depth (2 mm tolerance, the bound),
  // and require the lateral offset alone to be small.
  const Eigen::Vector3d dir = scene_.groove_dir_camera;
  const Eigen::Vector3d mid =
      scene_.root_point_camera + scene_.up_camera * (scene_params_.depth / 2);
  const auto poses = read_trajectory_csv(out / "trajectory.csv");
  ASSERT_EQ(poses.size(), 50u);
  double max_dist = 0, max_lateral = 0;
  for (const auto& pose : poses) {
    Eigen::Vector3d off = pose.p - mid;
    off -= off.dot(dir) * dir;
    max_dist = std::max(max_dist, off.norm());
    const Eigen::Vector3d across = dir.cross(scene_.up_camera);
    max_lateral = std::max(max_lateral, std::abs(off.dot(across)));
    // The torch points into the plate: tool z against the plate normal, within 10 deg.
    const Eigen::Vector3d z = pose.q.normalized().toRotationMatrix().col(2);
    EXPECT_GT(z.dot(-scene_.up_camera), std::cos(10 * M_PI / 180));
  }
  EXPECT_LT(max_dist, 0.002);
  EXPECT_LT(max_lateral, 0.001);
  // Ordered along the groove, spanning most of the visible length.
  const Eigen::Vector3d along = poses.back().p - poses.front().p;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    EXPECT_GT((poses[i].p - poses[i - 1].p).dot(along), 0.0) << "waypoint " << i;
  }
  EXPECT_GT((poses.back().p - poses.front().p).norm(), 0.15);

  // annotated.pcd keeps the input shape and marks the groove where the truth is.
  const Cloud annotated = read_cloud((out / "annotated.pcd").string());
  EXPECT_EQ(annotated.width, 640u);
  EXPECT_EQ(annotated.height, 480u);
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["backend"], "cpu");
  EXPECT_EQ(report["points"]["total"], 640 * 480);
  EXPECT_GT(report["points"]["groove"].get<int>(), 1000);
  EXPECT_TRUE(report["timings_ms"].contains("descriptor"));
  EXPECT_DOUBLE_EQ(report["parameters"]["radius"].get<double>(), 0.003);

  const std::string script = test::read_text(out / "program.script");
  EXPECT_NE(script.find("def weld_seam():"), std::string::npos);
  std::size_t moves = 0;
  for (auto at = script.find("movep("); at != std::string::npos;
       at = script.find("movep(", at + 1)) {
    ++moves;
  }
  EXPECT_EQ(moves, poses.size() - 1);  // every waypoint after the first is a movep
}

// A file name is bytes, not necessarily UTF-8: the run still succeeds, and its JSON files name
// the scan with U+FFFD for the bytes that are not UTF-8 (nlohmann's dump threw: exit 5).
TEST_F(CliRun, AScanPathThatIsNotUtf8StillRuns) {
  const fs::path odd = dir_ / "scan\xff.pcd";
  fs::copy_file(scan_, odd);
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli("run '" + odd.string() + "' -o " + out.string() + " -q", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["input"], (dir_ / "scan\xef\xbf\xbd.pcd").string());
}

// The same scan and parameters give byte-identical outputs whatever the thread count, for
// both methods and on the default backend too; report.json differs only in its timings and
// the device line (which names the thread count).
TEST_F(CliRun, OutputsAreTheSameForEveryThreadCount) {
  if (test::small_runs()) {  // six runs: the smaller scan of the repeated-run tests
    test::VGrooveScene s = test::repeated_run_scene();
    s.tilt_deg = scene_params_.tilt_deg;
    s.yaw_deg = scene_params_.yaw_deg;
    s.noise_sigma = scene_params_.noise_sigma;
    write_file_atomic(scan_.string(), pcd_bytes(test::render_vgroove(s).cloud));
  }
  for (const std::string flags :
       {"--method robust --backend cpu", "--method robust", "--method paper --backend cpu"}) {
    SCOPED_TRACE(flags);
    std::vector<fs::path> outs;
    for (const char* threads : {"1", "2"}) {
      outs.push_back(dir_ / (std::string("out") + threads));
      fs::remove_all(outs.back());
      const auto r =
          test::run_cli("run " + scan_.string() + " -o " + outs.back().string() + " -q " + flags,
                        dir_, std::string("OMP_NUM_THREADS=") + threads);
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    for (const auto& entry : fs::directory_iterator(outs[0])) {
      const std::string name = entry.path().filename().string();
      const std::string a = test::read_text(entry.path()), b = test::read_text(outs[1] / name);
      if (name != "report.json") {
        EXPECT_TRUE(a == b) << name << " differs between 1 and 2 threads";
        continue;
      }
      nlohmann::json ja = nlohmann::json::parse(a), jb = nlohmann::json::parse(b);
      for (auto* j : {&ja, &jb}) {
        j->erase("timings_ms");
        j->erase("device");
      }
      EXPECT_EQ(ja, jb) << "report.json differs beyond timings and device";
    }
  }
}

TEST_F(CliRun, FlagsOverrideConfigAndReportRecordsThem) {
  const fs::path out = dir_ / "out_cfg";
  const fs::path cfg = dir_ / "cfg.yaml";
  std::ofstream(cfg) << "slices: 20\nthreshold: 6.0\nweld_speed: 0.01\n";
  const auto r = test::run_cli("run " + scan_.string() + " -o " + out.string() + " --config " +
                                   cfg.string() + " --method paper --slices 30 --backend cpu -q",
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");  // --quiet
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["parameters"]["slices"], 30);                           // flag wins
  EXPECT_DOUBLE_EQ(report["parameters"]["threshold"].get<double>(), 6.0);  // from config
  EXPECT_DOUBLE_EQ(report["parameters"]["weld_speed"].get<double>(), 0.01);
  EXPECT_EQ(read_trajectory_csv(out / "trajectory.csv").size(), 30u);
}

TEST_F(CliRun, AutoThresholdFindsTheGroove) {
  const fs::path out = dir_ / "out_auto";
  const auto r = test::run_cli("run " + scan_.string() + " -o " + out.string() +
                                   " --method paper --threshold auto --backend cpu",
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["detection"]["threshold_mode"], "otsu_log_descriptor");
  EXPECT_EQ(report["parameters"]["threshold"], "auto");
  const auto poses = read_trajectory_csv(out / "trajectory.csv");
  const Eigen::Vector3d dir = scene_.groove_dir_camera;
  const Eigen::Vector3d across = dir.cross(scene_.up_camera);
  for (const auto& pose : poses) {
    EXPECT_LT(std::abs((pose.p - scene_.root_point_camera).dot(across)), 0.001);
  }
}

// A flag of the other method does nothing there: the user is told, on stderr and in
// report.json, once per flag, whether it came from the config file or the command line.
TEST_F(CliRun, FlagsOfTheOtherMethodAreWarnedAbout) {
  const fs::path out = dir_ / "out_other";
  const fs::path cfg = dir_ / "cfg.yaml";
  std::ofstream(cfg) << "radius: 0.004\n";
  const auto r =
      test::run_cli("run " + scan_.string() + " -o " + out.string() + " --config " + cfg.string() +
                        " --radius 0.005 --step 0.003 --slices 20" +
                        " --method paper --backend cpu -q " + test::identity_calibration(dir_),
                    dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string step_warning = "step belongs to the robust method; the paper method ignores it";
  EXPECT_NE(r.err.find("warning: " + step_warning), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("radius belongs"), std::string::npos) << r.err;  // paper's own
  EXPECT_EQ(r.err.find("slices belongs"), std::string::npos) << r.err;  // both methods'
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["warnings"], nlohmann::json::array({step_warning}));

  const fs::path out2 = dir_ / "out_other_robust";
  const auto r2 =
      test::run_cli("run " + scan_.string() + " -o " + out2.string() + " --config " + cfg.string() +
                        " --radius 0.005 --backend cpu -q " + test::identity_calibration(dir_),
                    dir_);
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  const std::string radius_warning =
      "radius belongs to the paper method; the robust method ignores it";
  const auto report2 = nlohmann::json::parse(test::read_text(out2 / "report.json"));
  EXPECT_EQ(report2["warnings"], nlohmann::json::array({radius_warning}));  // once, not twice
  EXPECT_EQ(report2["method"], "robust");

  // trajectory.json says which axis each method's torch follows.
  const auto tool_frame = [](const fs::path& dir) {
    return nlohmann::json::parse(test::read_text(dir / "trajectory.json"))["tool_frame"]
        .get<std::string>();
  };
  EXPECT_NE(tool_frame(out).find("-mean surface normal of the slice"), std::string::npos);
  EXPECT_NE(tool_frame(out2).find("-bisector of the two fitted walls"), std::string::npos);
}

}  // namespace
}  // namespace groovetrace
