// Calibration files (good and bad) and moving a trajectory into the robot base frame,
// checked against transforms computed by hand.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>
#include <groovetrace/frames.hpp>
#include <groovetrace/rotation.hpp>
#include <string>

namespace {

namespace fs = std::filesystem;
using groovetrace::read_transform;

constexpr double kPi = 3.14159265358979323846;

groovetrace::Waypoint waypoint(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  groovetrace::Waypoint w;
  w.position = p;
  w.orientation = q;
  w.rotation_vector.setZero();  // Eigen members are not initialized by Waypoint
  w.euler_zyx_deg.setZero();
  return w;
}

/// A scratch directory per test, removed afterwards.
class FramesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("gt_frames_" + std::to_string(::getpid()) + "_" + info->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }
  /// The InputError message for `path`, or "" when nothing (or something else) was thrown.
  static std::string input_error(const std::string& path) {
    try {
      read_transform(path);
    } catch (const groovetrace::InputError& e) {
      return e.what();
    } catch (...) {
      return "";
    }
    return "";
  }
  void expect_error(const std::string& path, const std::string& fragment) const {
    const std::string message = input_error(path);
    ASSERT_FALSE(message.empty()) << path << " was accepted";
    EXPECT_NE(message.find(path), std::string::npos) << message;  // names the file
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;  // one line for stderr
  }
  fs::path dir_;
};

