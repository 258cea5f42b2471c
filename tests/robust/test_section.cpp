// The V model fitted across a seam (robust/v_profile.cpp, robust/section.cpp): root estimation
// against analytic V profiles, and the shapes that are not V-grooves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "robust/stages.hpp"

namespace groovetrace {
namespace {

// Profile samples (u across, v up; m) of a V whose walls dip `left_deg` / `right_deg` below a
// flat top at v = 0, root at (root_u, -depth), every `pitch` m in u over +-20 mm, `rows`
// times, with Gaussian noise in v.
std::vector<Eigen::Vector2d> v_profile(double depth, double left_deg, double right_deg,
                                       double root_u, double noise, unsigned seed,
                                       double pitch = 0.0008, int rows = 4) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double ul = root_u - depth / std::tan(left_deg * M_PI / 180);
  const double ur = root_u + depth / std::tan(right_deg * M_PI / 180);
  std::vector<Eigen::Vector2d> pts;
  for (int r = 0; r < rows; ++r) {
    for (double u = -0.02 + 0.25 * r * pitch; u <= 0.02; u += pitch) {
      double v = 0.0;
      if (u > ul && u <= root_u) v = -depth * (u - ul) / (root_u - ul);
      if (u > root_u && u < ur) v = -depth * (ur - u) / (ur - root_u);
      pts.emplace_back(u, v + noise * gauss(rng));
    }
  }
  return pts;
}

TEST(RobustSection, RootOfANoiseFreeVIsTheWallsIntersection) {
  const VProfile f = fit_v_profile(v_profile(0.008, 60, 60, 0.0, 0.0, 1), 0.02);
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_NEAR(f.root.x(), 0.0, 1e-5);
  EXPECT_NEAR(f.root.y(), -0.008, 1e-5);
  const double half = 0.008 / std::tan(M_PI / 3);
  EXPECT_NEAR(f.edge_left.x(), -half, 1e-5);
  EXPECT_NEAR(f.edge_right.x(), half, 1e-5);
  EXPECT_NEAR(f.opening_deg, 60.0, 0.1);
  EXPECT_NEAR(f.depth, 0.008, 1e-5);
  EXPECT_NEAR(f.bisector.y(), 1.0, 1e-6);  // symmetric: straight up, out of the groove
  EXPECT_FALSE(f.one_wall);
}

TEST(RobustSection, NoisyRootStaysOnTheAnalyticRoot) {
  // D415-like noise at 0.5 m (0.5 mm rms) over several seeds: the root stays within a few
  // tenths of a millimetre, the opening within a few degrees.
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const VProfile f = fit_v_profile(v_profile(0.008, 60, 60, 0.001, 0.0005, seed), 0.02);
    ASSERT_TRUE(f.ok) << f.why << " seed " << seed;
    EXPECT_NEAR(f.root.x(), 0.001, 3e-4) << seed;
    EXPECT_NEAR(f.root.y(), -0.008, 6e-4) << seed;
    EXPECT_NEAR(f.opening_deg, 60.0, 6.0) << seed;
    EXPECT_NEAR(f.width, 2 * 0.008 / std::tan(M_PI / 3), 8e-4) << seed;
  }
}

TEST(RobustSection, AsymmetricVHasItsOwnBisector) {
  // A V with walls at 45 and 75 deg: the bisector of the wall directions leans towards the
  // gentler (left) wall by half the difference, (75 - 45) / 2 = 15 deg from the top normal.
  const VProfile f = fit_v_profile(v_profile(0.006, 45, 75, 0.0, 0.0, 1), 0.02);
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_NEAR(f.root.x(), 0.0, 1e-5);
  EXPECT_NEAR(f.root.y(), -0.006, 1e-5);
  EXPECT_NEAR(f.wall_left_deg, 45.0, 0.1);
  EXPECT_NEAR(f.wall_right_deg, 75.0, 0.1);
  EXPECT_NEAR(std::atan2(f.bisector.x(), f.bisector.y()) * 180 / M_PI, -15.0, 0.2);
}

