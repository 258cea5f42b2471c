// Golden files of every program format for the small path of tests/robot/test_urscript.cpp
// (four waypoints along base +x at z = 0.2 m, torch straight down, the last one tilted 10 deg
// about the travel axis; segments 10, 6 and 4 mm).
//
// Checked by hand when created (the values test_urscript.cpp derives for weld_seam.script, in
// each controller's units):
// - approach above (0.4, -0.1, 0.2) m by 0.05 m along -tool z: (400, -100, 250) mm; retreat
//   above the tilted last one: (420, -108.682, 249.240) mm.
// - weld_seam.mod: torch down = a half turn about x, q = [w,x,y,z] = [0,1,0,0]; the last,
//   Rx(190 deg): q = [cos 95, sin 95, 0, 0] = [-0.087156, 0.996195, 0, 0], printed with w >= 0
//   as [0.087155743,-0.996194698,0,0]; speeds 250 and 6 mm/s; zones zGt2000 (2 mm) at waypoint
//   1 and zGt1600 (0.4 * 4 mm) at waypoint 2, fine at the ends; SetDO doArc3; WaitTime 0.4.
// - weld_seam.src/.dat: KUKA tool X = torch (0,0,-1), Y = (0,-1,0), Z = -travel (-1,0,0):
//   R = [[0,0,-1],[0,-1,0],[-1,0,0]] = Rz(180) Ry(90): A 180, B 90, C 0 (gimbal lock: C = 0);
//   the last: X = (0, sin 10, -cos 10), Y = (0, -cos 10, -sin 10), Z = (-1, 0, 0):
//   B = atan2(cos 10, sin 10) = 80, A = atan2(sin 10, 0) = 90, C = atan2(-sin 10, 0) = -90;
//   $VEL.CP 0.25 and 0.006 m/s, $APO.CDIS 2 then 1.6 mm, $OUT[3], WAIT SEC 0.4.
// - weld_seam.ros.yaml: frame_id base, positions in m, quaternions x,y,z,w (1,0,0,0) and
//   (sin 95, 0, 0, cos 95) as Eigen gives them; loads with Python's yaml.safe_load.
// Regenerate only deliberately: GT_UPDATE_GOLDEN=1 rewrites the files and fails the test.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <groovetrace/program.hpp>
#include <groovetrace/trajectory_io.hpp>
#include <sstream>

namespace groovetrace {
namespace {

Trajectory golden_trajectory() {
  auto waypoint = [](const Eigen::Vector3d& p, const Eigen::Vector3d& normal) {
    Waypoint w;
    w.position = p;
    w.orientation = tool_orientation(normal, Eigen::Vector3d::UnitX());
    return w;
  };
  Trajectory t;
  t.frame = "base";
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const double tilt = 10.0 * M_PI / 180.0;
  t.waypoints = {waypoint({0.400, -0.100, 0.200}, up), waypoint({0.410, -0.100, 0.200}, up),
                 waypoint({0.416, -0.100, 0.200}, up),
                 waypoint({0.420, -0.100, 0.200}, {0.0, -std::sin(tilt), std::cos(tilt)})};
  t.direction = Eigen::Vector3d::UnitX();
  t.length = 0.02;
  fill_rotation_representations(t);
  return t;
}

ProgramParams golden_params(Robot robot) {
  ProgramParams p;
  p.robot = robot;
  p.approach_offset = 0.05;
  p.approach_speed = 0.25;
  p.weld_speed = 0.006;
  p.acceleration = 0.8;
  p.blend_radius = 0.002;
  p.arc_output = 3;
  p.arc_delay = 0.4;
  return p;
}

void expect_golden(const std::string& text, const std::string& file) {
  const std::string path = std::string(GT_SOURCE_DIR) + "/tests/support/golden/" + file;
  if (std::getenv("GT_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(path, std::ios::binary) << text;
    FAIL() << "rewrote " << path << "; check it by hand before committing";
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream golden;
  golden << in.rdbuf();
  ASSERT_FALSE(golden.str().empty()) << "missing golden file " << path;
  EXPECT_EQ(text, golden.str()) << file;
}

TEST(ProgramGolden, UrScriptIsUnchanged) {
  const auto files =
      program_files({{"seam", golden_trajectory()}}, golden_params(Robot::ur), "program");
  ASSERT_EQ(files.size(), 1u);
  expect_golden(files[0].second, "weld_seam.script");
}

TEST(ProgramGolden, AbbRapidModule) {
  const auto files =
      program_files({{"seam", golden_trajectory()}}, golden_params(Robot::abb), "program");
  ASSERT_EQ(files.size(), 1u);
  expect_golden(files[0].second, "weld_seam.mod");
}

TEST(ProgramGolden, KukaKrlSrcAndDat) {
  const auto files =
      program_files({{"seam", golden_trajectory()}}, golden_params(Robot::kuka), "program");
  ASSERT_EQ(files.size(), 2u);
  expect_golden(files[0].second, "weld_seam.src");
  expect_golden(files[1].second, "weld_seam.dat");
}

TEST(ProgramGolden, RosPathYaml) {
  expect_golden(trajectory_ros_yaml(golden_trajectory()), "weld_seam.ros.yaml");
}

}  // namespace
}  // namespace groovetrace