TEST_F(FramesTest, ReadsYamlAndJson) {
  // 90 degrees about z: q = (0, 0, sin 45, cos 45).
  const std::string yaml = write("hand_eye.yaml",
                                 "# T_flange_camera\n"
                                 "translation: [0.03, -0.01, 0.12]  # m\n"
                                 "rotation: [0.0, 0.0, 0.7071067811865476, 0.7071067811865476]\n");
  const std::string json = write("flange.json",
                                 R"({"translation": [0.4, -0.2, 0.3],
                                     "rotation": [0, 0, 0.7071067811865476, 0.7071067811865476],
                                     "comment": "extra keys are ignored"})");
  for (const std::string& path : {yaml, json}) {
    const Eigen::Isometry3d T = read_transform(path);
    Eigen::Matrix3d R;
    R << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    EXPECT_LT((T.linear() - R).norm(), 1e-12) << path;
  }
  EXPECT_LT((read_transform(yaml).translation() - Eigen::Vector3d(0.03, -0.01, 0.12)).norm(),
            1e-15);
  EXPECT_LT((read_transform(json).translation() - Eigen::Vector3d(0.4, -0.2, 0.3)).norm(), 1e-15);

  // Block-style YAML, .yml, upper-case extension, integers, and a quaternion slightly off
  // unit (within 1e-3), which is normalized.
  const std::string block = write("pose.YML",
                                  "translation:\n  - 1\n  - 2\n  - 3\n"
                                  "rotation:\n  - 0\n  - 0\n  - 0\n  - 1.0005\n");
  const Eigen::Isometry3d T = read_transform(block);
  EXPECT_LT((T.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-15);
  EXPECT_LT((T.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST_F(FramesTest, BadFilesAreInputErrorsNamingTheProblem) {
  const std::string ok_rotation = "rotation: [0, 0, 0, 1]\n";
  expect_error((dir_ / "missing.yaml").string(), "cannot read");
  expect_error((dir_ / "calibration").string(), "no extension");
  fs::create_directories(dir_ / "adir.yaml");
  expect_error((dir_ / "adir.yaml").string(), "directory");
  expect_error(write("pose.txt", "translation: [0, 0, 0]\n" + ok_rotation), "unknown");
  expect_error(write("syntax.yaml", "translation: [0, 0\nrotation: {\n"), "YAML parse error");
  expect_error(write("syntax.json", "{\"translation\": [0, 0, 0], }"), "JSON parse error");
  expect_error(write("empty.yaml", ""), "empty");
  expect_error(write("scalar_root.yaml", "42\n"), "mapping");
  expect_error(write("list.json", "[1, 2, 3]"), "object");
  expect_error(write("no_t.yaml", ok_rotation), "missing field 'translation'");
  expect_error(write("no_r.json", R"({"translation": [0, 0, 0]})"), "missing field 'rotation'");
  expect_error(write("short.yaml", "translation: [0, 0]\n" + ok_rotation),
               "'translation' has 2 values, expected 3");
  expect_error(write("long.json", R"({"translation": [0, 0, 0], "rotation": [0, 0, 0, 1, 0]})"),
               "'rotation' has 5 values, expected 4");
  expect_error(write("scalar.yaml", "translation: 0.5\n" + ok_rotation), "must be a list");
  expect_error(write("word.yaml", "translation: [0, abc, 0]\n" + ok_rotation),
               "translation[1] is not a number ('abc')");
  expect_error(write("string.json", R"({"translation": [0, "1", 0], "rotation": [0, 0, 0, 1]})"),
               "translation[1] is not a number");
  expect_error(write("bool.json", R"({"translation": [0, 0, true], "rotation": [0, 0, 0, 1]})"),
               "translation[2] is not a number");
  expect_error(write("nested.yaml", "translation: [0, [1], 0]\n" + ok_rotation),
               "translation[1] is not a number");
  expect_error(write("nan.yaml", "translation: [0, 0, .nan]\n" + ok_rotation),
               "translation[2] is not finite");
  expect_error(write("inf.yaml", "translation: [0, 0, 0]\nrotation: [0, 0, -.inf, 1]\n"),
               "rotation[2] is not finite");
  expect_error(write("huge.json", R"({"translation": [1e999, 0, 0], "rotation": [0, 0, 0, 1]})"),
               "");  // overflow: either a parse error or "not finite", never accepted
  expect_error(write("scaled.yaml", "translation: [0, 0, 0]\nrotation: [0, 0, 0, 1.2]\n"),
               "rotation quaternion is not unit (norm 1.2)");
  expect_error(write("zero.json", R"({"translation": [0, 0, 0], "rotation": [0, 0, 0, 0]})"),
               "rotation quaternion is not unit (norm 0)");
}

TEST_F(FramesTest, TransformTrajectoryMatchesHandComputation) {
  // T_base_flange: 90 deg about z, then +(1, 2, 3). T_flange_camera: pure +0.1 m along z.
  const std::string flange = write("flange.yaml",
                                   "translation: [1, 2, 3]\n"
                                   "rotation: [0, 0, 0.7071067811865476, 0.7071067811865476]\n");
  const std::string hand_eye =
      write("hand_eye.json", R"({"translation": [0, 0, 0.1], "rotation": [0, 0, 0, 1]})");
  const Eigen::Isometry3d T_base_camera = read_transform(flange) * read_transform(hand_eye);

  groovetrace::Trajectory t;
  t.direction = Eigen::Vector3d::UnitX();
  t.length = 0.1;
  for (int i = 0; i < 3; ++i) {
    t.waypoints.push_back(
        waypoint(Eigen::Vector3d(0.1 + 0.05 * i, 0.2, 0.3), Eigen::Quaterniond::Identity()));
  }
  groovetrace::fill_rotation_representations(t);
  groovetrace::transform_trajectory(t, T_base_camera);

  // p_flange = p_camera + (0, 0, 0.1); Rz(90) (x, y, z) = (-y, x, z); then + (1, 2, 3):
  // (0.1, 0.2, 0.3) -> (0.1, 0.2, 0.4) -> (-0.2, 0.1, 0.4) -> (0.8, 2.1, 3.4).
  EXPECT_EQ(t.frame, "base");
  for (int i = 0; i < 3; ++i) {
    const auto& w = t.waypoints[static_cast<std::size_t>(i)];
    EXPECT_LT((w.position - Eigen::Vector3d(0.8, 2.1 + 0.05 * i, 3.4)).norm(), 1e-12) << i;
    // The tool frame is now the flange's rotation: 90 deg about base z.
    EXPECT_LT((w.rotation_vector - Eigen::Vector3d(0, 0, kPi / 2)).norm(), 1e-12) << i;
    EXPECT_NEAR(w.euler_zyx_deg[0], 90.0, 1e-9);
    EXPECT_NEAR(w.euler_zyx_deg[1], 0.0, 1e-9);
    EXPECT_NEAR(w.euler_zyx_deg[2], 0.0, 1e-9);
  }
  EXPECT_LT((t.direction - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_EQ(t.length, 0.1);
}

TEST_F(FramesTest, TransformKeepsRotationVectorsContinuous) {
  // Camera tool poses near a half turn; a base frame that adds a rotation must not leave a
  // 2 pi jump between neighbours.
  groovetrace::Trajectory t;
  for (int i = 0; i <= 20; ++i) {
    t.waypoints.push_back(
        waypoint(Eigen::Vector3d(0.01 * i, 0, 0.5),
                 Eigen::Quaterniond(Eigen::AngleAxisd(-0.2 + 0.02 * i, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()))));
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  groovetrace::transform_trajectory(t, T);
  for (std::size_t i = 1; i < t.waypoints.size(); ++i) {
    EXPECT_LT((t.waypoints[i].rotation_vector - t.waypoints[i - 1].rotation_vector).norm(), 0.1);
    const Eigen::Quaterniond q =
        groovetrace::quaternion_from_rotation_vector(t.waypoints[i].rotation_vector);
    EXPECT_LT(q.angularDistance(t.waypoints[i].orientation), 1e-12);
  }
}

}  // namespace