TEST(RobustSection, RoundedRimsAndRootGapDoNotPullTheRoot) {
  // What stereo matching and the root gap do: rims rounded over 0.8 mm, a 0.5 mm gap at the
  // root seen down to 2 mm deeper. The fit ignores points near the three vertices.
  std::vector<Eigen::Vector2d> pts = v_profile(0.008, 60, 60, 0.0, 0.0, 1);
  const double half = 0.008 / std::tan(M_PI / 3);
  for (auto& p : pts) {
    const double d = std::abs(std::abs(p.x()) - half);
    if (d < 0.0008) p.y() -= 0.0003 * (1 - d / 0.0008);  // rounded rim
    if (std::abs(p.x()) < 0.00025) p.y() = -0.010;       // the gap shows the table
  }
  const VProfile f = fit_v_profile(pts, 0.02);
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_NEAR(f.root.x(), 0.0, 5e-5);
  EXPECT_NEAR(f.root.y(), -0.008, 1e-4);
  EXPECT_NEAR(f.width, 2 * half, 2e-4);
}

// A 60 deg V whose walls end at root faces `gap` apart at 8 mm depth, the table seen 3 mm
// below them through the slot, straight down, with `noise` (m rms) in v.
std::vector<Eigen::Vector2d> gapped_v_profile(double gap, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double depth = 0.008, run = depth * std::tan(M_PI / 6);
  std::vector<Eigen::Vector2d> pts;
  for (int r = 0; r < 4; ++r) {
    for (double u = -0.02 + 0.0001 * r; u <= 0.02; u += 0.0004) {
      const double a = std::abs(u) - 0.5 * gap;  // into the wall from its root face
      const double v = a < 0 ? -depth - 0.003 : a < run ? -depth * (1 - a / run) : 0.0;
      pts.emplace_back(u, v + noise * gauss(rng));
    }
  }
  return pts;
}

TEST(RobustSection, RootGapIsMeasuredFromTheSlot) {
  // Seen straight down, a 2 mm slot is 20 samples of the table: measured within 0.6 mm (the
  // noise puts 2-3 % of the walls' samples below the 2-sigma band, a few tenths of a mm), and
  // on a seam known to have a gap the table's points do not pull the walls (the root stays
  // where they meet; the seam lifts it to the root faces, trace.cpp). A sharp V reads none.
  VFit seam_with_gap;
  seam_with_gap.root_gap = true;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const VProfile g = fit_v_profile(gapped_v_profile(0.002, 0.0002, seed), 0.02, seam_with_gap);
    ASSERT_TRUE(g.ok) << g.why;
    EXPECT_NEAR(g.gap, 0.002, 0.0006) << seed;
    const double walls_meet = -0.008 - 0.001 / std::tan(M_PI / 6);
    EXPECT_NEAR(g.root.y(), walls_meet, 3e-4) << seed;
    const VProfile v = fit_v_profile(gapped_v_profile(0.0, 0.0002, seed), 0.02);
    ASSERT_TRUE(v.ok) << v.why;
    EXPECT_LT(v.gap, 1e-4) << seed;
  }
}

TEST(RobustSection, RootGapSlotIsNotAFloor) {
  // The floor test (VProfile::inside: points inside the walls away from the root) leaves out
  // a 2 mm root gap's slot, where the table shows below the walls beside the root, and a clean
  // V has nothing there; a channel's floor between a plate and a bar is what it counts.
  VFit seam_with_gap;
  seam_with_gap.root_gap = true;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    for (const VFit& mode : {VFit{}, seam_with_gap}) {
      const VProfile g = fit_v_profile(gapped_v_profile(0.002, 0.0002, seed), 0.02, mode);
      ASSERT_TRUE(g.ok) << g.why;
      EXPECT_LT(g.inside, 0.02) << seed;
    }
    const VProfile v = fit_v_profile(v_profile(0.008, 60, 60, 0.0, 0.0003, seed), 0.02);
    ASSERT_TRUE(v.ok) << v.why;
    EXPECT_LT(v.inside, 0.02) << seed;
  }
}

