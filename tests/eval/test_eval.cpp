// Metrics on hand-made cases with known answers, and the file reader on a hand-made run.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/eval.hpp>
#include <groovetrace/synth.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace gt = groovetrace;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A 20 x 10 "scan" whose truth labels 40 points, and one straight seam in the camera frame:
// from x = -0.1 to 0.1 m at y = 0, z = 0.4, the surface facing the camera (normal -z).
gt::SynthTruth hand_truth() {
  gt::SynthTruth t;
  t.camera.width = 20;
  t.camera.height = 10;
  t.label.assign(200, 0);
  t.valid.assign(200, 1);
  for (int i = 80; i < 120; ++i) t.label[i] = 1;  // rows 4 and 5
  gt::Seam s;
  for (int k = 0; k <= 200; ++k) {
    s.root.emplace_back(-0.1 + 0.001 * k, 0.0, 0.4);
    s.normal.emplace_back(0, 0, -1);
    s.bisector.emplace_back(0, 0, -1);
    s.in_view.push_back(1);
  }
  t.seams.push_back(s);
  return t;
}

// Tool frame with z = -normal = +z (camera) and x along +x: the identity.
std::vector<gt::ToolPose> line_poses(double x0, double x1, int n, const Eigen::Vector3d& offset,
                                     const Eigen::Quaterniond& q = Eigen::Quaterniond::Identity()) {
  std::vector<gt::ToolPose> poses;
  for (int k = 0; k < n; ++k) {
    gt::ToolPose p;
    p.position = Eigen::Vector3d(x0 + (x1 - x0) * k / (n - 1), 0.0, 0.4) + offset;
    p.orientation = q;
    poses.push_back(p);
  }
  return poses;
}

// A run output in `out` that detects exactly the truth of `scan` (annotated.pcd) and follows its
// first seam's root line (trajectory.csv, every 10th vertex; from its end when `backwards`), tool
// z = -normal and x along the travel.
void write_run(const gt::SynthScan& scan, const std::filesystem::path& out, bool backwards) {
  gt::Normals normals;
  normals.resize(scan.cloud.size());
  std::fill(normals.z.begin(), normals.z.end(), -1.0f);
  const std::vector<float> descriptor(scan.cloud.size(), 1.0f);
  gt::write_file_atomic(
      (out / "annotated.pcd").string(),
      gt::annotated_pcd_bytes(scan.cloud, {&normals, &descriptor, &scan.truth.label}));
  const gt::Seam& seam = scan.truth.seams[0];
  std::ofstream csv(out / "trajectory.csv");
  csv << "idx,x_m,y_m,z_m,qx,qy,qz,qw,rx,ry,rz\n";
  csv.precision(17);
  const Eigen::Vector3d x =
      (seam.root.back() - seam.root.front()).normalized() * (backwards ? -1 : 1);
  for (std::size_t j = 0; j < seam.root.size(); j += 10) {
    const std::size_t k = backwards ? seam.root.size() - 1 - j : j;
    const Eigen::Vector3d z = -seam.normal[k];
    Eigen::Matrix3d R;
    R.col(0) = (x - x.dot(z) * z).normalized();
    R.col(2) = z;
    R.col(1) = z.cross(R.col(0));
    const Eigen::Quaterniond q(R);
    const Eigen::Vector3d& r = seam.root[k];
    csv << j / 10 << "," << r.x() << "," << r.y() << "," << r.z() << "," << q.x() << "," << q.y()
        << "," << q.z() << "," << q.w() << ",0,0,0\n";
  }
}

}  // namespace

TEST(Eval, PerfectDetectionIsIoU100) {
  const gt::SynthTruth t = hand_truth();
  const gt::EvalMetrics m = gt::evaluate(t, t.label, line_poses(-0.1, 0.1, 50, {0, 0, 0}));
  EXPECT_DOUBLE_EQ(m.iou_percent, 100.0);
  EXPECT_DOUBLE_EQ(m.precision_percent, 100.0);
  EXPECT_DOUBLE_EQ(m.recall_percent, 100.0);
  EXPECT_EQ(m.truth_points, 40u);
  EXPECT_EQ(m.valid_points, 200u);
  EXPECT_NEAR(m.distance_mean, 0.0, 1e-12);
  EXPECT_NEAR(m.distance_max, 0.0, 1e-12);
  EXPECT_NEAR(m.tool_axis_max_deg, 0.0, 1e-9);
  EXPECT_NEAR(m.travel_axis_max_deg, 0.0, 1e-9);
  EXPECT_NEAR(m.coverage_percent, 100.0, 1e-9);
  EXPECT_NEAR(m.seam_length_in_view, 0.2, 1e-12);
}

