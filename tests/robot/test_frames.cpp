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
#include <iterator>
#include <optional>
#include <string>
#include <vector>

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
  static std::string test_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
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

// The transform every file in tests/robot/data describes (make_golden.py wrote them with
// numpy's Rodrigues formula, not with groovetrace): 0.7 rad about (1, -2, 2) / 3, then
// (0.031, -0.012, 0.118) m.
Eigen::Isometry3d golden_transform() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 2) / 3).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.031, -0.012, 0.118);
  return T;
}

std::string golden(const std::string& name) {
  return std::string(GT_SOURCE_DIR) + "/tests/robot/data/" + name;
}

TEST_F(FramesTest, EveryFormatReadsTheSameTransform) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"groovetrace.yaml", "groovetrace"},   {"groovetrace.json", "groovetrace"},
      {"easy_handeye.yaml", "easy_handeye"}, {"easy_handeye2.calib", "easy_handeye2"},
      {"opencv.yaml", "opencv_yaml"},        {"opencv.xml", "opencv_xml"},
      {"matrix.txt", "matrix_text"},         {"matrix.json", "matrix_text"},
      {"matrix.yaml", "matrix_list"},        {"ur_pose.txt", "ur_pose"},
      {"ros_pose.yaml", "ros_pose"},         {"quaternion_wxyz.json", "groovetrace"}};
  const Eigen::Isometry3d expected = golden_transform();
  for (const auto& [name, format] : files) {
    const groovetrace::Calibration c = groovetrace::read_calibration(golden(name));
    EXPECT_EQ(c.format, format) << name;
    EXPECT_LT((c.transform.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-9) << name;
    // Exactly rigid, whatever digits the file had.
    EXPECT_LT(
        (c.transform.linear() * c.transform.linear().transpose() - Eigen::Matrix3d::Identity())
            .norm(),
        1e-14)
        << name;
  }
}

