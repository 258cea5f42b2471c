// Torch poses along a traced seam (robust/trajectory.cpp): arc-length spacing, slices, the
// travel direction convention, tool axis into the workpiece, continuous rotation vectors.
#include <gtest/gtest.h>

#include <cmath>
#include <groovetrace/robust.hpp>

namespace groovetrace {
namespace {

// A seam along a quarter circle (radius 50 mm, z = 0.4 m, camera looking along +z), traced
// from +y round to -x... so that its end lies at smaller x than its start.
SeamCandidate quarter_circle() {
  SeamCandidate s;
  for (int k = 0; k <= 100; ++k) {
    const double a = M_PI / 2 * k / 100;
    GrooveSection g;
    g.ok = true;
    g.root = Eigen::Vector3d(0.05 * std::cos(a), 0.05 * std::sin(a), 0.4);
    g.tangent = Eigen::Vector3d(-std::sin(a), std::cos(a), 0);
    g.normal = g.bisector = Eigen::Vector3d(0, 0, -1);  // towards the camera at the origin
    s.sections.push_back(g);
  }
  s.accepted = true;
  return s;
}

// Roots 1.5 mm apart that jitter 0.4 mm across a straight seam (a far 640x480 scan): the
// tool's x follows the seam's smoothed tangent, not the chord between neighbouring roots,
// which would swing by up to 28 deg.
TEST(RobustTrajectory, TravelAxisFollowsTheTangentNotTheRootJitter) {
  SeamCandidate s;
  for (int k = 0; k <= 100; ++k) {
    GrooveSection g;
    g.ok = true;
    g.root = Eigen::Vector3d(-0.075 + 0.0015 * k, (k % 2 ? 0.0002 : -0.0002), 0.4);
    g.tangent = Eigen::Vector3d(k % 3 ? 1 : -1, 0, 0);  // the sign carries no meaning
    g.normal = g.bisector = Eigen::Vector3d(0, 0, -1);
    s.sections.push_back(g);
  }
  s.accepted = true;
  RobustParams p;
  const Trajectory t = seam_trajectory(s, p);
  for (const Waypoint& w : t.waypoints) {
    const Eigen::Vector3d x = w.orientation.toRotationMatrix().col(0);
    EXPECT_GT(x.x(), std::cos(1.0 * M_PI / 180)) << "at " << w.position.transpose();
  }
}

TEST(RobustTrajectory, StepsAlongTheArcInTravelOrder) {
  const SeamCandidate s = quarter_circle();
  RobustParams p;
  p.step = 0.002;
  const Trajectory t = seam_trajectory(s, p);
  const double length = 0.05 * M_PI / 2;
  EXPECT_NEAR(t.length, length, 1e-4);
  EXPECT_EQ(t.waypoints.size(), static_cast<std::size_t>(std::ceil(length / 0.002)) + 1);
  // Travel ends at larger x than it starts: the seam was reversed.
  EXPECT_GT(t.waypoints.back().position.x(), t.waypoints.front().position.x());
  for (std::size_t k = 0; k < t.waypoints.size(); ++k) {
    const Waypoint& w = t.waypoints[k];
    EXPECT_NEAR(std::hypot(w.position.x(), w.position.y()), 0.05, 1e-4);
    const Eigen::Matrix3d R = w.orientation.toRotationMatrix();
    EXPECT_GT(R.col(2).dot(Eigen::Vector3d(0, 0, 1)), 0.9999);  // into the workpiece
    if (k == 0) continue;
    const Eigen::Vector3d step = w.position - t.waypoints[k - 1].position;
    EXPECT_LE(step.norm(), 0.002 + 1e-9);
    EXPECT_GT(R.col(0).dot(step.normalized()), 0.99);  // tool x along the travel
    EXPECT_LT((w.rotation_vector - t.waypoints[k - 1].rotation_vector).norm(), 0.1);
  }
}

TEST(RobustTrajectory, SlicesGiveThatManyWaypoints) {
  RobustParams p;
  p.slices = 30;
  EXPECT_EQ(seam_trajectory(quarter_circle(), p).waypoints.size(), 30u);
}

TEST(RobustTrajectory, ClosedSeamReturnsToItsStart) {
  SeamCandidate s;
  for (int k = 0; k < 200; ++k) {
    const double a = 2 * M_PI * k / 200;
    GrooveSection g;
    g.ok = true;
    g.root = Eigen::Vector3d(0.04 * std::cos(a), 0.04 * std::sin(a), 0.4);
    g.tangent = Eigen::Vector3d(-std::sin(a), std::cos(a), 0);
    g.normal = g.bisector = Eigen::Vector3d(0, 0, -1);
    s.sections.push_back(g);
  }
  s.closed = true;
  s.accepted = true;
  const Trajectory t = seam_trajectory(s, RobustParams{});
  ASSERT_GT(t.waypoints.size(), 100u);
  EXPECT_LT((t.waypoints.front().position - t.waypoints.back().position).norm(), 1e-9);
  // Starts at the smallest x.
  EXPECT_NEAR(t.waypoints.front().position.x(), -0.04, 1e-4);
}

// The arc length along the trajectory of its waypoint nearest to p (m).
double path_arc_at(const Trajectory& t, const Eigen::Vector3d& p) {
  double arc = 0, best_arc = 0, best = INFINITY;
  for (std::size_t k = 0; k < t.waypoints.size(); ++k) {
    if (k > 0) arc += (t.waypoints[k].position - t.waypoints[k - 1].position).norm();
    const double d = (t.waypoints[k].position - p).norm();
    if (d < best) {
      best = d;
      best_arc = arc;
    }
  }
  return best_arc;
}

// report.json counts stations and tacks along the path (travel_arc): an open seam traced
// against the travel and a ring whose sections run clockwise about its normal (the path runs
// the other way) from a point that is not its path's start both map onto the waypoints' arc length,
// within the 2 mm step.
TEST(RobustTrajectory, TravelArcCountsAlongThePath) {
  SeamCandidate open = quarter_circle();
  for (std::size_t k = 0; k < open.sections.size(); ++k) open.sections[k].s = 0.05 * M_PI / 200 * k;
  const Trajectory t_open = seam_trajectory(open, RobustParams{});
  for (std::size_t k = 0; k < open.sections.size(); k += 10) {
    const GrooveSection& g = open.sections[k];
    EXPECT_NEAR(travel_arc(open, g.s), path_arc_at(t_open, g.root), 0.0011) << k;
  }
  SeamCandidate ring;
  const double radius = 0.04, length = 2 * M_PI * radius;
  for (int k = 0; k < 200; ++k) {
    const double a = 1.0 + 2 * M_PI * k / 200;  // from 1 rad, clockwise about the normal
    GrooveSection g;
    g.ok = true;
    g.root = Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), 0.4);
    g.tangent = Eigen::Vector3d(-std::sin(a), std::cos(a), 0);
    g.normal = g.bisector = Eigen::Vector3d(0, 0, -1);
    g.s = length * k / 200;
    ring.sections.push_back(g);
  }
  ring.closed = ring.curve.closed = true;
  ring.curve.length = ring.length = length;
  ring.accepted = true;
  const Trajectory t_ring = seam_trajectory(ring, RobustParams{});
  for (int k = 0; k < 200; k += 10) {
    const GrooveSection& g = ring.sections[k];
    const double along = travel_arc(ring, g.s);
    EXPECT_GE(along, 0.0);
    EXPECT_LT(along, length);
    const double d = std::abs(along - path_arc_at(t_ring, g.root));
    EXPECT_LT(std::min(d, length - d), 0.0011) << k;
  }
}

