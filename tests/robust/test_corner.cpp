// Corner joints (robust/corner_profile.cpp): fillet and lap profiles against their analytic
// corners, and what is not a corner.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "robust/stages.hpp"

namespace groovetrace {
namespace {

constexpr double kDeg = M_PI / 180;

// Unit direction at `deg` from +v towards +u.
Eigen::Vector2d dir_at(double deg) { return {std::sin(deg * kDeg), std::cos(deg * kDeg)}; }

// Samples every `pitch` m along the segment from a to b, `rows` times, with Gaussian noise of
// `noise` m across it.
void add_face(std::vector<Eigen::Vector2d>& pts, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
              double noise, std::mt19937& rng, double pitch = 0.0007, int rows = 3) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Eigen::Vector2d d = (b - a).normalized(), n(-d.y(), d.x());
  for (int r = 0; r < rows; ++r) {
    for (double t = (r + 0.5) * pitch / rows; t <= (b - a).norm(); t += pitch)
      pts.push_back(a + t * d + noise * gauss(rng) * n);
  }
}

// A concave corner at `root` whose faces leave it at `left_deg` and `right_deg` from +v
// (left negative), each `length` m long.
std::vector<Eigen::Vector2d> corner(const Eigen::Vector2d& root, double left_deg, double right_deg,
                                    double length, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Eigen::Vector2d> pts;
  add_face(pts, root, root + length * dir_at(left_deg), noise, rng);
  add_face(pts, root, root + length * dir_at(right_deg), noise, rng);
  return pts;
}

TEST(RobustCorner, FilletSeenDownItsBisectorHasItsRootAtTheCorner) {
  const VProfile f = fit_v_profile(corner({0.001, -0.002}, -45, 45, 0.03, 0.0, 1), 0.02);
  ASSERT_TRUE(f.ok) << f.why;
  EXPECT_TRUE(f.corner);
  EXPECT_FALSE(f.short_face);
  EXPECT_NEAR(f.root.x(), 0.001, 1e-5);
  EXPECT_NEAR(f.root.y(), -0.002, 1e-5);
  EXPECT_NEAR(f.opening_deg, 90.0, 0.1);
  EXPECT_NEAR(std::atan2(f.bisector.x(), f.bisector.y()) / kDeg, 0.0, 0.1);
  // The weld's legs (7 mm by default) on the faces; the throat is its depth.
  const double leg = 0.007;
  EXPECT_NEAR((f.edge_left - f.root).norm(), leg, 1e-6);
  EXPECT_NEAR((f.edge_right - f.root).norm(), leg, 1e-6);
  EXPECT_NEAR(f.width, leg * std::sqrt(2.0), 1e-5);
  EXPECT_NEAR(f.depth, leg / std::sqrt(2.0), 1e-5);
}

TEST(RobustCorner, NoisyTiltedCornerKeepsItsOwnBisector) {
  // Seen 20 deg off its bisector, faces 95 deg apart, 0.3 mm of noise.
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const VProfile f = fit_v_profile(corner({0, 0}, -30, 65, 0.03, 0.0003, seed), 0.02);
    ASSERT_TRUE(f.ok) << f.why;
    EXPECT_TRUE(f.corner);
    EXPECT_LT(f.root.norm(), 3e-4);
    EXPECT_NEAR(std::atan2(f.bisector.x(), f.bisector.y()) / kDeg, 17.5, 1.0);
    EXPECT_NEAR(f.opening_deg, 95.0, 1.5);
  }
}

TEST(RobustCorner, LapsUpperFaceEndsInsideTheWindow) {
  // The lower plate's top runs on; the upper plate's edge face is 10 mm high, then its top
  // runs parallel to the lower one.
  std::mt19937 rng(3);
  std::vector<Eigen::Vector2d> pts;
  const Eigen::Vector2d root(0, 0), up = 0.010 * dir_at(-45);
  add_face(pts, root, root + 0.03 * dir_at(45), 0.0002, rng);
  add_face(pts, root, root + up, 0.0002, rng);
  add_face(pts, root + up, root + up + 0.03 * dir_at(-135), 0.0002, rng);
  // In a 20 mm window the upper plate's top holds more points than its edge face.
  for (double half_window : {0.01, 0.02}) {
    SCOPED_TRACE(half_window);
    const VProfile f = fit_v_profile(pts, half_window);
    ASSERT_TRUE(f.ok) << f.why;
    EXPECT_TRUE(f.corner);
    EXPECT_TRUE(f.short_face);
    EXPECT_LT(f.root.norm(), 3e-4);
    EXPECT_NEAR(std::atan2(f.bisector.x(), f.bisector.y()) / kDeg, 0.0, 1.5);
  }
}

TEST(RobustCorner, FlatConvexAndWideAreNotCorners) {
  std::mt19937 rng(4);
  std::vector<Eigen::Vector2d> flat;
  add_face(flat, {-0.02, 0}, {0.02, 0}, 0.0002, rng);
  EXPECT_FALSE(fit_corner_profile(flat, 0.02, 0.007, {0, 1}).ok);
  // A roof: the faces run down from the apex.
  EXPECT_FALSE(
      fit_corner_profile(corner({0, 0}, -135, 135, 0.03, 0.0002, 5), 0.02, 0.007, {0, 1}).ok);
  // 150 deg: a wide V's walls, not a corner joint.
  EXPECT_FALSE(
      fit_corner_profile(corner({0, 0}, -75, 75, 0.03, 0.0002, 6), 0.02, 0.007, {0, 1}).ok);
  // A face shorter than the weld's leg.
  EXPECT_FALSE(fit_corner_profile(corner({0, 0}, -45, 45, 0.005, 0.0, 7), 0.02, 0.007, {0, 1}).ok);
}

TEST(RobustCorner, CornerSeenFromBehindIsRejected) {
  const VProfile f =
      fit_corner_profile(corner({0, 0}, -45, 45, 0.03, 0.0002, 8), 0.02, 0.007, {0, -1});
  EXPECT_FALSE(f.ok);
}

}  // namespace
}  // namespace groovetrace