TEST_F(FramesTest, TheContentDecidesNotTheExtension) {
  // The same bytes under other names: an OpenCV YAML as .txt, a UR pose as .yaml, a JSON
  // layout as .yml, a matrix without extension.
  const Eigen::Isometry3d expected = golden_transform();
  for (const auto& [from, to] :
       std::vector<std::pair<std::string, std::string>>{{"opencv.yaml", "calib.txt"},
                                                        {"ur_pose.txt", "pose.yaml"},
                                                        {"groovetrace.json", "hand_eye.yml"},
                                                        {"matrix.txt", "T_flange_camera"},
                                                        {"opencv.xml", "result.yaml"}}) {
    const std::string path = write(to, test_text(golden(from)));
    EXPECT_LT((read_transform(path).matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-9)
        << from << " as " << to;
  }
}

TEST_F(FramesTest, HandEyeFilesSayTheirFrames) {
  const groovetrace::Calibration ros1 = groovetrace::read_calibration(golden("easy_handeye.yaml"));
  ASSERT_TRUE(ros1.eye_on_hand.has_value());
  EXPECT_TRUE(*ros1.eye_on_hand);
  EXPECT_EQ(ros1.parent_frame, "tool0");
  EXPECT_EQ(ros1.child_frame, "camera_color_optical_frame");
  const groovetrace::Calibration ros2 =
      groovetrace::read_calibration(golden("easy_handeye2.calib"));
  EXPECT_EQ(ros2.eye_on_hand, std::optional<bool>(true));
  EXPECT_EQ(ros2.parent_frame, "tool0");
  EXPECT_EQ(ros2.child_frame, "camera_link");
  // Eye-on-base (older easy_handeye: the parameters at the top): T_base_camera.
  const groovetrace::Calibration base = groovetrace::read_calibration(
      write("eob.yaml",
            "eye_on_hand: false\nrobot_base_frame: base_link\nrobot_effector_frame: tool0\n"
            "tracking_base_frame: cam\ntransformation: {x: 1, y: 0, z: 0.5, qx: 0, qy: 0, qz: 0, "
            "qw: 1}\n"));
  EXPECT_EQ(base.eye_on_hand, std::optional<bool>(false));
  EXPECT_EQ(base.parent_frame, "base_link");
  EXPECT_LT((base.transform.translation() - Eigen::Vector3d(1, 0, 0.5)).norm(), 1e-15);
}

TEST_F(FramesTest, AQuaternionWithoutItsOrderIsRefused) {
  // 0.1, 0.2, 0.3, 0.927 read as x, y, z, w or as w, x, y, z: two different rotations.
  const std::string q = "[0.1, 0.2, 0.3, 0.9273618495495703]";
  expect_error(write("q.yaml", "translation: [0, 0, 0]\nquaternion: " + q + "\n"),
               "'quaternion' is a quaternion of 4 numbers that does not say its order");
  expect_error(write("pose.yaml", "position: [0, 0, 0]\norientation: " + q + "\n"),
               "name the fields (x, y, z, w) or the key (orientation_xyzw or orientation_wxyz)");
  expect_error(write("tf.json", R"({"transform": {"translation": {"x": 0, "y": 0, "z": 0},)"
                                R"( "rotation": )" +
                                    q + "}}"),
               "does not say its order");
  // Named fields and an order in the key are read by them; so is groovetrace's own
  // `rotation` list (x, y, z, w, documented), and 4 equal numbers (both readings agree).
  const Eigen::Quaterniond xyzw(0.9273618495495703, 0.1, 0.2, 0.3);
  const auto angle_to = [&](const std::string& path, const Eigen::Quaterniond& q) {
    return Eigen::Quaterniond(read_transform(path).linear()).angularDistance(q);
  };
  EXPECT_LT(angle_to(write("named.yaml",
                           "position: [0, 0, 0]\norientation: {w: 0.9273618495495703, "
                           "x: 0.1, y: 0.2, z: 0.3}\n"),
                     xyzw),
            1e-12);
  EXPECT_LT(angle_to(write("prefixed.yaml",
                           "translation: [0, 0, 0]\nrotation: {qx: 0.1, qy: 0.2, "
                           "qz: 0.3, qw: 0.9273618495495703}\n"),
                     xyzw),
            1e-12);
  EXPECT_LT(
      angle_to(write("keyed.yaml", "translation: [0, 0, 0]\nquaternion_xyzw: " + q + "\n"), xyzw),
      1e-12);
  EXPECT_LT(angle_to(write("own.yaml", "translation: [0, 0, 0]\nrotation: " + q + "\n"), xyzw),
            1e-12);
  EXPECT_LT(
      angle_to(write("equal.yaml", "translation: [0, 0, 0]\nquaternion: [0.5, 0.5, 0.5, 0.5]\n"),
               Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5)),
      1e-12);
  expect_error(write("half.yaml", "translation: [0, 0, 0]\nrotation: {x: 0, y: 0, z: 1}\n"),
               "'rotation' has no 'w'");
}

