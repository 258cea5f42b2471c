// Robot programs for every controller (program.hpp): each program is read back by a small
// parser written from the controller's conventions (program_parsers.hpp) and compared pose by
// pose with the passes; dry runs never switch the arc on; passes come in order, each with its
// arc on and off; the orientation conventions are checked both ways against hand values.

#include <gtest/gtest.h>

#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/program.hpp>
#include <groovetrace/trajectory_io.hpp>
#include <groovetrace/urscript.hpp>
#include <nlohmann/json.hpp>

#include "robot/program_parsers.hpp"

namespace groovetrace {
namespace {

using test::ProgramEvent;

Waypoint make_waypoint(const Eigen::Vector3d& p, const Eigen::Vector3d& normal,
                       const Eigen::Vector3d& travel) {
  Waypoint w;
  w.position = p;
  w.orientation = tool_orientation(normal, travel);
  return w;
}

/// A wavy seam in the base frame: uneven spacing, torch tilts either side, travel turning.
Trajectory wavy(double z_offset = 0.0, int n = 9) {
  Trajectory t;
  t.frame = "base";
  double x = 0.3;
  for (int i = 0; i < n; ++i) {
    const double tilt = 0.4 * std::sin(0.9 * i);
    const Eigen::Vector3d normal(0.2 * std::cos(0.5 * i), std::sin(tilt), std::cos(tilt));
    t.waypoints.push_back(make_waypoint({x, 0.02 * std::sin(30.0 * x), 0.15 + z_offset}, normal,
                                        {1.0, 0.3 * std::cos(i), 0.0}));
    x += 0.002 + 0.003 * (i % 3);
  }
  fill_rotation_representations(t);
  return t;
}

/// A path whose torch points straight down at the first two waypoints (KUKA's B = 90 deg, the
/// gimbal lock of A and C) and horizontally at the last.
Trajectory gimbal() {
  Trajectory t;
  t.frame = "base";
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  t.waypoints.push_back(make_waypoint({0.5, 0.0, 0.1}, up, {-1, 0, 0}));
  t.waypoints.push_back(make_waypoint({0.49, 0.0, 0.1}, up, {-1, 0.2, 0}));
  t.waypoints.push_back(make_waypoint({0.48, 0.01, 0.1}, {1, 0, 0}, {0, 0, 1}));
  fill_rotation_representations(t);
  return t;
}

ProgramParams params_for(Robot robot) {
  ProgramParams p;
  p.robot = robot;
  p.arc_output = 3;
  p.approach_offset = 0.04;
  p.blend_radius = 0.0015;
  return p;
}

/// The program of `robot` read back as events.
std::vector<ProgramEvent> read_back(const std::vector<WeldPass>& passes, const ProgramParams& p) {
  const auto files = program_files(passes, p, "program");
  switch (p.robot) {
    case Robot::abb:
      EXPECT_EQ(files.size(), 1u);
      EXPECT_EQ(files[0].first, "program.mod");
      return test::parse_rapid(files[0].second, p.arc_output);
    case Robot::kuka:
      EXPECT_EQ(files.size(), 2u);
      EXPECT_EQ(files[0].first, "program.src");
      EXPECT_EQ(files[1].first, "program.dat");
      return test::parse_krl(files[0].second, files[1].second, p.arc_output);
    case Robot::ur:
      break;
  }
  EXPECT_EQ(files.size(), 1u);
  EXPECT_EQ(files[0].first, "program.script");
  return test::parse_urscript(files[0].second, p.arc_output);
}

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

/// The events must be, pass after pass: approach above the first waypoint (-tool z by
/// approach_offset), the first waypoint, arc on (not in a dry run), the other waypoints, arc
/// off, retreat above the last one; poses within 1 um and 2 urad (the printed precision).
void expect_passes(const std::vector<ProgramEvent>& all, const std::vector<WeldPass>& passes,
                   const ProgramParams& p) {
  std::vector<ProgramEvent> events;
  for (const ProgramEvent& e : all)
    if (e.kind != ProgramEvent::kText) events.push_back(e);
  std::size_t at = 0;
  auto expect_move = [&](const Eigen::Vector3d& position, const Eigen::Matrix3d& rotation,
                         const std::string& what) {
    ASSERT_LT(at, events.size()) << what;
    const ProgramEvent& e = events[at++];
    ASSERT_EQ(e.kind, ProgramEvent::kMove) << what;
    EXPECT_LT((e.position - position).norm(), 1e-6) << what << ": " << e.text;
    EXPECT_LT(angle_between(e.rotation, rotation), 2e-6) << what << ": " << e.text;
  };
  auto expect_kind = [&](ProgramEvent::Kind kind, const std::string& what) {
    ASSERT_LT(at, events.size()) << what;
    EXPECT_EQ(events[at++].kind, kind) << what;
  };
  for (std::size_t k = 0; k < passes.size(); ++k) {
    const auto& w = passes[k].path.waypoints;
    const std::string pass = "pass " + std::to_string(k);
    const Eigen::Matrix3d first = w.front().orientation.toRotationMatrix();
    const Eigen::Matrix3d last = w.back().orientation.toRotationMatrix();
    expect_move(w.front().position - p.approach_offset * first.col(2), first, pass + " approach");
    expect_move(w.front().position, first, pass + " start");
    if (!p.dry_run) expect_kind(ProgramEvent::kArcOn, pass + " arc on");
    for (std::size_t i = 1; i < w.size(); ++i) {
      expect_move(w[i].position, w[i].orientation.toRotationMatrix(),
                  pass + " waypoint " + std::to_string(i));
    }
    expect_kind(ProgramEvent::kArcOff, pass + " arc off");
    expect_move(w.back().position - p.approach_offset * last.col(2), last, pass + " retreat");
  }
  EXPECT_EQ(at, events.size()) << "events after the last pass";
}

class EveryController : public ::testing::TestWithParam<Robot> {};

TEST_P(EveryController, ReadBackPosesAreThePath) {
  for (const Trajectory& t : {wavy(), gimbal()}) {
    const std::vector<WeldPass> passes = {{"seam", t}};
    expect_passes(read_back(passes, params_for(GetParam())), passes, params_for(GetParam()));
  }
}

TEST_P(EveryController, DryRunNeverSwitchesTheArcOn) {
  const std::vector<WeldPass> passes = {{"root", wavy()}, {"cap", wavy(0.004)}};
  ProgramParams p = params_for(GetParam());
  p.dry_run = true;
  const std::vector<ProgramEvent> events = read_back(passes, p);
  expect_passes(events, passes, p);  // the same motions, with no arc on
  for (const ProgramEvent& e : events) EXPECT_NE(e.kind, ProgramEvent::kArcOn);
  // Nor any other way of switching an output on, and the program says it is a dry run.
  std::string text;
  for (const auto& [name, bytes] : program_files(passes, p, "program")) text += bytes;
  for (const char* on : {", True)", "SetDO doArc3, 1", "= TRUE", "sleep(", "WaitTime", "WAIT"}) {
    EXPECT_EQ(text.find(on), std::string::npos) << on;
  }
  EXPECT_NE(text.find("DRY RUN: the arc is never switched on"), std::string::npos);
}

TEST_P(EveryController, PassesComeInOrderEachWithItsArc) {
  const std::vector<WeldPass> passes = {
      {"root", wavy(0.0, 7)}, {"fill 1", wavy(0.003, 5)}, {"cap", wavy(0.006, 8)}};
  const ProgramParams p = params_for(GetParam());
  const std::vector<ProgramEvent> events = read_back(passes, p);
  expect_passes(events, passes, p);
  // Each pass announced, in weld order.
  std::vector<std::string> announced;
  for (const ProgramEvent& e : events) {
    for (const char* name : {"pass 1 of 3: root", "pass 2 of 3: fill 1", "pass 3 of 3: cap"}) {
      if (e.kind == ProgramEvent::kText && e.text.find(name) != std::string::npos) {
        announced.push_back(name);
      }
    }
  }
  EXPECT_EQ(announced, (std::vector<std::string>{"pass 1 of 3: root", "pass 2 of 3: fill 1",
                                                 "pass 3 of 3: cap"}));
}

INSTANTIATE_TEST_SUITE_P(Robots, EveryController,
                         ::testing::Values(Robot::ur, Robot::abb, Robot::kuka),
                         [](const auto& info) { return std::string(to_string(info.param)); });

// --- orientation conventions, the other way: hand values -------------------------------

/// The one line of `text` that starts (after spaces) with `prefix`.
std::string line_with(const std::string& text, const std::string& prefix) {
  for (const std::string& line : test::text_lines(text)) {
    if (test::begins(test::trimmed(line), prefix)) return test::trimmed(line);
  }
  return "";
}

Trajectory one_pose(const Eigen::Matrix3d& rotation) {
  Trajectory t;
  t.frame = "base";
  Waypoint w;
  w.position = {0.5, -0.25, 0.125};
  w.orientation = Eigen::Quaterniond(rotation);
  t.waypoints = {w, w};
  t.waypoints[1].position.x() += 0.01;
  fill_rotation_representations(t);
  return t;
}

TEST(RapidConvention, QuaternionIsWFirstWithPositionsInMillimetres) {
  // Tool z up turned 90 deg about base z: q = (w, x, y, z) = (cos 45, 0, 0, sin 45).
  const std::string mod =
      rapid_module({{"seam", one_pose(test::rot_z(90))}}, params_for(Robot::abb), "program");
  EXPECT_EQ(line_with(mod, "LOCAL CONST robtarget p1_0 "),
            "LOCAL CONST robtarget p1_0 := [[500.000,-250.000,125.000],"
            "[0.707106781,0.000000000,0.000000000,0.707106781],[0,0,0,0],"
            "[9E9,9E9,9E9,9E9,9E9,9E9]];");
  // Torch straight down, travel +x: a half turn about x, q = (0, 1, 0, 0).
  const std::string down =
      rapid_module({{"seam", one_pose(test::rot_x(180))}}, params_for(Robot::abb), "program");
  EXPECT_NE(line_with(down, "LOCAL CONST robtarget p1_0 ").find("[0.000000000,1.000000000,"),
            std::string::npos);
  // A quaternion with w < 0 prints as its equal with w > 0.
  const std::string neg = rapid_module(
      {{"seam", one_pose(Eigen::Quaterniond(-0.5, 0.5, -0.5, 0.5).toRotationMatrix())}},
      params_for(Robot::abb), "program");
  EXPECT_NE(line_with(neg, "LOCAL CONST robtarget p1_0 ")
                .find("[0.500000000,-0.500000000,0.500000000,-0.500000000]"),
            std::string::npos);
}

TEST(KrlConvention, AbcAreZyxDegreesOfAToolWhoseXIsTheTorch) {
  ProgramParams p = params_for(Robot::kuka);
  // Chosen A, B, C: the KUKA tool frame Rz(30) Ry(20) Rx(-40); groovetrace's tool frame is it
  // turned back +90 deg about y (x = -Z_kuka, z = X_kuka).
  const Eigen::Matrix3d kuka = test::rot_z(30) * test::rot_y(20) * test::rot_x(-40);
  const KrlProgram krl = krl_program({{"seam", one_pose(kuka * test::rot_y(90))}}, p, "program");
  EXPECT_EQ(line_with(krl.dat, "DECL E6POS XP1_0="),
            "DECL E6POS XP1_0={X 500.000,Y -250.000,Z 125.000,A 30.00000,B 20.00000,C -40.00000}");
  // Torch straight down, travel -x: KUKA's familiar A 0, B 90, C 0 (X down, Z along +x).
  Trajectory down;
  down.frame = "base";
  down.waypoints = {make_waypoint({0.5, 0, 0.1}, {0, 0, 1}, {-1, 0, 0}),
                    make_waypoint({0.49, 0, 0.1}, {0, 0, 1}, {-1, 0, 0})};
  fill_rotation_representations(down);
  const KrlProgram d = krl_program({{"seam", down}}, p, "program");
  EXPECT_NE(line_with(d.dat, "DECL E6POS XP1_0=").find(",A 0.00000,B 90.00000,C 0.00000}"),
            std::string::npos)
      << d.dat;
}

TEST(RosPath, ReadBackIsThePathWithItsFrame) {
  for (const char* frame : {"base", "camera"}) {
    Trajectory t = wavy();
    t.frame = frame;
    std::string path_frame;
    const std::vector<test::RosPose> poses =
        test::parse_ros_path(trajectory_ros_yaml(t), path_frame);
    EXPECT_EQ(path_frame, frame);
    ASSERT_EQ(poses.size(), t.waypoints.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(poses[i].frame_id, frame);
      EXPECT_LT((poses[i].position - t.waypoints[i].position).norm(), 1e-8) << i;
      EXPECT_NEAR(poses[i].orientation.norm(), 1.0, 1e-8);
      EXPECT_LT(poses[i].orientation.angularDistance(t.waypoints[i].orientation), 1e-6) << i;
    }
  }
  Trajectory empty;
  EXPECT_EQ(trajectory_ros_yaml(empty).substr(trajectory_ros_yaml(empty).find("poses:")),
            "poses: []\n");
}

// --- settings and inputs that are wrong -------------------------------------------------

TEST(ProgramSettings, ArcOutputMustExistOnTheController) {
  const std::vector<WeldPass> passes = {{"seam", wavy()}};
  ProgramParams p = params_for(Robot::kuka);
  p.arc_output = 0;  // there is no $OUT[0]
  EXPECT_THROW(program_files(passes, p, "program"), UsageError);
  EXPECT_THROW(check_program_params(p), UsageError);
  p.arc_output = 4096;
  EXPECT_NO_THROW(program_files(passes, p, "program"));
  p.robot = Robot::ur;  // UR has standard digital outputs 0..7
  EXPECT_THROW(program_files(passes, p, "program"), UsageError);
  p.arc_output = 7;
  EXPECT_NO_THROW(program_files(passes, p, "program"));
  p.robot = Robot::abb;
  p.weld_speed = 0.0;
  EXPECT_THROW(program_files(passes, p, "program"), UsageError);
}

TEST(ProgramSettings, RobotAndDryRunAreParameters) {
  Params p;
  EXPECT_EQ(p.program.robot, Robot::ur);
  EXPECT_FALSE(p.program.dry_run);
  set_param(p, "robot", "kuka");
  set_param(p, "dry-run", "true");
  EXPECT_EQ(p.program.robot, Robot::kuka);
  EXPECT_TRUE(p.program.dry_run);
  const auto j = nlohmann::json::parse(params_json(p));
  EXPECT_EQ(j["robot"], "kuka");
  EXPECT_EQ(j["dry_run"], true);
  EXPECT_THROW(set_param(p, "robot", "fanuc"), UsageError);
  EXPECT_THROW(set_param(p, "dry_run", "maybe"), UsageError);
  EXPECT_THROW(set_param(p, "arc_output", "4097"), UsageError);
  for (const ParamSpec& spec : param_specs()) {
    // The switches: off by default, given without a value.
    EXPECT_EQ(spec.flag, spec.key == "dry_run" || spec.key == "multi_pass" ||
                             spec.key == "camera_frame_program")
        << spec.key;
  }
}

TEST(ProgramSettings, PassesThatCannotBeWeldedThrow) {
  const ProgramParams p = params_for(Robot::abb);
  EXPECT_THROW(program_files({}, p, "program"), NoGrooveError);
  EXPECT_THROW(program_files({{"root", Trajectory{}}}, p, "program"), NoGrooveError);
  Trajectory camera = wavy();
  camera.frame = "camera";
  for (Robot r : {Robot::ur, Robot::abb, Robot::kuka}) {
    ProgramParams q = params_for(r);
    EXPECT_THROW(program_files({{"root", wavy()}, {"cap", camera}}, q, "program"), InternalError);
    Trajectory bad = wavy();
    bad.waypoints[2].position.y() = NAN;
    EXPECT_THROW(program_files({{"root", bad}}, q, "program"), InternalError);
  }
}

TEST(ProgramSettings, PassNamesCannotBreakTheProgram) {
  // A quote, a newline and a semicolon in a name stay out of strings and comments.
  const std::vector<WeldPass> passes = {{"ro\"ot\n;END", wavy()}, {"cap", wavy(0.004)}};
  for (Robot r : {Robot::ur, Robot::abb, Robot::kuka}) {
    std::string text;
    for (const auto& [name, bytes] : program_files(passes, params_for(r), "program")) text += bytes;
    EXPECT_EQ(text.find("ro\"ot"), std::string::npos) << to_string(r);
    EXPECT_NE(text.find("pass 1 of 2: ro_ot__END"), std::string::npos) << to_string(r);
  }
}

TEST(ProgramSettings, OnePassUrScriptIsTheSingleTrajectoryProgram) {
  const Trajectory t = wavy();
  const ProgramParams p = params_for(Robot::ur);
  EXPECT_EQ(urscript_program({{"seam", t}}, p), urscript_program(t, p));
  EXPECT_EQ(urscript_program({{"root", t}}, p), urscript_program(t, p));  // one pass: no title
}

}  // namespace
}  // namespace groovetrace