// An L: 60 mm along +x, a 90 deg corner at the origin, 60 mm along +y; sections every 1.5 mm,
// the bisector tilted 10 deg across the first leg. Tangent signs carry no meaning.
SeamCandidate l_corner() {
  SeamCandidate s;
  const Eigen::Vector3d up(0, std::sin(10 * M_PI / 180), -std::cos(10 * M_PI / 180));
  for (int k = -40; k <= 40; ++k) {
    GrooveSection g;
    g.ok = true;
    const double d = 0.0015 * std::abs(k);
    g.root = k <= 0 ? Eigen::Vector3d(-d, 0, 0.4) : Eigen::Vector3d(0, d, 0.4);
    g.tangent = Eigen::Vector3d(k <= 0 ? 1 : 0, k <= 0 ? 0 : 1, 0) * (k % 3 ? 1 : -1);
    g.normal = g.bisector = k <= 0 ? up : Eigen::Vector3d(0, 0, -1);
    s.sections.push_back(g);
  }
  s.accepted = true;
  return s;
}

// Through a corner the torch turns over the blend length (orientation_blend), at no more than
// 1.5 times 90 deg / blend per millimetre; without blending it turns within one step. The
// positions do not change.
TEST(RobustTrajectory, OrientationTurnsThroughACornerOverTheBlendLength) {
  RobustParams p;
  for (double blend : {0.01, 0.025, 0.05}) {
    SCOPED_TRACE(blend);
    p.orientation_blend = blend;
    const Trajectory t = seam_trajectory(l_corner(), p);
    const RotationRate r = max_rotation_rate(t);
    EXPECT_LE(r.deg_per_mm, 1.5 * 90.0 / (1000 * blend));
    EXPECT_NEAR(r.at_m, 0.06, 0.5 * blend);
    // The whole turn still happens: tool x along each leg at the ends, z into the workpiece.
    const Eigen::Matrix3d R0 = t.waypoints.front().orientation.toRotationMatrix();
    const Eigen::Matrix3d R1 = t.waypoints.back().orientation.toRotationMatrix();
    EXPECT_GT(R0.col(0).x(), 0.9999);
    EXPECT_GT(R1.col(0).y(), 0.9999);
    for (const Waypoint& w : t.waypoints) {
      EXPECT_GT(w.orientation.toRotationMatrix().col(2).z(), 0.98);
    }
  }
  p.orientation_blend = 0;
  const Trajectory sharp = seam_trajectory(l_corner(), p);
  EXPECT_GT(max_rotation_rate(sharp).deg_per_mm, 20.0);
  p.orientation_blend = 0.025;
  const Trajectory blended = seam_trajectory(l_corner(), p);
  ASSERT_EQ(sharp.waypoints.size(), blended.waypoints.size());
  for (std::size_t k = 0; k < sharp.waypoints.size(); ++k) {
    EXPECT_EQ(sharp.waypoints[k].position, blended.waypoints[k].position) << k;
  }
}