TEST_F(FramesTest, BadHandEyeAndOpenCvFilesAreRefused) {
  expect_error(write("eih.yaml", "transformation: {x: 0, y: 0, z: 0, qx: 0, qy: 0, qz: 0}\n"),
               "'transformation' has no 'qw'");
  expect_error(write("eih2.yaml",
                     "eye_on_hand: maybe\ntransformation: {x: 0, y: 0, z: 0, qx: 0, "
                     "qy: 0, qz: 0, qw: 1}\n"),
               "eye_on_hand is 'maybe', expected true or false");
  expect_error(write("eih3.calib",
                     "parameters: {calibration_type: eye_on_table}\ntransform:\n"
                     "  translation: {x: 0, y: 0, z: 0}\n"
                     "  rotation: {x: 0, y: 0, z: 0, w: 1}\n"),
               "calibration_type is 'eye_on_table'");
  const std::string head = "%YAML:1.0\n---\n";
  const auto mat = [](const std::string& name, int rows, int cols, const std::string& data) {
    return name + ": !!opencv-matrix\n   rows: " + std::to_string(rows) +
           "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + data + " ]\n";
  };
  const std::string t = mat("t", 3, 1, "0., 0., 0.1");
  expect_error(write("skew.yaml", head + mat("R", 3, 3, "1., 0.1, 0., 0., 1., 0., 0., 0., 1.") + t),
               "R is not a rotation: R^T R differs from the identity by 0.1");
  expect_error(
      write("mirror.yaml", head + mat("R", 3, 3, "1., 0., 0., 0., 1., 0., 0., 0., -1.") + t),
      "R is a reflection");
  expect_error(write("count.yaml", head + mat("R", 3, 3, "1., 0., 0., 0., 1., 0., 0., 0.") + t),
               "R.data has 8 values, expected 9 (3x3)");
  expect_error(write("alone.yaml", head + mat("R_cam2gripper", 3, 3, "1,0,0,0,1,0,0,0,1")),
               "holds no R/t pair");
  expect_error(write("pairs.yaml", head + mat("R", 3, 3, "1,0,0,0,1,0,0,0,1") + t +
                                       mat("R_cam2base", 3, 3, "1,0,0,0,1,0,0,0,1") +
                                       mat("t_cam2base", 3, 1, "0,0,0")),
               "more than one R/t pair");
  expect_error(write("nan.yaml", head + mat("R", 3, 3, "1,0,0,0,1,0,0,0,.nan") + t),
               "R.data[8] is not finite");
  const std::string xml_r =
      "<R type_id=\"opencv-matrix\"><rows>3</rows><cols>3</cols><dt>d</dt>"
      "<data>1 0 0 0 1 0 0 0 1</data></R>";
  const std::string xml_t =
      "<t type_id=\"opencv-matrix\"><rows>3</rows><cols>1</cols><dt>d</dt>"
      "<data>0 0 0.1</data></t>";
  EXPECT_LT(
      (read_transform(write("ok.xml", "<opencv_storage>" + xml_r + xml_t + "</opencv_storage>"))
           .translation() -
       Eigen::Vector3d(0, 0, 0.1))
          .norm(),
      1e-15);
  expect_error(write("open.xml", "<opencv_storage>" + xml_r + xml_t), "is not closed");
  expect_error(write("root.xml", "<?xml version=\"1.0\"?>\n<storage>" + xml_r + "</storage>"),
               "root element is 'storage', expected 'opencv_storage'");
  expect_error(
      write("mixed.xml", "<opencv_storage>" + xml_r + "words" + xml_t + "</opencv_storage>"),
      "mixes text and elements");
  expect_error(write("tag.xml", "<opencv_storage>" + xml_r + xml_t + "</opencv>"),
               "closing tag does not match 'opencv_storage'");
  expect_error(write("dtd.xml", "<!DOCTYPE x [ <!ENTITY a \"b\"> ]><opencv_storage/>"),
               "DTD or CDATA is not supported");
  expect_error(write("word.xml",
                     "<opencv_storage><R type_id=\"opencv-matrix\"><rows>3</rows>"
                     "<cols>3</cols><dt>d</dt><data>1 0 0 0 one 0 0 0 1</data></R>"
                     "</opencv_storage>"),
               "R.data holds 'one', not a number");
}

TEST_F(FramesTest, BadMatricesAndUrPosesAreRefused) {
  expect_error(write("15.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0\n"),
               "holds 15 numbers; a plain 4x4 matrix has 16");
  expect_error(write("row.txt", "1 0 0 0.1\n0 1 0 0\n0 0 1 0\n0.1 0 0 1\n"),
               "the matrix's last row is 0.1 0 0 1, expected 0 0 0 1");
  expect_error(write("scaled.txt", "2 0 0 0\n0 2 0 0\n0 0 2 0\n0 0 0 1\n"),
               "the matrix's rotation is not a rotation: R^T R differs from the identity by 3");
  expect_error(write("nan.txt", "1 0 0 nan\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"),
               "matrix value 4 is not finite");
  expect_error(write("rows.yaml", "- [1, 0, 0, 0]\n- [0, 1, 0]\n- [0, 0, 1, 0]\n- [0, 0, 0, 1]\n"),
               "field 'matrix[1]' has 3 values, expected 4");
  expect_error(write("six.txt", "0.1, 0.2, 0.3, 0, 0, 1\n"),
               "holds 6 numbers: a UR pose is written p[x, y, z, rx, ry, rz]");
  expect_error(write("five.txt", "p[0.1, 0.2, 0.3, 0, 0]\n"),
               "UR pose p[...] has 5 numbers, expected 6");
  expect_error(write("open.txt", "p[0.1, 0.2, 0.3, 0, 0, 1\n"), "has no closing ']'");
  expect_error(write("after.txt", "p[0.1, 0.2, 0.3, 0, 0, 1] p[0, 0, 0, 0, 0, 0]\n"),
               "text after the UR pose");
  expect_error(write("word.txt", "p[0.1, 0.2, zero, 0, 0, 1]\n"), "must hold numbers");
  expect_error(write("inf.txt", "p[0.1, 0.2, inf, 0, 0, 1]\n"), "UR pose value 3 is not finite");
  // Too large for a double: refused, not read as 0 (from_chars leaves it unset).
  expect_error(write("over.txt", "1 0 0 1e999\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"),
               "matrix value 4 is not finite");
  expect_error(write("long.txt", "p[0, 0, 0, 1e308, 1e308, 1e308]\n"),
               "the rotation vector's length is not finite");
  // A half turn and a rotation vector longer than pi are still the rotations they say.
  const Eigen::Isometry3d T =
      read_transform(write("ok.txt", "# flange\np [0.4, -0.1, 0.3, 0, 3.1415926535897931, 0]\n"));
  EXPECT_LT((T.linear() - Eigen::Matrix3d(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitY()))).norm(),
            1e-12);
  EXPECT_LT((T.translation() - Eigen::Vector3d(0.4, -0.1, 0.3)).norm(), 1e-15);
}