TEST(Eval, PartialDetections) {
  gt::SynthTruth t = hand_truth();
  std::vector<std::uint8_t> half(200, 0);
  for (int i = 80; i < 100; ++i) half[i] = 1;  // 20 of the 40
  gt::EvalMetrics m = gt::evaluate(t, half, {});
  EXPECT_NEAR(m.iou_percent, 50.0, 1e-12);  // 20 / (20 + 40 - 20)
  EXPECT_NEAR(m.precision_percent, 100.0, 1e-12);
  EXPECT_NEAR(m.recall_percent, 50.0, 1e-12);
  // 20 right and 20 wrong: 20 / (40 + 40 - 20).
  for (int i = 0; i < 20; ++i) half[i] = 1;
  m = gt::evaluate(t, half, {});
  EXPECT_NEAR(m.iou_percent, 100.0 / 3.0, 1e-12);
  // Points without a return do not count, detected or not.
  for (int i = 0; i < 20; ++i) t.valid[i] = 0;
  for (int i = 100; i < 110; ++i) t.valid[i] = 0;
  m = gt::evaluate(t, half, {});
  EXPECT_EQ(m.valid_points, 170u);
  EXPECT_EQ(m.truth_points, 30u);
  EXPECT_NEAR(m.iou_percent, 20.0 / 30.0 * 100.0, 1e-12);
  // No groove anywhere: undefined, not 0 or 100.
  const std::vector<std::uint8_t> none(200, 0);
  t.label.assign(200, 0);
  EXPECT_TRUE(std::isnan(gt::evaluate(t, none, {}).iou_percent));
  EXPECT_THROW(gt::evaluate(t, std::vector<std::uint8_t>(199, 0), {}), gt::InputError);
}

TEST(Eval, LateralOffsetIsLateralError) {
  const gt::SynthTruth t = hand_truth();
  const gt::EvalMetrics m = gt::evaluate(t, t.label, line_poses(-0.09, 0.09, 37, {0, 0.001, 0}));
  EXPECT_NEAR(m.lateral_mean, 0.001, 1e-6);
  EXPECT_NEAR(m.lateral_max, 0.001, 1e-6);
  EXPECT_NEAR(m.depth_mean, 0.0, 1e-12);
  EXPECT_NEAR(m.depth_max, 0.0, 1e-12);
  EXPECT_NEAR(m.distance_mean, 0.001, 1e-6);
  EXPECT_EQ(m.waypoints, 37u);
}

// Two true seams 40 mm apart and two exported paths, one 1 mm beside each: every path is
// scored against every seam on its own, so the pairs that match show it and the others do not.
TEST(Eval, EveryExportedSeamAgainstEveryTrueOne) {
  gt::SynthTruth t = hand_truth();
  gt::Seam second = t.seams[0];
  for (auto& p : second.root) p.y() = 0.04;
  t.seams.push_back(second);
  const auto scores =
      gt::score_seams(t, {{"trajectory.csv", line_poses(-0.1, 0.1, 41, {0, 0.041, 0})},
                          {"trajectory_1.csv", line_poses(-0.1, 0.1, 41, {0, 0.001, 0})}});
  ASSERT_EQ(scores.size(), 4u);
  const double lateral[2][2] = {{0.041, 0.001}, {0.001, 0.039}};  // [file][truth seam]
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& s = scores[k];
    EXPECT_EQ(s.file, k < 2 ? "trajectory.csv" : "trajectory_1.csv");
    EXPECT_EQ(s.truth_seam, k % 2);
    EXPECT_EQ(s.waypoints, 41u);
    EXPECT_NEAR(s.lateral_mean, lateral[k / 2][k % 2], 1e-6) << k;
    // Within the 6 mm coverage radius only where the path runs 1 mm beside the seam.
    EXPECT_NEAR(s.coverage_percent, lateral[k / 2][k % 2] < 0.002 ? 100.0 : 0.0, 1e-9) << k;
  }
  const std::string text = gt::metrics_summary([&] {
    gt::EvalMetrics m = gt::evaluate(t, t.label, {});
    m.seam_scores = scores;
    return m;
  }());
  EXPECT_NE(text.find("trajectory_1.csv against true seam 0: lateral 1.00 mm"), std::string::npos)
      << text;
}