// A straight seam with a constant (tilted) bisector keeps its orientation when blended.
TEST(RobustTrajectory, BlendingLeavesAStraightSeamsOrientation) {
  SeamCandidate s;
  const Eigen::Vector3d up = Eigen::Vector3d(0.1, 0.3, -1).normalized();
  for (int k = 0; k <= 100; ++k) {
    GrooveSection g;
    g.ok = true;
    g.root = Eigen::Vector3d(-0.075 + 0.0015 * k, 0.0, 0.4 + 0.0003 * k);
    g.tangent = Eigen::Vector3d(1, 0, 0.2).normalized() * (k % 3 ? 1 : -1);
    g.normal = g.bisector = up;
    s.sections.push_back(g);
  }
  s.accepted = true;
  RobustParams p;
  p.orientation_blend = 0;
  const Trajectory a = seam_trajectory(s, p);
  p.orientation_blend = 0.05;
  const Trajectory b = seam_trajectory(s, p);
  ASSERT_EQ(a.waypoints.size(), b.waypoints.size());
  for (std::size_t k = 0; k < a.waypoints.size(); ++k) {
    EXPECT_LT(a.waypoints[k].orientation.angularDistance(b.waypoints[k].orientation), 1e-9) << k;
    EXPECT_EQ(a.waypoints[k].position, b.waypoints[k].position) << k;
  }
  EXPECT_LT(max_rotation_rate(b).deg_per_mm, 1e-6);
}

// A straight seam whose first two sections read their bisector 20 deg off (a noisy seam end):
// near the end the blend window runs one-sided rather than shrinking to the end root alone,
// so the torch does not swing through those 20 deg within the first millimetre (it turned
// 18 deg/mm at a 640x480 seam's start).
TEST(RobustTrajectory, ANoisyEndDoesNotSwingTheTorch) {
  SeamCandidate s;
  const Eigen::Vector3d down(0, 0, -1);
  const Eigen::Vector3d off(0, std::sin(20 * M_PI / 180), -std::cos(20 * M_PI / 180));
  for (int k = 0; k <= 100; ++k) {
    GrooveSection g;
    g.ok = true;
    g.root = Eigen::Vector3d(-0.075 + 0.0015 * k, 0.0, 0.4);
    g.tangent = Eigen::Vector3d(1, 0, 0);
    g.normal = g.bisector = k < 2 ? off : down;
    s.sections.push_back(g);
  }
  s.accepted = true;
  const Trajectory t = seam_trajectory(s, RobustParams{});  // orientation_blend 25 mm
  EXPECT_LT(max_rotation_rate(t).deg_per_mm, 3.0);  // 1.1; 5.9 with the window shrunk to the end
}