TEST(RobustSection, OneWallSeenKeepsTheOpeningAndRoot) {
  // The left wall of a 60 deg V returns nothing. Seen from 20 deg to the left it faces the
  // sensor at 80 deg incidence (grazing): the top ends at its rim, the V is taken symmetric.
  std::vector<Eigen::Vector2d> pts;
  const double half = 0.008 / std::tan(M_PI / 3);
  for (const auto& p : v_profile(0.008, 60, 60, 0.0, 0.0001, 3)) {
    if (p.x() > -half && p.x() < 0) continue;
    pts.push_back(p);
  }
  const double tilt = 20 * M_PI / 180;
  const VProfile f = fit_v_profile(pts, 0.02, {}, {-std::sin(tilt), std::cos(tilt)});
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_TRUE(f.one_wall);
  EXPECT_FALSE(f.square_side);
  EXPECT_NEAR(f.edge_right.x(), half, 3e-4);
  EXPECT_NEAR(f.edge_left.x(), -half, 8e-4);  // within a sample spacing
  EXPECT_NEAR(f.root.x(), 0.0, 5e-4);
  // Seen straight down, that wall would have faced the sensor at 60 deg, so its side would be
  // square - but then the seen wall would run on down to that side's foot, 16 mm deep, and it
  // ends at 8 mm: neither reading holds, and the section is not taken (its neighbours are).
  const VProfile above = fit_v_profile(pts, 0.02);
  EXPECT_FALSE(above.ok);
  EXPECT_FALSE(above.square_side);
}

// A 60 deg V (depth 8 mm, no root gap) in a flat top at v = 0, seen as a D415 640x480 sees it
// from 0.55 m with a tilt of 15 deg across the seam: rays from the sensor at (-0.142, 0.531) m,
// one image row every 1/502 rad, each row's point taken three times (a 3 mm slab holds ~3
// columns). The left wall faces away (75 deg incidence) and gets two rows. `blur`: stereo
// matching's 3-row average of disparity (1 / depth), which rounds the rims and the root.
std::vector<Eigen::Vector2d> slanted_v_profile(bool blur) {
  const double depth = 0.008, half = depth * std::tan(M_PI / 6);
  const Eigen::Vector2d eye(-0.142, 0.531);
  const Eigen::Vector2d axis = -eye.normalized();
  std::vector<double> range;
  std::vector<Eigen::Vector2d> dirs;
  for (int i = -18; i <= 18; ++i) {
    const double a = i / 502.0;
    const Eigen::Vector2d d(std::cos(a) * axis.x() - std::sin(a) * axis.y(),
                            std::sin(a) * axis.x() + std::cos(a) * axis.y());
    // First crossing of the ray with the top (v = 0) outside the groove, else a wall.
    double t = -eye.y() / d.y();
    const double u = eye.x() + t * d.x();
    if (std::abs(u) < half) {
      for (const double side : {-1.0, 1.0}) {
        // Wall from (side * half, 0) to (0, -depth): n.(p - root) = 0.
        const Eigen::Vector2d n(depth, -side * half), root(0, -depth);
        const double tw = n.dot(root - eye) / n.dot(d);
        const Eigen::Vector2d p = eye + tw * d;
        if (tw > 0 && side * p.x() >= 0 && side * p.x() <= half && p.y() <= 0) t = tw;
      }
    }
    dirs.push_back(d);
    range.push_back(t * d.dot(axis));  // depth along the optical axis
  }
  std::vector<Eigen::Vector2d> pts;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    double z = range[i];
    if (blur && i > 0 && i + 1 < dirs.size()) {
      z = 1 / (0.25 / range[i - 1] + 0.5 / range[i] + 0.25 / range[i + 1]);
    }
    const Eigen::Vector2d p = eye + (z / dirs[i].dot(axis)) * dirs[i];
    for (int k = 0; k < 3; ++k) pts.push_back(p);
  }
  return pts;
}

