// `groovetrace run --method robust` end to end: outputs, report.json's candidate seams,
// --step / --slices / --max-seams, no groove -> exit 4, unorganized input, base frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <groovetrace/cloud_io.hpp>
#include <nlohmann/json.hpp>
#include <random>

#include "support/cli_runner.hpp"
#include "support/robust_scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

std::vector<Eigen::Vector3d> csv_positions(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "idx,x_m,y_m,z_m,qx,qy,qz,qw,rx,ry,rz");
  std::vector<Eigen::Vector3d> out;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    out.emplace_back(v.at(1), v.at(2), v.at(3));
  }
  return out;
}

class CliRobust : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  fs::path write_scan(const Cloud& cloud, const std::string& name) {
    const fs::path p = dir_ / name;
    write_file_atomic(p.string(), pcd_bytes(cloud));
    return p;
  }
  static test::TopCamera camera() {
    test::TopCamera cam;
    cam.noise = 0.0002;
    return cam;
  }
  fs::path dir_;
};

TEST_F(CliRobust, GrooveOnABoxWithReportedCandidates) {
  const test::HeightRender box = test::render_box(camera(), true);
  const fs::path scan = write_scan(box.cloud, "box.pcd");
  const fs::path out = dir_ / "out";
  // robust is the default method.
  const auto r = test::run_cli(
      "run " + scan.string() + " -o " + out.string() + " --camera-frame-program", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  for (const char* f : {"annotated.pcd", "overview.png", "trajectory.csv", "trajectory.json",
                        "program.script", "report.json"}) {
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  }
  EXPECT_FALSE(fs::exists(out / "trajectory_1.csv"));
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["method"], "robust");
  EXPECT_EQ(report["detection"]["threshold_mode"], "robust_concavity_mm");
  const auto& seams = report["robust"]["seams"];
  ASSERT_GE(seams.size(), 1u);
  EXPECT_TRUE(seams[0]["accepted"].get<bool>());
  EXPECT_GT(seams[0]["score"].get<double>(), 50.0);
  EXPECT_EQ(seams[0]["file"], "trajectory.csv");
  EXPECT_NEAR(seams[0]["width_m"].get<double>(), 0.010, 0.0015);
  for (std::size_t k = 1; k < seams.size(); ++k) {
    EXPECT_LE(seams[k]["score"].get<double>(), seams[0]["score"].get<double>());
    if (seams[k]["file"].is_null()) {
      EXPECT_TRUE(seams[k]["max_rotation_deg_per_mm"].is_null());
    }
  }
  // The torch's fastest turn, per exported seam and at the top level: a straight groove on a
  // flat top turns it by little.
  const double rate = seams[0]["max_rotation_deg_per_mm"].get<double>();
  EXPECT_GE(rate, 0.0);
  EXPECT_LT(rate, 5.0);
  EXPECT_EQ(report["trajectory"]["max_rotation_deg_per_mm"].get<double>(), rate);
  const double at = report["trajectory"]["max_rotation_at_m"].get<double>();
  EXPECT_GE(at, 0.0);
  EXPECT_LE(at, report["trajectory"]["length_m"].get<double>() + 1e-9);
  EXPECT_EQ(report["parameters"]["orientation_blend"].get<double>(), 0.025);
  // Waypoints every 2 mm along the groove (world x at y = 0 on the block's top).
  const auto poses = csv_positions(out / "trajectory.csv");
  ASSERT_GT(poses.size(), 40u);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Vector3d w = box.T_world_camera * poses[k];
    EXPECT_NEAR(w.y(), 0.0, 0.001);
    if (k > 0) {
      EXPECT_LT((poses[k] - poses[k - 1]).norm(), 0.0021);
    }
  }
  // annotated.pcd: groove points where the truth has them.
  const Cloud annotated = read_cloud((out / "annotated.pcd").string());
  EXPECT_EQ(annotated.width, box.cloud.width);
  EXPECT_EQ(annotated.height, box.cloud.height);
}