// Tacks placed on a path that runs against the root's direction (arc lengths from the path's
// start, x = 0.1 - s), scored along the root: nearest pairs first, each tack used once.
TEST(Eval, TacksMatchAlongTheRoot) {
  gt::SynthTruth t = hand_truth();
  const auto tack = [](double s, double length) {
    gt::Tack k;
    k.position = s;
    k.centre = {-0.1 + s, 0, 0.4};
    k.length = length;
    return k;
  };
  t.seams[0].tacks = {tack(0.05, 0.010), tack(0.15, 0.012), tack(0.18, 0.008)};
  const std::vector<gt::ReportedTack> reported = {
      {0.151, 0.008},  // x -0.051: the first tack, 1 mm off, 2 mm short
      {0.148, 0.010},  // x -0.048: 2 mm off the same tack, which the nearer one took
      {0.050, 0.012},  // x 0.05: the second tack exactly
      {0.190, 0.006},  // x -0.09: no tack there
  };
  const gt::TackScore s = gt::score_tacks(t, line_poses(0.1, -0.1, 41, {0, 0, 0}), reported);
  EXPECT_EQ(s.expected, 3u);
  EXPECT_EQ(s.found, 2u);
  EXPECT_EQ(s.extra, 2u);
  EXPECT_NEAR(s.position_mean, 0.0005, 1e-9);
  EXPECT_NEAR(s.position_max, 0.001, 1e-9);
  EXPECT_NEAR(s.length_bias, -0.001, 1e-9);
  // A path 7 mm beside the seam (beyond the 6 mm coverage radius) places no tack on it.
  const gt::TackScore off = gt::score_tacks(t, line_poses(0.1, -0.1, 41, {0, 0.007, 0}), reported);
  EXPECT_EQ(off.found, 0u);
  EXPECT_EQ(off.extra, 4u);
  EXPECT_TRUE(std::isnan(off.position_mean));
}

TEST(Eval, DepthOffsetIsDepthError) {
  const gt::SynthTruth t = hand_truth();
  // 1 mm towards the camera (-z): above the root, positive along the outward normal.
  const gt::EvalMetrics m = gt::evaluate(t, t.label, line_poses(-0.09, 0.09, 10, {0, 0, -0.001}));
  EXPECT_NEAR(m.depth_mean, 0.001, 1e-9);
  EXPECT_NEAR(m.depth_bias, 0.001, 1e-9);
  EXPECT_NEAR(m.lateral_max, 0.0, 1e-12);
  // And below it.
  const gt::EvalMetrics b = gt::evaluate(t, t.label, line_poses(-0.09, 0.09, 10, {0, 0, 0.002}));
  EXPECT_NEAR(b.depth_bias, -0.002, 1e-9);
  EXPECT_NEAR(b.depth_max, 0.002, 1e-9);
}

TEST(Eval, AxisErrors) {
  const gt::SynthTruth t = hand_truth();
  // Torch tilted 10 deg about the travel axis.
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(10.0 * kPi / 180.0, Eigen::Vector3d::UnitX()));
  gt::EvalMetrics m = gt::evaluate(t, t.label, line_poses(-0.1, 0.1, 20, {0, 0, 0}, tilt));
  EXPECT_NEAR(m.tool_axis_mean_deg, 10.0, 1e-9);
  EXPECT_NEAR(m.travel_axis_max_deg, 0.0, 1e-9);
  // Tool yawed 5 deg about its own z: the travel axis is 5 deg off, the torch axis is not.
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(5.0 * kPi / 180.0, Eigen::Vector3d::UnitZ()));
  m = gt::evaluate(t, t.label, line_poses(-0.1, 0.1, 20, {0, 0, 0}, yaw));
  EXPECT_NEAR(m.travel_axis_mean_deg, 5.0, 1e-9);
  EXPECT_NEAR(m.tool_axis_max_deg, 0.0, 1e-9);
  // Travelling towards -x with the tool x still along +x: 180 deg off.
  m = gt::evaluate(t, t.label, line_poses(0.1, -0.1, 20, {0, 0, 0}));
  EXPECT_NEAR(m.travel_axis_mean_deg, 180.0, 1e-9);
}