TEST(RobustSection, SymmetricFitKeepsTheGrazingWallsRim) {
  // Stereo matching pulls the grazing wall's lower row up into the groove (the root's rounding
  // reaches a whole row there); fitted freely from its two rows, that wall comes out several
  // degrees too flat, its rim ~0.4 mm out and the root ~0.2 mm towards the other wall. Fitted
  // as a symmetric V, the wall's slope comes from both walls.
  const double half = 0.008 * std::tan(M_PI / 6);
  const VProfile f = fit_v_profile(slanted_v_profile(true), 0.02, {true});
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_FALSE(f.one_wall);
  EXPECT_NEAR(f.edge_left.x(), -half, 1e-4);
  EXPECT_NEAR(f.edge_right.x(), half, 2e-4);
  EXPECT_NEAR(f.root.x(), 0.0, 1e-4);
  EXPECT_NEAR(f.wall_left_deg, f.wall_right_deg, 0.5);
  // The profile does show the bias: the free fit's grazing rim lies out by over 0.25 mm.
  const VProfile free_fit = fit_v_profile(slanted_v_profile(true), 0.02);
  ASSERT_TRUE(free_fit.ok) << free_fit.why;
  EXPECT_LT(free_fit.edge_left.x(), -half - 2.5e-4);
  // A symmetric V fitted either way: the same.
  const std::vector<Eigen::Vector2d> v = v_profile(0.008, 60, 60, 0.001, 0.0, 1);
  const VProfile free = fit_v_profile(v, 0.02), sym = fit_v_profile(v, 0.02, {true});
  ASSERT_TRUE(sym.ok) << sym.why;
  EXPECT_NEAR((sym.root - free.root).norm(), 0.0, 1e-5);
  EXPECT_NEAR(sym.edge_left.x(), free.edge_left.x(), 1e-5);
  EXPECT_NEAR(sym.edge_right.x(), free.edge_right.x(), 1e-5);
}

TEST(RobustSection, SquareSideUnseenFromAboveIsABevel) {
  // A single bevel seen straight down its square side: the vertical wall returns nothing, the
  // 45 deg wall is seen. Its mirror image would face the sensor at 45 deg and would have been
  // seen, so the hidden side is square and the root sits at its foot, not halfway up the
  // inclined wall (where a symmetric V would put it: 4 mm off at 8 mm depth).
  const double depth = 0.008;
  const VProfile f = fit_v_profile(v_profile(depth, 90, 45, 0.0, 0.0, 1), 0.02);
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_TRUE(f.one_wall);
  EXPECT_TRUE(f.square_side);
  EXPECT_NEAR(f.root.x(), 0.0, 2e-4);
  EXPECT_NEAR(f.root.y(), -depth, 2e-4);
  EXPECT_GT(f.wall_left_deg, 85.0);
  EXPECT_NEAR(f.wall_right_deg, 45.0, 1.0);
  // The joint's own bisector: 22.5 deg from the top normal, towards the inclined wall.
  EXPECT_NEAR(std::atan2(f.bisector.x(), f.bisector.y()) * 180 / M_PI, 22.5, 1.0);
}

// `pts` turned by `deg` about the origin (counter-clockwise in (u, v)).
std::vector<Eigen::Vector2d> turned(std::vector<Eigen::Vector2d> pts, double deg) {
  const Eigen::Rotation2Dd R(deg * M_PI / 180);
  for (auto& p : pts) p = R * p;
  return pts;
}

TEST(RobustSection, SquareSideInATiltedFrameKeepsItsFoot) {
  // The bevel above in a frame tilted 3 deg either way against its top (the crease stage's
  // normal, which the inclined wall tilts): the foot of the square side then lies up to
  // 0.4 mm outside its rim in u. On a seam known to be a bevel (VFit::square) the rim moves out
  // with it; that failed the profile (root outside the opening) for one sign of the tilt.
  const double depth = 0.008;
  VFit bevel;
  bevel.square = -1;
  for (double deg : {-3.0, 3.0}) {
    const Eigen::Rotation2Dd R(deg * M_PI / 180);
    const VProfile f = fit_v_profile(turned(v_profile(depth, 90, 45, 0.0, 0.0, 1), deg), 0.02,
                                     bevel, R * Eigen::Vector2d(0, 1));
    ASSERT_TRUE(f.ok) << f.why << " tilt " << deg;
    EXPECT_TRUE(f.square_side) << deg;
    EXPECT_NEAR((f.root - R * Eigen::Vector2d(0, -depth)).norm(), 0.0, 2e-4) << deg;
  }
}