// A fillet (T-joint) from the renderer: the joint type and the per-station corner geometry in
// report.json, with the weld's leg as given (the scan cannot show it).
TEST_F(CliRobust, FilletReportsItsJointAndTheWeldsLeg) {
  const fs::path scan = dir_ / "fillet.pcd";
  const auto s = test::run_cli(
      "synth --shape straight --joint fillet --resolution 640x480 --seed 21 -o " + scan.string(),
      dir_);
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const fs::path out = dir_ / "out";
  const auto r =
      test::run_cli("run " + scan.string() + " --fillet-leg 0.006 -q -o " + out.string(), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  EXPECT_EQ(report["parameters"]["fillet_leg"].get<double>(), 0.006);
  const auto& seam = report["robust"]["seams"].at(0);
  EXPECT_EQ(seam["joint"], "fillet");
  std::vector<double> angles;
  for (const auto& st : seam["stations"]) {
    if (st["fit"] != "corner") continue;
    // The weld face between the legs' ends and its throat, for legs of 6 mm on a 90 deg corner.
    EXPECT_NEAR(st["opening_m"].get<double>(), 0.006 * std::sqrt(2.0), 0.0015);
    EXPECT_NEAR(st["depth_m"].get<double>(), 0.006 / std::sqrt(2.0), 0.0008);
    angles.push_back(st["included_angle_deg"].get<double>());
    EXPECT_NEAR(angles.back(), 90.0, 20.0);  // 74 deg at the first station, 87-97 elsewhere
    EXPECT_TRUE(st["misalignment_m"].is_null());
  }
  ASSERT_GT(angles.size(), seam["stations"].size() / 2);
  std::nth_element(angles.begin(), angles.begin() + angles.size() / 2, angles.end());
  EXPECT_NEAR(angles[angles.size() / 2], 90.0, 3.0);
}

// report.json's stations and tacks count their arc length as the trajectory runs, like
// max_rotation_at_m: this seam is traced from its far end (larger x), and its tacks were
// reported at 300 mm minus their place. Against the renderer's tacks (the truth's seam runs
// the same way as the path: towards larger x).
TEST_F(CliRobust, StationsAndTacksRunWithTheTrajectory) {
  const fs::path scan = dir_ / "tacks.pcd";
  const auto s = test::run_cli(
      "synth --shape straight --tacks 3 --tack-height 0.7 --resolution "
      "640x480 --distance 0.4 --tilt 20 --seed 354 -o " +
          scan.string(),
      dir_);
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli("run " + scan.string() + " -q -o " + out.string(), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(out / "report.json"));
  const auto& seam = report["robust"]["seams"].at(0);
  const auto path = nlohmann::json::parse(test::read_text(out / "trajectory.json"));
  const auto& first = path["waypoints"].front()["position_m"];
  const auto& stations = seam["stations"];
  ASSERT_GT(stations.size(), 100u);
  double gap = 0, last_s = -1;
  for (int i = 0; i < 3; ++i) {
    gap = std::max(gap, std::abs(stations[0]["root_m"][i].get<double>() - first[i].get<double>()));
  }
  EXPECT_LT(gap, 0.003);
  for (const auto& st : stations) {
    EXPECT_GT(st["s_m"].get<double>(), last_s);
    last_s = st["s_m"].get<double>();
  }
  const auto truth = nlohmann::json::parse(test::read_text(dir_ / "tacks.truth.json"));
  const auto& tacks = truth["seams"].at(0)["tacks"];
  ASSERT_GE(seam["tacks"].size(), 2u);
  for (const auto& found : seam["tacks"]) {
    double nearest = 1.0;
    for (const auto& t : tacks) {
      nearest = std::min(
          nearest, std::abs(found["position_m"].get<double>() - t["position_m"].get<double>()));
    }
    EXPECT_LT(nearest, 0.008) << found.dump();
  }
}

TEST_F(CliRobust, StepSlicesAndMaxSeams) {
  // Two parallel straight grooves 40 mm apart.
  const fs::path scan = write_scan(
      test::render_plate_groove(
          [](double, double y) { return std::min(std::abs(y - 0.02), std::abs(y + 0.02)); },
          camera())
          .cloud,
      "two.pcd");
  const auto r = test::run_cli("run " + scan.string() + " -o " + (dir_ / "a").string() +
                                   " --method robust --max-seams 2 --step 0.004 -q "
                                   "--camera-frame-program",
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("seams found"), std::string::npos) << r.err;  // both exported
  ASSERT_TRUE(fs::is_regular_file(dir_ / "a" / "trajectory_1.csv"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "a" / "program_1.script"));
  const auto first = csv_positions(dir_ / "a" / "trajectory.csv");
  const auto second = csv_positions(dir_ / "a" / "trajectory_1.csv");
  ASSERT_GT(first.size(), 10u);
  ASSERT_GT(second.size(), 10u);
  EXPECT_GT((first.front() - second.front()).norm(), 0.03);  // two different seams
  EXPECT_LT((first[1] - first[0]).norm(), 0.0041);
  const auto report = nlohmann::json::parse(test::read_text(dir_ / "a" / "report.json"));
  EXPECT_EQ(report["parameters"]["max_seams"], 2);
  EXPECT_EQ(report["robust"]["seams"][1]["file"], "trajectory_1.csv");

  EXPECT_EQ(report["detection"]["seams_found"], 2);
  EXPECT_EQ(report["detection"]["seams_exported"], 2);

  // One seam exported of two: said on stderr and in report.json.
  const auto s = test::run_cli(
      "run " + scan.string() + " -o " + (dir_ / "b").string() + " --method robust --slices 25 -q",
      dir_);
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_EQ(csv_positions(dir_ / "b" / "trajectory.csv").size(), 25u);
  EXPECT_NE(s.err.find("groovetrace: warning: 2 seams found, 1 exported; --max-seams 2 exports "
                       "them all"),
            std::string::npos)
      << s.err;
  const auto one = nlohmann::json::parse(test::read_text(dir_ / "b" / "report.json"));
  EXPECT_EQ(one["detection"]["seams_found"], 2);
  EXPECT_EQ(one["detection"]["seams_exported"], 1);
}

TEST_F(CliRobust, NoGrooveExitsWithFour) {
  const fs::path scan = write_scan(test::render_box(camera(), false).cloud, "box.pcd");
  const auto r = test::run_cli(
      "run " + scan.string() + " -o " + (dir_ / "out").string() + " --method robust -q", dir_);
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("no groove"), std::string::npos) << r.err;
  // Nothing accepted: the second search ran (at RobustParams::retry_threshold_k) and the line
  // says so.
  EXPECT_NE(r.err.find("searched again with a lower threshold: none either"), std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "trajectory.csv"));
}