// An L whose corner point lies 1 mm beyond the second leg (its lines and the first leg's meet
// there, its roots run 1 mm short of it): the path does not go out to the corner and back.
TEST(RobustTrajectory, ACornerThatFoldsBackIsCut) {
  SeamCandidate s = l_corner();
  for (GrooveSection& g : s.sections) {
    if (g.root.y() > 0) g.root.x() -= 0.001;
  }
  RobustParams p;
  const Trajectory t = seam_trajectory(s, p);
  for (std::size_t k = 1; k + 1 < t.waypoints.size(); ++k) {
    const Eigen::Vector3d a = t.waypoints[k].position - t.waypoints[k - 1].position;
    const Eigen::Vector3d b = t.waypoints[k + 1].position - t.waypoints[k].position;
    EXPECT_GT(a.dot(b), 0.0) << k;  // never back the way it came
  }
  p.orientation_blend = 0;
  p.depth_smooth = 0;  // the legs' tilted normals would lift the corner's roots
  const Trajectory sharp = seam_trajectory(s, p);
  // The corner point is dropped: from the first leg's last root straight to the second's first.
  EXPECT_NEAR(sharp.length, 2 * 0.0585 + std::hypot(0.0005, 0.0015), 1e-9);
}

// A straight seam along x (-150..150 mm every 1.5 mm), tool down the -z normal: each root at
// (x, across(x), 0.4 + up(x)) m, `depth(x)` m below the top.
template <class Across, class Up, class Depth>
SeamCandidate straight_seam(Across across, Up up, Depth depth) {
  SeamCandidate s;
  for (int k = 0; k <= 200; ++k) {
    GrooveSection g;
    g.ok = true;
    const double x = -0.15 + 0.0015 * k;
    g.root = Eigen::Vector3d(x, across(x), 0.4 + up(x));
    g.depth = depth(x);
    g.tangent = Eigen::Vector3d(1, 0, 0);
    g.normal = g.bisector = Eigen::Vector3d(0, 0, -1);
    s.sections.push_back(g);
  }
  s.accepted = true;
  return s;
}

// A flat straight seam whose roots wave up and down by +-0.5 mm (period 15 mm, a D415's
// undulation) comes out within +-0.1 mm; the waves across the seam stay (the path follows the
// sections across), and RobustParams::depth_smooth = 0 leaves the depth alone.
TEST(RobustTrajectory, DepthIsSmoothedAlongAFlatSeam) {
  const auto wave = [](double x) { return 0.0005 * std::sin(2 * M_PI * x / 0.015); };
  const SeamCandidate s =
      straight_seam([&](double x) { return 0.2 * wave(x); }, wave, [](double) { return 0.0; });
  RobustParams p;
  double inner = 0, across = 0, raw = 0;
  for (const Waypoint& w : seam_trajectory(s, p).waypoints) {
    if (std::abs(w.position.x()) < 0.1) inner = std::max(inner, std::abs(w.position.z() - 0.4));
    across = std::max(across, std::abs(w.position.y()));
  }
  p.depth_smooth = 0;
  for (const Waypoint& w : seam_trajectory(s, p).waypoints) {
    raw = std::max(raw, std::abs(w.position.z() - 0.4));
  }
  EXPECT_LT(inner, 0.0001);
  EXPECT_GT(across, 0.00009);
  EXPECT_GT(raw, 0.00045);
}