TEST(RobustSection, BevelSeamFitsItsSquareWallStraightDown) {
  // A single bevel seen from its square side (both walls return points), with 0.4 mm noise.
  // Told the left side is square (VFit::square, from the seam's first pass), the fit holds
  // that wall at 90 deg and the bisector at the joint's own 22.5 deg.
  const double depth = 0.008;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::vector<Eigen::Vector2d> pts = v_profile(depth, 90, 45, 0.0, 0.0004, seed);
    std::mt19937 rng(seed + 100);
    std::normal_distribution<double> gauss(0.0, 0.0004);
    for (double v = -depth; v < 0; v += 0.0006) pts.emplace_back(gauss(rng), v);
    VFit bevel;
    bevel.square = -1;
    const VProfile f = fit_v_profile(pts, 0.02, bevel);
    ASSERT_TRUE(f.ok) << f.why << " seed " << seed;
    EXPECT_FALSE(f.one_wall) << seed;
    EXPECT_NEAR(f.wall_left_deg, 90.0, 0.5) << seed;
    EXPECT_NEAR(f.root.x(), 0.0, 3e-4) << seed;
    EXPECT_NEAR(f.root.y(), -depth, 6e-4) << seed;
    EXPECT_NEAR(std::atan2(f.bisector.x(), f.bisector.y()) * 180 / M_PI, 22.5, 2.0) << seed;
  }
}

TEST(RobustSection, BevelSideIsTheSteepWallsSide) {
  auto sections = [](double left_deg, double right_deg) {
    std::vector<GrooveSection> s(5);
    for (auto& g : s) {
      g.ok = true;
      g.wall_left_deg = left_deg;
      g.wall_right_deg = right_deg;
    }
    return s;
  };
  EXPECT_EQ(bevel_square_side(sections(89, 46)), -1);
  EXPECT_EQ(bevel_square_side(sections(44, 88)), 1);
  EXPECT_EQ(bevel_square_side(sections(62, 58)), 0);  // a V read with a slant
  EXPECT_EQ(bevel_square_side(sections(80, 70)), 0);  // steep, but the walls dip alike
  std::vector<GrooveSection> two = sections(89, 46);
  two.resize(2);
  EXPECT_EQ(bevel_square_side(two), 0);  // too few sections to tell
}

TEST(RobustSection, HighLowPlatesReportTheirMisalignment) {
  // The right plate 1.5 mm higher than the left; both walls dip 60 deg to a root 8 mm below
  // the left top.
  const double depth = 0.008, rise = 0.0015, k = 1 / std::tan(M_PI / 3);
  const double ul = -depth * k, ur = (depth + rise) * k;
  std::vector<Eigen::Vector2d> pts;
  for (int row = 0; row < 4; ++row) {
    for (double u = -0.02 + 0.0002 * row; u <= 0.02; u += 0.0008) {
      double v = u < ul ? 0.0 : u > ur ? rise : u <= 0 ? -depth * (u - ul) / -ul : -depth + u / k;
      pts.emplace_back(u, v);
    }
  }
  const VProfile f = fit_v_profile(pts, 0.02);
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_NEAR(f.misalignment, rise, 2e-4);
  // One top line through both sides tilts by about the step over the window's half: the
  // torch would lean 2-3 deg. Fitted with the step (a seam found high-low), the tops are
  // level, and the edges lie on their own tops.
  EXPECT_GT(std::abs(f.top[1]), 0.03);
  VFit stepped;
  stepped.stepped = true;
  const VProfile g = fit_v_profile(pts, 0.02, stepped);
  ASSERT_TRUE(g.ok) << g.why;
  EXPECT_NEAR(g.top[1], 0.0, 1e-3);
  EXPECT_NEAR(g.root.x(), 0.0, 1e-4);
  EXPECT_NEAR(g.root.y(), -depth, 1e-4);
  EXPECT_NEAR(g.edge_left.x(), ul, 1e-4);
  EXPECT_NEAR(g.edge_right.x(), ur, 1e-4);
  EXPECT_NEAR(g.edge_right.y(), rise, 1e-4);
  EXPECT_NEAR(g.opening_deg, 60.0, 0.2);
  // With the seam's step held (VFit::step) rather than the station's own, the same.
  stepped.step = rise;
  const VProfile h = fit_v_profile(pts, 0.02, stepped);
  ASSERT_TRUE(h.ok) << h.why;
  EXPECT_NEAR(h.top[1], 0.0, 1e-3);
  EXPECT_NEAR(h.edge_right.y(), rise, 1e-4);
}

