// Torch angles, weaving, multi-pass planning and the program guards (docs/robot.md), on paths
// and sections whose answers are worked out by hand here.
#include <gtest/gtest.h>

#include <cmath>
#include <groovetrace/error.hpp>
#include <groovetrace/guards.hpp>
#include <groovetrace/weld.hpp>

namespace groovetrace {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A straight seam along +x of `length` (m), waypoints every `step`, the torch straight down
// (tool z = -Z, x = +X, so tool y = z x x = -Y).
Trajectory straight_path(double length = 0.02, double step = 0.002) {
  Trajectory t;
  t.frame = "base";
  const Eigen::Quaterniond down =
      tool_orientation(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
  for (double s = 0; s <= length + 1e-12; s += step) {
    Waypoint w;
    w.position = Eigen::Vector3d(s, 0, 0);
    w.orientation = down;
    t.waypoints.push_back(w);
  }
  fill_rotation_representations(t);
  t.length = length;
  return t;
}

Eigen::Vector3d tool_z(const Waypoint& w) { return w.orientation * Eigen::Vector3d::UnitZ(); }

TEST(TorchAngles, PushLeansTheTorchForwardAndWorkAngleTowardsMinusY) {
  Trajectory push = straight_path();
  apply_torch_angles(push, 10.0, 0.0);
  // Tool z (0,0,-1) turned 10 deg about tool y towards travel (+X).
  EXPECT_LT(
      (tool_z(push.waypoints[3]) - Eigen::Vector3d(std::sin(10 * kDeg), 0, -std::cos(10 * kDeg)))
          .norm(),
      1e-12);
  EXPECT_EQ(push.waypoints[3].position, Eigen::Vector3d(0.006, 0, 0));

  Trajectory work = straight_path();
  apply_torch_angles(work, 0.0, 10.0);
  // Tool y is -Y, so towards -y is +Y.
  EXPECT_LT(
      (tool_z(work.waypoints[0]) - Eigen::Vector3d(0, std::sin(10 * kDeg), -std::cos(10 * kDeg)))
          .norm(),
      1e-12);
  // Rotation vectors follow the new orientation.
  const Eigen::Vector3d r = work.waypoints[0].rotation_vector;
  EXPECT_LT(Eigen::AngleAxisd(r.norm(), r.normalized())
                    .toRotationMatrix()
                    .col(2)
                    .dot(tool_z(work.waypoints[0])) -
                1.0,
            1e-12);
}

// Lateral offsets of a woven straight path (m, along tool y = -Y) by arc length (x).
std::vector<std::pair<double, double>> offsets(const Trajectory& t) {
  std::vector<std::pair<double, double>> out;
  for (const Waypoint& w : t.waypoints) out.emplace_back(w.position.x(), -w.position.y());
  return out;
}

TEST(Weave, ZigzagTurnsAtEveryQuarterWaveOnAlternateSides) {
  const auto o = offsets(weave_path(straight_path(0.02), "zigzag", 0.001, 0.004, {}));
  // Start, 10 corners at x = 1, 3, ..., 19 mm, end.
  ASSERT_EQ(o.size(), 12u);
  EXPECT_EQ(o.front(), std::make_pair(0.0, 0.0));
  for (int k = 0; k < 10; ++k) {
    EXPECT_NEAR(o[k + 1].first, 0.001 + 0.002 * k, 1e-12);
    EXPECT_NEAR(o[k + 1].second, k % 2 == 0 ? 0.001 : -0.001, 1e-12);
  }
  EXPECT_NEAR(o.back().first, 0.02, 1e-12);
  EXPECT_NEAR(o.back().second, 0.0, 1e-12);
}

TEST(Weave, AmplitudeIsBoundedWhereTheOpeningIsNarrow) {
  const Trajectory path = straight_path(0.02);
  std::vector<double> bound(path.waypoints.size(), 0.004);
  for (std::size_t i = 6; i < bound.size(); ++i) bound[i] = 0.0005;  // narrower from 12 mm on
  for (const auto& [x, y] : offsets(weave_path(path, "sine", 0.002, 0.004, bound))) {
    EXPECT_LE(std::abs(y), (x < 0.011 ? 0.002 : 0.0005) + 1e-12) << "at x = " << x;
  }
}

TEST(Weave, SineSamplesTheWaveAndTriangleCrossesStraight) {
  const auto sine = offsets(weave_path(straight_path(0.008), "sine", 0.001, 0.004, {}));
  for (const auto& [x, y] : sine) {
    if (x > 0 && x < 0.008) {
      EXPECT_NEAR(y, 0.001 * std::sin(2 * M_PI * x / 0.004), 1e-12);
    }
  }
  EXPECT_EQ(sine.size(), 33u);  // 16 per period over two periods, plus both ends
  const auto tri = offsets(weave_path(straight_path(0.008), "triangle", 0.001, 0.004, {}));
  // (0,0) (0,-A) (4,+A) (4,-A) (8,0): straight across at x = 4 mm.
  ASSERT_EQ(tri.size(), 5u);
  EXPECT_NEAR(tri[1].second, -0.001, 1e-12);
  EXPECT_NEAR(tri[2].first, 0.004, 1e-12);
  EXPECT_NEAR(tri[2].second, 0.001, 1e-12);
  EXPECT_NEAR(tri[3].first, 0.004, 1e-12);
  EXPECT_NEAR(tri[3].second, -0.001, 1e-12);
  EXPECT_THROW(weave_path(straight_path(), "spiral", 0.001, 0.004, {}), UsageError);
}

// A V 8 mm deep whose walls run 0.5 mm across per mm of height on each side (53.1 deg
// included), filled with 8 mm^2 beads. Worked by hand: bead height sqrt(1.5 * 8 / 2.5) = 2.19
// mm, width 5.48 mm. Layer 0: 1 bead, up to sqrt(2 * 8 / 1) = 4 mm. Layer 1: 5.1 mm wide at its
// middle, 1 bead, up to sqrt(16 + 16) = 5.66 mm. Layer 2 would end at 6.93 mm, within half a
// bead of the top (8 - 1.1 = 6.9): the cap, from 5.66 mm to the top, 16 mm^2 and 8 mm wide =
// 2 beads. 4 passes of 8 mm^2 = 32 mm^2 = the section (8 * 8 / 2).
TEST(MultiPass, AKnownVGrooveTakesFourPasses) {
  const PassPlan plan = plan_passes({0.008, 0.5, 0.5}, 8e-6);
  ASSERT_EQ(plan.beads.size(), 4u);
  const std::vector<std::string> names = {"root", "fill 1", "cap 1", "cap 2"};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(plan.beads[i].name, names[i]);
  EXPECT_NEAR(plan.section_area, 32e-6, 1e-15);
  EXPECT_NEAR(plan.beads[1].height, 0.004, 1e-12);
  EXPECT_NEAR(plan.beads[2].height, std::sqrt(32e-6), 1e-12);
  // The cap's two beads sit at +-1/4 of its mid-height width, leaning towards their walls.
  const double mid = 0.5 * (std::sqrt(32e-6) + 0.008);
  EXPECT_NEAR(plan.beads[2].lateral, 0.25 * mid, 1e-12);
  EXPECT_NEAR(plan.beads[3].lateral, -0.25 * mid, 1e-12);
  EXPECT_LT(plan.beads[2].work_angle, 0.0);
  EXPECT_GT(plan.beads[3].work_angle, 0.0);
  EXPECT_EQ(plan.beads[0].work_angle, 0.0);
}

// Grooves of known area, 50 to 120 deg, 4 to 30 mm deep, V and single bevel, with beads of 5
// to 40 mm^2: every layer but the cap holds exactly its beads' metal, the cap covers the rest,
// so the passes' metal is at least the section and overfills it by less than the cap's beads;
// every bead lies inside the walls, layer above layer.
TEST(MultiPass, PassesFillGroovesOfKnownArea) {
  for (double deg : {50.0, 60.0, 90.0, 120.0}) {
    for (double depth : {0.004, 0.010, 0.030}) {
      for (double area : {5e-6, 14e-6, 40e-6}) {
        for (bool bevel : {false, true}) {
          const double run = std::tan(0.5 * deg * kDeg);
          const SectionShape s{depth, bevel ? 0.0 : run, bevel ? 2 * run : run};
          const double truth = 0.5 * depth * depth * 2 * run;  // the triangle's area
          const PassPlan plan = plan_passes(s, area);
          SCOPED_TRACE(testing::Message() << deg << " deg, " << depth * 1e3 << " mm, " << area * 1e6
                                          << " mm^2, bevel " << bevel);
          EXPECT_NEAR(plan.section_area, truth, 1e-15);
          const int layers = plan.beads.back().layer + 1;
          int caps = 0;
          for (const Bead& b : plan.beads) caps += b.layer == layers - 1;
          const double metal = static_cast<double>(plan.beads.size()) * area;
          EXPECT_GE(metal, truth * (1 - 1e-9));
          EXPECT_LT(metal - truth, caps * area + 1e-15);
          EXPECT_GE(static_cast<double>(plan.beads.size()), std::ceil(truth / area - 1e-9));
          for (std::size_t i = 0; i < plan.beads.size(); ++i) {
            const Bead& b = plan.beads[i];
            EXPECT_LE(b.lateral, s.run_pos_y * b.mid_height + 1e-12);
            EXPECT_GE(b.lateral, -s.run_neg_y * b.mid_height - 1e-12);
            EXPECT_LE(b.mid_height, depth + 1e-12);
            if (i > 0) {
              EXPECT_GE(b.layer, plan.beads[i - 1].layer);
            }
            if (i > 0 && b.layer > plan.beads[i - 1].layer) {
              EXPECT_GT(b.height, plan.beads[i - 1].height);
            }
          }
          EXPECT_EQ(plan.beads.front().name, "root");
        }
      }
    }
  }
  EXPECT_THROW(plan_passes({0.01, 0.5, 0.5}, 0.0), UsageError);
  EXPECT_THROW(plan_passes({0.0, 0.5, 0.5}, 8e-6), UsageError);
}

TEST(MultiPass, PassesFollowEachWaypointsOwnSection) {
  const Trajectory path = straight_path(0.004);  // 3 waypoints
  // The middle waypoint's groove is twice as deep and as wide as the others'.
  std::vector<SectionShape> shapes(3, SectionShape{0.008, 0.5, 0.5});
  shapes[1].depth = 0.016;
  WeldParams weld;
  weld.multi_pass = true;
  weld.bead_area = 8e-6;
  std::vector<std::string> warnings;
  const auto passes = weld_passes(path, shapes, weld, ProgramParams{}, warnings);
  ASSERT_EQ(passes.size(), 4u);  // the plan of the median section (8 mm), as above
  EXPECT_TRUE(warnings.empty());
  // The root pass stays on the root; cap 1 at height 5.66 mm and lateral 0.25 * mid, along
  // -tool z (= +Z) and tool y (= -Y); doubled at the deeper waypoint.
  EXPECT_LT((passes[0].path.waypoints[1].position - path.waypoints[1].position).norm(), 1e-12);
  const double h = std::sqrt(32e-6), lateral = 0.25 * 0.5 * (h + 0.008);
  for (std::size_t i = 0; i < 3; ++i) {
    const double k = i == 1 ? 2.0 : 1.0;
    const Eigen::Vector3d expected =
        path.waypoints[i].position + Eigen::Vector3d(0, -k * lateral, k * h);
    EXPECT_LT((passes[2].path.waypoints[i].position - expected).norm(), 1e-12) << i;
  }
}

TEST(MultiPass, WithoutAFittedSectionItIsOnePassAndAWarning) {
  WeldParams weld;
  weld.multi_pass = true;
  std::vector<std::string> warnings;
  const auto passes = weld_passes(straight_path(), {}, weld, ProgramParams{}, warnings);
  ASSERT_EQ(passes.size(), 1u);
  EXPECT_EQ(passes[0].name, "seam");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("one pass"), std::string::npos);
}

TEST(MultiPass, BeadAreaComesFromTheWire) {
  WeldParams weld;  // 1.2 mm wire at 0.1 m/s, 8 mm/s travel: 1.131 mm^2 * 12.5 = 14.14 mm^2
  EXPECT_NEAR(bead_area(weld, ProgramParams{}), 0.25 * M_PI * 1.44e-6 * 12.5, 1e-15);
  weld.bead_area = 2e-5;
  EXPECT_EQ(bead_area(weld, ProgramParams{}), 2e-5);
}

// The guards: a camera 0.3 m above the straight path looks down on it.
class Guards : public ::testing::Test {
 protected:
  void expect_unsafe(const Trajectory& path, const std::string& words, const GuardParams& g = {}) {
    try {
      check_program({{"seam", path}}, g, ProgramParams{}, viewpoint_);
      ADD_FAILURE() << "no guard tripped; expected: " << words;
    } catch (const UnsafeProgramError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
      EXPECT_EQ(e.code(), ExitCode::kUnsafe);
    }
  }
  Eigen::Vector3d viewpoint_{0.01, 0, 0.3};
};

TEST_F(Guards, AGoodPathPasses) {
  EXPECT_NO_THROW(check_program({{"seam", straight_path()}}, {}, ProgramParams{}, viewpoint_));
}

TEST_F(Guards, EachViolationIsNamed) {
  Trajectory t = straight_path();
  t.waypoints[4].position.x() = NAN;
  expect_unsafe(t, "waypoint 4: the pose is not finite");

  t = straight_path();
  t.waypoints[5].position.y() = 0.06;  // a 60 mm jump
  expect_unsafe(t, "waypoint 5: a step of 60.0 mm");

  t = straight_path();
  t.waypoints[2].orientation =
      t.waypoints[2].orientation *
      Eigen::Quaterniond(Eigen::AngleAxisd(40 * kDeg, Eigen::Vector3d::UnitX()));
  expect_unsafe(t, "waypoint 2: the torch turns by 40.0 deg");

  t = straight_path();
  for (Waypoint& w : t.waypoints) {  // torch upside down: z towards the camera
    w.orientation =
        w.orientation * Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  }
  expect_unsafe(t, "waypoint 0: the torch points out of the part");
}

TEST_F(Guards, WorkspaceHoldsApproachAndRetreat) {
  GuardParams g;
  // The waypoints lie at z = 0, the approach 50 mm above: a box up to 40 mm refuses it.
  g.workspace =
      Eigen::AlignedBox3d(Eigen::Vector3d(-0.1, -0.1, -0.1), Eigen::Vector3d(0.1, 0.1, 0.04));
  expect_unsafe(straight_path(), "the approach pose (0.0, 0.0, 50.0) mm lies outside the workspace",
                g);
  g.workspace->max().z() = 0.06;
  EXPECT_NO_THROW(check_program({{"seam", straight_path()}}, g, ProgramParams{}, viewpoint_));
  g.workspace->max().x() = 0.015;
  expect_unsafe(straight_path(), "waypoint 8: the pose (16.0, 0.0, 0.0) mm lies outside", g);
}

}  // namespace
}  // namespace groovetrace