TEST_F(CliRobust, UnorganizedCloudInABaseFrameWithItsViewpoint) {
  // The scan flattened, shuffled and moved into a robot base frame; the sensor origin given
  // with --viewpoint.
  const test::HeightRender box = test::render_box(camera(), true);
  const Eigen::Isometry3d T_base_camera =
      Eigen::Translation3d(0.3, 0.1, 0.5) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < box.cloud.size(); ++i) {
    if (box.cloud.valid(i)) order.push_back(i);
  }
  std::mt19937 rng(3);
  std::shuffle(order.begin(), order.end(), rng);
  Cloud flat;
  flat.resize(order.size());
  flat.width = static_cast<std::uint32_t>(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Eigen::Vector3d p = T_base_camera * box.cloud.point(order[k]).cast<double>();
    flat.x[k] = static_cast<float>(p.x());
    flat.y[k] = static_cast<float>(p.y());
    flat.z[k] = static_cast<float>(p.z());
  }
  const fs::path scan = write_scan(flat, "flat.pcd");
  const auto r = test::run_cli("run " + scan.string() + " -o " + (dir_ / "out").string() +
                                   " --method robust --viewpoint 0.3,0.1,0.5 -q",
                               dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto poses = csv_positions(dir_ / "out" / "trajectory.csv");
  ASSERT_GT(poses.size(), 40u);
  const Eigen::Isometry3d T_world_base = box.T_world_camera * T_base_camera.inverse();
  for (const auto& p : poses) EXPECT_NEAR((T_world_base * p).y(), 0.0, 0.001);
}

}  // namespace
}  // namespace groovetrace
