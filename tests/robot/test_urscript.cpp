// The URScript program: a golden file for a small hand-built path, plus structural checks
// that hold for any path and do not depend on the golden file.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <groovetrace/error.hpp>
#include <groovetrace/trajectory.hpp>
#include <groovetrace/urscript.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using groovetrace::ProgramParams;
using groovetrace::Trajectory;

constexpr double kPi = 3.14159265358979323846;

groovetrace::Waypoint waypoint(const Eigen::Vector3d& p, const Eigen::Vector3d& normal,
                               const Eigen::Vector3d& travel) {
  groovetrace::Waypoint w;
  w.position = p;
  w.orientation = groovetrace::tool_orientation(normal, travel);
  w.rotation_vector.setZero();  // Eigen members are not initialized by Waypoint
  w.euler_zyx_deg.setZero();
  return w;
}

/// Four waypoints along base +x at z = 0.2 m, torch pointing straight down, the last one
/// tilted 10 degrees about the travel axis. Segments 10, 6 and 4 mm.
Trajectory golden_trajectory() {
  Trajectory t;
  t.frame = "base";
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), x = Eigen::Vector3d::UnitX();
  const double tilt = 10.0 * kPi / 180.0;
  t.waypoints.push_back(waypoint({0.400, -0.100, 0.200}, up, x));
  t.waypoints.push_back(waypoint({0.410, -0.100, 0.200}, up, x));
  t.waypoints.push_back(waypoint({0.416, -0.100, 0.200}, up, x));
  t.waypoints.push_back(
      waypoint({0.420, -0.100, 0.200}, {0.0, -std::sin(tilt), std::cos(tilt)}, x));
  t.direction = x;
  t.length = 0.02;
  groovetrace::fill_rotation_representations(t);
  return t;
}