TEST(Eval, CoverageOfHalfATrajectory) {
  const gt::SynthTruth t = hand_truth();
  // Waypoints over x in [-0.1, 0]: the root is covered up to 6 mm beyond the last one.
  const gt::EvalMetrics m = gt::evaluate(t, t.label, line_poses(-0.1, 0.0, 26, {0, 0, 0}));
  EXPECT_NEAR(m.coverage_percent, (0.1 + 0.006) / 0.2 * 100.0, 0.3);
  // 7 mm to the side: nothing within 6 mm.
  EXPECT_NEAR(gt::evaluate(t, t.label, line_poses(-0.1, 0.1, 26, {0, 0.007, 0})).coverage_percent,
              0.0, 1e-12);
  // Out-of-view root does not count: hide the second half.
  gt::SynthTruth h = t;
  for (std::size_t k = 101; k < h.seams[0].in_view.size(); ++k) h.seams[0].in_view[k] = 0;
  EXPECT_NEAR(gt::evaluate(h, h.label, line_poses(-0.1, 0.0, 26, {0, 0, 0})).coverage_percent,
              100.0, 1e-9);
  // No trajectory: nothing covered, trajectory errors undefined.
  const gt::EvalMetrics none = gt::evaluate(t, t.label, {});
  EXPECT_DOUBLE_EQ(none.coverage_percent, 0.0);
  EXPECT_TRUE(std::isnan(none.distance_mean));
}

TEST(Eval, ReadsARunDirectory) {
  // A small real scan, a hand-written run output that detects exactly the truth and follows
  // the root line, and the files eval reads.
  gt::SynthParams p;
  p.shape = gt::Shape::kStraight;
  p.width = 160;
  p.height = 120;
  p.noise = false;
  const gt::SynthScan scan = gt::render(p);
  const auto dir =
      std::filesystem::temp_directory_path() / ("gt-eval-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "out");
  const std::string scan_path = (dir / "scan.pcd").string();
  gt::write_synth_scan(scan, scan_path);

  write_run(scan, dir / "out", false);
  std::ofstream(dir / "out" / "report.json")
      << R"({"timings_ms": {"features": 10.5, "total": 25.0}})";

  const gt::EvalMetrics m = gt::evaluate_files(scan_path, (dir / "out").string());
  EXPECT_DOUBLE_EQ(m.iou_percent, 100.0);
  EXPECT_LT(m.distance_max, 1e-9);
  EXPECT_LT(m.tool_axis_max_deg, 1e-6);
  EXPECT_LT(m.travel_axis_max_deg, 1e-6);
  EXPECT_GT(m.coverage_percent, 99.9);
  EXPECT_DOUBLE_EQ(m.runtime_ms, 25.0);
  EXPECT_NEAR(m.points_per_second, 160.0 * 120.0 / 0.025, 1e-6);
  ASSERT_EQ(m.stage_ms.size(), 1u);
  EXPECT_EQ(m.stage_ms[0].first, "features");
  EXPECT_TRUE(m.notes.empty());

  const std::string json = gt::metrics_json(m, scan_path, (dir / "out").string());
  EXPECT_NE(json.find("\"iou_percent\": 100.0"), std::string::npos) << json;
  EXPECT_NE(gt::metrics_summary(m).find("IoU 100.00 %"), std::string::npos);

  // A base-frame trajectory is flagged; a missing annotated.pcd is an input error.
  std::ofstream(dir / "out" / "trajectory.json") << R"({"frame": "base"})";
  EXPECT_FALSE(gt::evaluate_files(scan_path, (dir / "out").string()).notes.empty());
  EXPECT_THROW(gt::evaluate_files(scan_path, (dir / "nowhere").string()), gt::InputError);
  std::filesystem::remove_all(dir);
}

// The joint a run reports for its first exported seam (report.json robust.seams, the entry
// whose file is trajectory.csv) against the truth's.
TEST(Eval, JointFromTheReport) {
  gt::SynthParams p;
  p.joint = gt::JointType::kBevel;
  p.groove_angle_deg = 45.0;
  p.width = 160;
  p.height = 120;
  p.noise = false;
  const gt::SynthScan scan = gt::render(p);
  const auto dir =
      std::filesystem::temp_directory_path() / ("gt-evaljoint-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "out");
  const std::string scan_path = (dir / "scan.pcd").string();
  gt::write_synth_scan(scan, scan_path);
  {
    gt::Normals normals;
    normals.resize(scan.cloud.size());
    const std::vector<float> descriptor(scan.cloud.size(), 1.0f);
    gt::write_file_atomic(
        (dir / "out" / "annotated.pcd").string(),
        gt::annotated_pcd_bytes(scan.cloud, {&normals, &descriptor, &scan.truth.label}));
  }
  const auto metrics = [&](const std::string& report) {
    std::ofstream(dir / "out" / "report.json") << report;
    const gt::EvalMetrics m = gt::evaluate_files(scan_path, (dir / "out").string());
    return std::make_pair(m, nlohmann::json::parse(gt::metrics_json(m, scan_path, "out")));
  };
  // The second seam is the first exported one; the other's joint is not taken.
  auto [m, j] = metrics(R"({"robust": {"seams": [{"file": "trajectory_2.csv", "joint": "V"},
                                                 {"file": "trajectory.csv", "joint": "bevel"}]}})");
  EXPECT_EQ(m.joint_expected, "bevel");
  EXPECT_EQ(m.joint_found, "bevel");
  EXPECT_EQ(j.at("joint_expected"), "bevel");
  EXPECT_EQ(j.at("joint_found"), "bevel");
  EXPECT_EQ(j.at("joint_match"), true);
  EXPECT_NE(gt::metrics_summary(m).find("joint: expected bevel, found bevel (match)"),
            std::string::npos);
  std::tie(m, j) =
      metrics(R"({"robust": {"seams": [{"file": "trajectory.csv", "joint": "fillet"}]}})");
  EXPECT_EQ(j.at("joint_found"), "fillet");
  EXPECT_EQ(j.at("joint_match"), false);
  // No joint reported (older runs): null, not a mismatch.
  for (const char* report : {R"({"robust": {"seams": [{"file": "trajectory.csv"}]}})",
                             R"({"timings_ms": {"total": 3.0}})", "not json"}) {
    std::tie(m, j) = metrics(report);
    EXPECT_EQ(j.at("joint_expected"), "bevel") << report;
    EXPECT_TRUE(j.at("joint_found").is_null()) << report;
    EXPECT_TRUE(j.at("joint_match").is_null()) << report;
  }
  std::filesystem::remove_all(dir);
}