// The same high-low V with 0.3 mm noise and tops waving by +-0.1 mm over 12 mm: the step read
// from the tops beyond the edges (misalignment) errs by 0.18 mm mean, the outer half's lines'
// (outer_step) by 0.29 mm; the parallel plates' median bend is 0, and a right top bending away
// (a curved part's far side at a slant) reads its bend. Waves of 0.2 mm bring the two steps
// level and of 0.3 mm reverse them: the sweep's high-low scans showed the edges' step
// scattering a third less along the seam.
TEST(RobustSection, HighLowStepIsReadBeyondTheEdges) {
  const double depth = 0.008, rise = 0.0015, k = 1 / std::tan(M_PI / 3);
  const double ul = -depth * k, ur = (depth + rise) * k;
  const auto profile = [&](unsigned seed, double bend) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> gauss(0.0, 0.0003);
    std::uniform_real_distribution<double> phase(0.0, 2 * M_PI);
    const double ph = phase(rng);
    std::vector<Eigen::Vector2d> pts;
    for (int row = 0; row < 4; ++row) {
      for (double u = -0.02 + 0.0002 * row; u <= 0.02; u += 0.0008) {
        double v = u < ul ? 0.0 : u > ur ? rise : u <= 0 ? -depth * (u - ul) / -ul : -depth + u / k;
        if (u < ul || u > ur) v += 0.0001 * std::sin(2 * M_PI * u / 0.012 + ph);
        if (u > ur) v += bend * (u - ur);
        pts.emplace_back(u, v + gauss(rng));
      }
    }
    return pts;
  };
  // One station's bend swings with the waves; a seam's median of them does not.
  double err_edges = 0, err_outer = 0;
  std::vector<double> level_bend, bent_bend;
  for (unsigned seed = 1; seed <= 41; ++seed) {
    const VProfile f = fit_v_profile(profile(seed, 0.0), 0.02);
    const VProfile g = fit_v_profile(profile(seed, 0.08), 0.02);
    ASSERT_TRUE(f.ok && g.ok) << f.why << g.why;
    err_edges += std::abs(f.misalignment - rise);
    err_outer += std::abs(f.outer_step - rise);
    level_bend.push_back(f.top_bend);
    bent_bend.push_back(g.top_bend);
  }
  EXPECT_LT(err_edges, 0.8 * err_outer) << err_edges / 41 << " " << err_outer / 41;
  std::nth_element(level_bend.begin(), level_bend.begin() + 20, level_bend.end());
  std::nth_element(bent_bend.begin(), bent_bend.begin() + 20, bent_bend.end());
  EXPECT_NEAR(level_bend[20], 0.0, 0.01);
  EXPECT_NEAR(bent_bend[20], 0.08, 0.02);
}

TEST(RobustSection, CurvedTopOfAPipeIsNotAGroove) {
  // A V in a pipe's crown (radius 50 mm): the top is fitted as a curve, the root found.
  std::vector<Eigen::Vector2d> pts = v_profile(0.008, 60, 60, 0.0, 0.0, 1);
  for (auto& p : pts) p.y() -= p.x() * p.x() / (2 * 0.05);
  const VProfile f = fit_v_profile(pts, 0.02);
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_NEAR(f.root.x(), 0.0, 2e-4);
  EXPECT_NEAR(f.root.y(), -0.008, 4e-4);
}