ProgramParams golden_params() {
  ProgramParams p;
  p.approach_offset = 0.05;
  p.approach_speed = 0.25;
  p.weld_speed = 0.006;
  p.acceleration = 0.8;
  p.blend_radius = 0.002;
  p.arc_output = 3;
  p.arc_delay = 0.4;
  return p;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The golden file was checked by hand, line by line, when it was created:
// - approach: first waypoint (0.4, -0.1, 0.2) minus 0.05 m along tool z = (0, 0, -1), i.e.
//   (0.4, -0.1, 0.25); tool frame x = (1,0,0), y = (0,-1,0), z = (0,0,-1) is a half turn
//   about x: rotation vector (pi, 0, 0) = (3.141593, 0, 0).
// - blends: at waypoint 1 min(2 mm, 0.4 * min(10, 6) mm = 2.4 mm) = 0.002000; at waypoint 2
//   min(2 mm, 0.4 * min(6, 4) mm = 1.6 mm) = 0.001600; last movep r = 0.
// - last waypoint: tool tilted 10 deg, R = Rx(190 deg); the principal vector would be
//   (-2.967060, 0, 0), the continuous one is 190 deg = (3.316126, 0, 0).
// - retreat: (0.42, -0.1, 0.2) - 0.05 * (0, sin 10, -cos 10) = (0.42, -0.108682, 0.249240).
// Regenerate only deliberately: GT_UPDATE_GOLDEN=1 rewrites the file and fails the test.
TEST(Urscript, MatchesGoldenFile) {
  const std::string program = groovetrace::urscript_program(golden_trajectory(), golden_params());
  const std::string path = std::string(GT_SOURCE_DIR) + "/tests/support/golden/weld_seam.script";
  if (std::getenv("GT_UPDATE_GOLDEN") != nullptr) {
    std::ofstream(path, std::ios::binary) << program;
    FAIL() << "rewrote " << path << "; check it by hand before committing";
  }
  const std::string golden = read_file(path);
  ASSERT_FALSE(golden.empty()) << "missing golden file " << path;
  EXPECT_EQ(program, golden);
}

// --- structure, independent of the golden file -----------------------------------------

/// The numbers of the pose literal p[...] on a line.
std::vector<double> pose_of(const std::string& line) {
  std::vector<double> values;
  const auto open = line.find("p[");
  const auto close = line.find(']', open);
  if (open == std::string::npos || close == std::string::npos) return values;
  std::istringstream s(line.substr(open + 2, close - open - 2));
  s.imbue(std::locale::classic());
  std::string item;
  while (std::getline(s, item, ',')) values.push_back(std::stod(item));
  return values;
}

double named_value(const std::string& line, const std::string& name) {
  const auto at = line.find(name + "=");
  if (at == std::string::npos) return NAN;
  return std::stod(line.substr(at + name.size() + 1));
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream s(text);
  std::string line;
  while (std::getline(s, line)) lines.push_back(line);
  return lines;
}

bool starts_with(const std::string& line, const std::string& prefix) {
  return line.compare(0, prefix.size(), prefix) == 0;
}

/// A wavy seam with uneven spacing (some segments far shorter than the blend radius) and
/// torch tilts that cross the half-turn, in the base frame.
Trajectory wavy_trajectory() {
  Trajectory t;
  t.frame = "base";
  double x = 0.3;
  const double steps[] = {0.004, 0.0015, 0.009, 0.0007, 0.006, 0.003, 0.012, 0.002, 0.005};
  for (int i = 0; i < 10; ++i) {
    const double tilt = 0.15 * std::sin(0.9 * i);
    const Eigen::Vector3d normal(0.1 * std::cos(0.5 * i), std::sin(tilt), std::cos(tilt));
    t.waypoints.push_back(waypoint({x, 0.02 * std::sin(30.0 * x), 0.15 + 0.01 * std::cos(20.0 * x)},
                                   normal, {1.0, 0.2, 0.0}));
    if (i < 9) x += steps[i];
  }
  groovetrace::fill_rotation_representations(t);
  return t;
}

TEST(Urscript, ProgramStructure) {
  const Trajectory t = wavy_trajectory();
  ProgramParams params;
  params.blend_radius = 0.003;
  params.arc_output = 5;
  const std::string program = groovetrace::urscript_program(t, params);
  const std::vector<std::string> lines = lines_of(program);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(program.back(), '\n');
  EXPECT_EQ(lines.back(), "end");

  int def_line = -1, arc_on = -1, arc_off = -1, first_movep = -1, last_movep = -1;
  std::vector<int> movel;
  std::vector<double> radii;
  for (int i = 0; i < static_cast<int>(lines.size()); ++i) {
    const std::string& line = lines[static_cast<std::size_t>(i)];
    if (line == "def weld_seam():") {
      EXPECT_EQ(def_line, -1);
      def_line = i;
    } else if (def_line >= 0 && i + 1 < static_cast<int>(lines.size())) {
      EXPECT_TRUE(starts_with(line, "  ")) << "body lines are indented: " << line;
    } else if (def_line < 0) {
      EXPECT_TRUE(starts_with(line, "#")) << "only comments before the def: " << line;
    }
    if (line == "  set_standard_digital_out(5, True)") arc_on = i;
    if (line == "  set_standard_digital_out(5, False)") arc_off = i;
    if (starts_with(line, "  movel(")) movel.push_back(i);
    if (starts_with(line, "  movep(")) {
      if (first_movep < 0) first_movep = i;
      last_movep = i;
      radii.push_back(named_value(line, "r"));
      EXPECT_NEAR(named_value(line, "v"), params.weld_speed, 1e-9);
      EXPECT_NEAR(named_value(line, "a"), params.acceleration, 1e-9);
    }
  }
  ASSERT_GE(def_line, 0);
  EXPECT_EQ(lines[static_cast<std::size_t>(def_line) + 1], "  textmsg(\"groovetrace: approach\")");
  ASSERT_EQ(radii.size(), t.waypoints.size() - 1);
  ASSERT_EQ(movel.size(), 3u);  // approach, down to the first waypoint, retreat
  EXPECT_LT(movel[1], arc_on);
  EXPECT_LT(arc_on, first_movep);
  EXPECT_LT(last_movep, arc_off);
  EXPECT_LT(arc_off, movel[2]);

  // Blend radii: capped at 0.4 of the shorter neighbouring segment, 0 at the end.
  const auto& w = t.waypoints;
  int capped = 0;
  for (std::size_t i = 1; i < w.size(); ++i) {
    const double r = radii[i - 1];
    EXPECT_GE(r, 0.0);
    EXPECT_LE(r, params.blend_radius + 5e-7);
    if (i + 1 < w.size()) {
      const double shorter = std::min((w[i].position - w[i - 1].position).norm(),
                                      (w[i + 1].position - w[i].position).norm());
      EXPECT_LE(r, 0.4 * shorter + 5e-7) << i;
      EXPECT_NEAR(r, std::min(params.blend_radius, 0.4 * shorter), 5e-7) << i;
      if (0.4 * shorter < params.blend_radius) ++capped;
    }
  }
  EXPECT_GE(capped, 3);  // the path was built so the cap matters
  EXPECT_EQ(radii.back(), 0.0);

  // Poses: every movep is its waypoint; approach and retreat back off along -tool z.
  for (std::size_t i = 1; i < w.size(); ++i) {
    const std::vector<double> p = pose_of(lines[static_cast<std::size_t>(first_movep) + i - 1]);
    ASSERT_EQ(p.size(), 6u);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(p[static_cast<std::size_t>(k)], w[i].position[k], 5e-7);
      EXPECT_NEAR(p[static_cast<std::size_t>(k) + 3], w[i].rotation_vector[k], 5e-7);
    }
  }
  const auto check_backed_off = [&](int line, const groovetrace::Waypoint& at) {
    const std::vector<double> p = pose_of(lines[static_cast<std::size_t>(line)]);
    ASSERT_EQ(p.size(), 6u);
    const Eigen::Vector3d pos(p[0], p[1], p[2]);
    const Eigen::Vector3d tool_z = at.orientation * Eigen::Vector3d::UnitZ();
    EXPECT_NEAR((pos - at.position).dot(tool_z), -params.approach_offset, 1e-6);
    EXPECT_NEAR((pos - at.position).norm(), params.approach_offset, 1e-6);
    // The torch points down (tool z has -z in base), so backing off is going up.
    EXPECT_GT(pos.z(), at.position.z() + 0.9 * params.approach_offset);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(p[static_cast<std::size_t>(k) + 3], at.rotation_vector[k], 5e-7);
    EXPECT_NEAR(named_value(lines[static_cast<std::size_t>(line)], "v"), params.approach_speed,
                1e-9);
  };
  check_backed_off(movel[0], w.front());
  check_backed_off(movel[2], w.back());
  const std::vector<double> first = pose_of(lines[static_cast<std::size_t>(movel[1])]);
  ASSERT_EQ(first.size(), 6u);
  EXPECT_LT((Eigen::Vector3d(first[0], first[1], first[2]) - w.front().position).norm(), 1e-6);

  // Deterministic text.
  EXPECT_EQ(program, groovetrace::urscript_program(t, params));
}