// Roots that wave by +-1.5 mm in 50 mm waves with the groove's depth while the top beside them
// stays flat (the roots where two steep walls fitted to a few image rows meet, the top from
// the wide surfaces beside them; the sweep's v16-90 s319 at 0.55 m, 640x480): the path takes
// the top less the groove's depth smoothed over 72 mm either side and comes out flat (0.11 mm
// off at worst). A corner joint's throat is taken alike (its roots' own heights, smoothed over
// +-24 mm as before, kept 1.38 mm of the waves). A top that does rise and fall, the groove as
// deep all along, is followed.
TEST(RobustTrajectory, GrooveDepthIsSmoothedLongerThanItsTop) {
  const auto inner_wave = [](const SeamCandidate& s) {
    double worst = 0;
    for (const Waypoint& w : seam_trajectory(s, RobustParams{}).waypoints) {
      if (std::abs(w.position.x()) < 0.1) worst = std::max(worst, std::abs(w.position.z() - 0.4));
    }
    return worst;
  };
  const auto wave = [](double x) { return 0.0015 * std::sin(2 * M_PI * x / 0.05); };
  // The top at z = 0.392 all along.
  SeamCandidate s =
      straight_seam([](double) { return 0.0; }, wave, [&](double x) { return 0.008 + wave(x); });
  EXPECT_LT(inner_wave(s), 0.0002);
  s.corner = true;
  EXPECT_LT(inner_wave(s), 0.0002);
  const auto swell = [](double x) { return 0.0015 * std::sin(2 * M_PI * x / 0.15); };
  EXPECT_GT(
      inner_wave(straight_seam([](double) { return 0.0; }, swell, [](double) { return 0.008; })),
      0.0012);
}

// A tack weld fills 15 mm of a flat seam (x in 0..15 mm): its stations' own fits failed
// (`filled`), and the roots smoothing gave them from the tack's flanks, which still pass as
// shallower V's (1 mm high, 7 mm deep, 3 mm either side), lie 2 mm high with the seam's 8 mm
// depth under them: a top 2 mm above the part's (the sweep's tacks s352: the path 1.2-1.8 mm
// over each tack). The stations on the seam's reported tack (flanks included) give neither
// top nor depth: the path stays on the root line through it.
TEST(RobustTrajectory, APathStaysOnTheRootThroughATack) {
  const auto tack = [](double x) { return x >= 0 && x < 0.015; };
  const auto flank = [&](double x) { return !tack(x) && x >= -0.003 && x < 0.018; };
  SeamCandidate s = straight_seam([](double) { return 0.0; },
                                  [&](double x) {
                                    return tack(x) ? -0.002 : flank(x) ? -0.001 : 0.0;
                                  },
                                  [&](double x) { return flank(x) ? 0.007 : 0.008; });
  for (GrooveSection& g : s.sections) {
    g.s = g.root.x() + 0.15;
    if (tack(g.root.x())) g.ok = false, g.filled = true;
  }
  const auto worst = [](const SeamCandidate& seam) {
    double w = 0;
    for (const Waypoint& p : seam_trajectory(seam, RobustParams{}).waypoints)
      w = std::max(w, std::abs(p.position.z() - 0.4));
    return w;
  };
  EXPECT_GT(worst(s), 0.0015);  // as long as no tack is reported there
  s.tacks.push_back({0.15 + 0.0075, 0.021});
  EXPECT_LT(worst(s), 0.0002);
}

// A seam that curves in depth (half a ring of radius 50 mm round a pipe, the normal radial)
// keeps its shape: the quadratic follows the curvature.
TEST(RobustTrajectory, DepthSmoothingFollowsAPipe) {
  SeamCandidate s;
  for (int k = 0; k <= 100; ++k) {
    const double a = M_PI * k / 100;
    GrooveSection g;
    g.ok = true;
    const Eigen::Vector3d radial(-std::cos(a), 0, -std::sin(a));
    g.root = Eigen::Vector3d(0, 0, 0.45) + 0.05 * radial;
    g.tangent = Eigen::Vector3d(std::sin(a), 0, -std::cos(a));
    g.normal = g.bisector = radial;
    s.sections.push_back(g);
  }
  s.accepted = true;
  for (const Waypoint& w : seam_trajectory(s, RobustParams{}).waypoints) {
    EXPECT_NEAR((w.position - Eigen::Vector3d(0, 0, 0.45)).norm(), 0.05, 0.00005);
  }
}

TEST(RobustTrajectory, TooShortSeamThrowsNoGroove) {
  SeamCandidate s;
  s.sections.resize(1);
  EXPECT_THROW(seam_trajectory(s, RobustParams{}), std::exception);
}

}  // namespace
}  // namespace groovetrace