TEST(RobustSection, ConvexEdgeStepAndFlatAreRejected) {
  // A ridge (an inverted V): nothing below the top.
  std::vector<Eigen::Vector2d> ridge = v_profile(0.008, 60, 60, 0.0, 0.0, 1);
  for (auto& p : ridge) p.y() = -p.y();
  EXPECT_FALSE(fit_v_profile(ridge, 0.02).ok);
  // A step down to a table (a part's edge): the two sides do not continue each other.
  std::vector<Eigen::Vector2d> step;
  for (double u = -0.02; u <= 0.02; u += 0.0005) step.emplace_back(u, u < 0.003 ? -0.010 : 0.0);
  EXPECT_FALSE(fit_v_profile(step, 0.02).ok);
  // A flat with noise.
  std::mt19937 rng(4);
  std::normal_distribution<double> gauss(0.0, 0.0005);
  std::vector<Eigen::Vector2d> flat;
  for (double u = -0.02; u <= 0.02; u += 0.0005) flat.emplace_back(u, gauss(rng));
  EXPECT_FALSE(fit_v_profile(flat, 0.02).ok);
  // Too few points.
  EXPECT_FALSE(fit_v_profile({{0, 0}, {0.001, 0}}, 0.02).ok);
}

TEST(RobustSection, SectionIn3DMapsTheProfileBack) {
  // A straight V along +y in a plate z = 0 (up = +z), sampled densely in 3-D.
  Cloud c;
  for (double y = -0.004; y <= 0.004; y += 0.0008) {
    for (const auto& p : v_profile(0.006, 60, 60, 0.002, 0.0, 1, 0.0008, 1)) {
      c.x.push_back(static_cast<float>(p.x()));
      c.y.push_back(static_cast<float>(y));
      c.z.push_back(static_cast<float>(p.y()));
    }
  }
  c.width = static_cast<std::uint32_t>(c.x.size());
  std::vector<std::uint32_t> all(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  const GrooveSection s = fit_section(c, all, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 1, 0),
                                      Eigen::Vector3d(0, 0, 1), 0.0015, 0.02);
  ASSERT_TRUE(s.ok) << s.why;
  EXPECT_NEAR((s.root - Eigen::Vector3d(0.002, 0, -0.006)).norm(), 0.0, 2e-5);
  EXPECT_NEAR(s.bisector.z(), 1.0, 1e-4);
  EXPECT_NEAR(s.normal.z(), 1.0, 1e-4);
  // across = normal x tangent = z x y = -x: u grows towards the right edge.
  EXPECT_GT((s.edge_right - s.edge_left).dot(s.across()), 0.0);
  EXPECT_NEAR(s.across().x(), -1.0, 1e-6);
}

TEST(RobustSection, ThinningDoesNotHangOnOnePointMore) {
  // A slab of ~1400 points (more than the fit takes): one point more at the far end of the
  // slab, outside the window, must not change which points the fit sees (every k-th point of
  // the list was a new subset each time the list grew by one).
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss(0.0, 0.0004);
  Cloud c;
  for (double y = -0.0015; y <= 0.0015; y += 0.0003) {
    for (const auto& p : v_profile(0.008, 60, 60, 0.001, 0.0, 1, 0.0003, 1)) {
      c.x.push_back(static_cast<float>(p.x()));
      c.y.push_back(static_cast<float>(y));
      c.z.push_back(static_cast<float>(p.y() + gauss(rng)));
    }
  }
  c.width = static_cast<std::uint32_t>(c.x.size());
  auto fit = [](const Cloud& cloud) {
    std::vector<std::uint32_t> all(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
    return fit_section(cloud, all, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 1, 0),
                       Eigen::Vector3d(0, 0, 1), 0.0015, 0.02);
  };
  const GrooveSection a = fit(c);
  ASSERT_GT(a.support, 1000);
  ASSERT_TRUE(a.ok) << a.why;
  Cloud more = c;
  more.x.push_back(0.025f);  // beyond the window
  more.y.push_back(0.0f);
  more.z.push_back(0.0f);
  more.width = static_cast<std::uint32_t>(more.x.size());
  const GrooveSection b = fit(more);
  ASSERT_TRUE(b.ok) << b.why;
  EXPECT_LT((a.root - b.root).norm(), 1e-5);
}

}  // namespace
}  // namespace groovetrace