// The tacks a run reports for trajectory.csv's seam (report.json), scored against the
// renderer's; the path runs from the root's far end, so positions count from there.
TEST(Eval, TacksFromTheReport) {
  gt::SynthParams p;
  p.tacks = 2;
  p.width = 160;
  p.height = 120;
  p.noise = false;
  const gt::SynthScan scan = gt::render(p);
  const auto dir =
      std::filesystem::temp_directory_path() / ("gt-evaltacks-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "out");
  const std::string scan_path = (dir / "scan.pcd").string();
  gt::write_synth_scan(scan, scan_path);
  write_run(scan, dir / "out", true);
  const gt::Seam& seam = scan.truth.seams[0];
  ASSERT_EQ(seam.tacks.size(), 2u);
  const double length = seam.length();
  nlohmann::json tacks = nlohmann::json::array();
  for (const gt::Tack& t : seam.tacks)  // 1 mm further along the path, 1 mm longer
    tacks.push_back({{"position_m", length - t.position + 0.001}, {"length_m", t.length + 0.001}});
  const nlohmann::json report = {
      {"robust",
       {{"seams",
         {{{"file", "trajectory_1.csv"}, {"tacks", nlohmann::json::array()}},
          {{"file", "trajectory.csv"}, {"joint", "V"}, {"tacks", tacks}}}}}}};
  std::ofstream(dir / "out" / "report.json") << report.dump();
  gt::EvalMetrics m = gt::evaluate_files(scan_path, (dir / "out").string());
  EXPECT_TRUE(m.tacks.reported);
  EXPECT_EQ(m.tacks.expected, 2u);
  EXPECT_EQ(m.tacks.found, 2u);
  EXPECT_EQ(m.tacks.extra, 0u);
  EXPECT_NEAR(m.tacks.position_mean, 0.001, 1e-6);
  EXPECT_NEAR(m.tacks.length_bias, 0.001, 1e-9);
  nlohmann::json j = nlohmann::json::parse(gt::metrics_json(m, scan_path, "out"));
  EXPECT_EQ(j.at("tacks").at("found"), 2);
  EXPECT_NEAR(j.at("tacks").at("position_error_max_m").get<double>(), 0.001, 1e-6);
  EXPECT_NE(gt::metrics_summary(m).find("tacks: 2 of 2 found, 0 extra"), std::string::npos)
      << gt::metrics_summary(m);
  // A report without tacks (another method, an older run): expected, not reported.
  std::ofstream(dir / "out" / "report.json")
      << R"({"robust": {"seams": [{"file": "trajectory.csv"}]}})";
  m = gt::evaluate_files(scan_path, (dir / "out").string());
  j = nlohmann::json::parse(gt::metrics_json(m, scan_path, "out"));
  EXPECT_FALSE(m.tacks.reported);
  EXPECT_EQ(j.at("tacks"), nlohmann::json({{"expected", 2}, {"reported", false}}));
  EXPECT_NE(gt::metrics_summary(m).find("tacks: 2 expected, none reported"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(Eval, MalformedAnnotatedPcdIsAnInputError) {
  // annotated.pcd goes through the scan reader's checks: what eval used to read as zeros or
  // guess around (words in ascii data, no POINTS, a shape that is not POINTS) is rejected,
  // with the file and the reason on one line.
  gt::SynthParams p;
  p.width = 64;
  p.height = 48;
  p.noise = false;
  const auto dir =
      std::filesystem::temp_directory_path() / ("gt-evalbad-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "out");
  const std::string scan_path = (dir / "scan.pcd").string();
  gt::write_synth_scan(gt::render(p), scan_path);
  const std::string head = "VERSION 0.7\nFIELDS x y z groove\nSIZE 4 4 4 1\nTYPE F F F U\n";
  std::string rows;
  for (int i = 0; i < 64 * 48; ++i) rows += i == 100 ? "0 0 0.4 yes\n" : "0 0 0.4 0\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {head + "WIDTH 64\nHEIGHT 48\nPOINTS 3072\nDATA ascii\n" + rows, "'yes' is not a number"},
      {head + "WIDTH 64\nHEIGHT 48\nDATA ascii\n" + rows, "no POINTS line"},
      {head + "WIDTH 64\nHEIGHT 47\nPOINTS 3072\nDATA ascii\n" + rows,
       "WIDTH x HEIGHT (64 x 47) is not POINTS (3072)"},
      {"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
       "has no groove field (fields: x y z)"},
  };
  for (const auto& [text, reason] : cases) {
    std::ofstream(dir / "out" / "annotated.pcd", std::ios::binary) << text;
    try {
      gt::evaluate_files(scan_path, (dir / "out").string());
      ADD_FAILURE() << "accepted; expected '" << reason << "'";
    } catch (const gt::InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("eval: ", 0), 0u) << msg;
      EXPECT_NE(msg.find("annotated.pcd"), std::string::npos) << msg;
      EXPECT_NE(msg.find(reason), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
  std::filesystem::remove_all(dir);
}

#ifdef GT_CLI_PATH
TEST(EvalCli, WritesMetricsAndFailsOnMissingInput) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("gt-evalcli-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "out");
  const std::string cli = GT_CLI_PATH;
  const auto run = [](const std::string& cmd) {
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  ASSERT_EQ(run(cli + " synth --shape box --resolution 160x120 --noise off -o " +
                (dir / "s.pcd").string() + " > /dev/null"),
            0);
  // A run output that detects nothing and has no trajectory.
  {
    std::ofstream pcd(dir / "out" / "annotated.pcd");
    pcd << "VERSION 0.7\nFIELDS x y z groove\nSIZE 4 4 4 1\nTYPE F F F U\nCOUNT 1 1 1 1\n"
           "WIDTH 160\nHEIGHT 120\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 19200\nDATA ascii\n";
    for (int i = 0; i < 19200; ++i) pcd << "0 0 0.4 0\n";
  }
  EXPECT_EQ(run(cli + " eval --truth " + (dir / "s.pcd").string() + " --result " +
                (dir / "out").string() + " > " + (dir / "summary.txt").string()),
            0);
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "metrics.json"));
  std::ifstream summary(dir / "summary.txt");
  const std::string text((std::istreambuf_iterator<char>(summary)),
                         std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("IoU 0.00 %"), std::string::npos) << text;
  EXPECT_NE(text.find("no trajectory.csv"), std::string::npos) << text;
  // Missing result: exit 3; missing flag: exit 2.
  EXPECT_EQ(run(cli + " eval --truth " + (dir / "s.pcd").string() + " --result " +
                (dir / "none").string() + " 2> /dev/null"),
            3);
  EXPECT_EQ(run(cli + " eval --truth " + (dir / "s.pcd").string() + " 2> /dev/null"), 2);
  std::filesystem::remove_all(dir);
}
#endif