TEST(Urscript, BlendRadiusAt) {
  const Trajectory t = golden_trajectory();  // segments 10, 6, 4 mm
  EXPECT_EQ(groovetrace::blend_radius_at(t, 0, 0.002), 0.0);
  EXPECT_NEAR(groovetrace::blend_radius_at(t, 1, 0.002), 0.002, 1e-15);
  EXPECT_NEAR(groovetrace::blend_radius_at(t, 1, 0.005), 0.0024, 1e-12);
  EXPECT_NEAR(groovetrace::blend_radius_at(t, 2, 0.002), 0.0016, 1e-12);
  EXPECT_NEAR(groovetrace::blend_radius_at(t, 2, 0.001), 0.001, 1e-15);
  EXPECT_EQ(groovetrace::blend_radius_at(t, 3, 0.002), 0.0);
  EXPECT_EQ(groovetrace::blend_radius_at(t, 1, -1.0), 0.0);
  EXPECT_THROW(groovetrace::blend_radius_at(t, 4, 0.002), std::out_of_range);
  Trajectory two = t;
  two.waypoints.resize(2);
  EXPECT_EQ(groovetrace::blend_radius_at(two, 0, 0.002), 0.0);
  EXPECT_EQ(groovetrace::blend_radius_at(two, 1, 0.002), 0.0);
}

TEST(Urscript, CameraFrameIsFlaggedAndBadInputsThrow) {
  Trajectory t = golden_trajectory();
  t.frame = "camera";
  const std::string program = groovetrace::urscript_program(t, golden_params());
  EXPECT_NE(program.find("# frame: camera\n"), std::string::npos);
  EXPECT_NE(program.find("# WARNING"), std::string::npos);

  ProgramParams bad = golden_params();
  bad.weld_speed = 0.0;
  EXPECT_THROW(groovetrace::urscript_program(t, bad), groovetrace::UsageError);
  bad = golden_params();
  bad.arc_output = 8;
  EXPECT_THROW(groovetrace::urscript_program(t, bad), groovetrace::UsageError);
  bad = golden_params();
  bad.blend_radius = -0.001;
  EXPECT_THROW(groovetrace::urscript_program(t, bad), groovetrace::UsageError);
  Trajectory empty;
  EXPECT_THROW(groovetrace::urscript_program(empty, golden_params()), groovetrace::NoGrooveError);
  t.waypoints[1].position.x() = NAN;
  EXPECT_THROW(groovetrace::urscript_program(t, golden_params()), groovetrace::InternalError);
}

TEST(Urscript, SingleWaypointHasNoMovep) {
  Trajectory t = golden_trajectory();
  t.waypoints.resize(1);
  const std::string program = groovetrace::urscript_program(t, golden_params());
  EXPECT_EQ(program.find("movep("), std::string::npos);
  EXPECT_NE(program.find("set_standard_digital_out(3, True)"), std::string::npos);
  EXPECT_NE(program.find("set_standard_digital_out(3, False)"), std::string::npos);
}

}  // namespace