TEST_F(FramesTest, BadFilesAreInputErrorsNamingTheProblem) {
  const std::string ok_rotation = "rotation: [0, 0, 0, 1]\n";
  expect_error((dir_ / "missing.yaml").string(), "cannot read");
  expect_error((dir_ / "calibration").string(), "cannot read");
  fs::create_directories(dir_ / "adir.yaml");
  expect_error((dir_ / "adir.yaml").string(), "directory");
  expect_error(write("syntax.yaml", "translation: [0, 0\nrotation: {\n"), "YAML parse error");
  expect_error(write("syntax.json", "{\"translation\": [0, 0, 0], }"), "JSON parse error");
  expect_error(write("empty.yaml", ""), "empty");
  expect_error(write("blank.txt", " \n\t\n"), "empty");
  expect_error(write("scalar_root.yaml", "42\n"), "holds 1 number; a plain 4x4 matrix has 16");
  expect_error(write("word_root.yaml", "hello\n"), "expected a mapping");
  expect_error(write("list.json", "[1, 2, 3]"), "holds 3 numbers");
  expect_error(write("no_t.yaml", ok_rotation), "missing field 'translation'");
  expect_error(write("no_r.json", R"({"translation": [0, 0, 0]})"), "missing field 'rotation'");
  expect_error(write("nothing.yaml", "a: 1\nb: [2]\n"), "holds no transform in a layout");
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
  expect_error(write("far.yaml", "translation: [0, 2000, 0]\n" + ok_rotation),
               "translation[1] is 2000 m, beyond the 1000 m");
  expect_error(write("scaled.yaml", "translation: [0, 0, 0]\nrotation: [0, 0, 0, 1.2]\n"),
               "rotation quaternion is not unit (norm 1.2)");
  expect_error(write("zero.json", R"({"translation": [0, 0, 0], "rotation": [0, 0, 0, 0]})"),
               "rotation quaternion is not unit (norm 0)");
  expect_error(write("twice.yaml", "translation: [0, 0, 0]\n" + ok_rotation + ok_rotation),
               "key 'rotation' appears twice");
  expect_error(write("twice.json", R"({"translation": [0, 0, 0], "rotation": [0, 0, 0, 1],)"
                                   R"( "translation": [1, 0, 0]})"),
               "key 'translation' appears twice");
  expect_error(write("rotvec.yaml", "translation: [0, 0, 0]\nrotation: [0, 0, 1]\n"),
               "rotation vector or Euler angles are not accepted");
  expect_error(write("two_rotations.yaml",
                     "translation: [0, 0, 0]\n" + ok_rotation + "quaternion_wxyz: [1, 0, 0, 0]\n"),
               "both 'rotation' and 'quaternion_wxyz'");
  expect_error(write("extra_field.yaml", "translation: {x: 0, y: 0, z: 0, w: 1}\n" + ok_rotation),
               "'translation' has an unexpected key 'w'");
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
