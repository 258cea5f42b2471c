// Stations along a seam anchored to the frame (robust/stations.cpp): where a seam's curve
// starts must not move the stations along it.
#include <gtest/gtest.h>

#include <cmath>

#include "robust/stages.hpp"
#include "robust/stations.hpp"

namespace groovetrace {
namespace {

// Points every 1 mm along an arc of radius `radius` (m) in the plane z = 0.4, from angle a0 to
// a1 (rad).
std::vector<Eigen::Vector3d> arc(double radius, double a0, double a1) {
  std::vector<Eigen::Vector3d> pts;
  const int n = static_cast<int>(std::ceil(std::abs(a1 - a0) * radius / 0.001));
  for (int k = 0; k <= n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    pts.emplace_back(radius * std::cos(a), radius * std::sin(a) - radius, 0.4);
  }
  return pts;
}

// Distance from p to the nearest station of `c` (m).
double nearest(const SeamCurve& c, const Eigen::Vector3d& p) {
  double best = INFINITY;
  for (const auto& q : c.points) best = std::min(best, (q - p).norm());
  return best;
}

TEST(RobustStations, StartOfTheCurveDoesNotMoveThem) {
  // A gentle arc (0.3 m radius) over 200 mm, and the same arc starting 0.7 mm later.
  const double station = 0.0015;
  const auto a = arc(0.3, -0.35, 0.35), b = arc(0.3, -0.35 + 0.0007 / 0.3, 0.35);
  const SeamCurve ca = anchored_stations(smooth_curve(a, false, 0.006, 0.25 * station), station);
  const SeamCurve cb = anchored_stations(smooth_curve(b, false, 0.006, 0.25 * station), station);
  ASSERT_GT(ca.points.size(), 100u);
  // Away from the ends, every station of one is a station of the other.
  int inner = 0;
  for (std::size_t k = 0; k < cb.points.size(); ++k) {
    if (cb.s[k] < 0.02 || cb.s[k] > cb.length - 0.02) continue;
    ++inner;
    EXPECT_LT(nearest(ca, cb.points[k]), 2e-6) << k;
  }
  EXPECT_GT(inner, 80);
  // About a station apart, tangents along the arc.
  for (std::size_t k = 1; k < ca.points.size(); ++k) {
    EXPECT_LE((ca.points[k] - ca.points[k - 1]).norm(), station + 1e-6) << k;
    EXPECT_GT(ca.tangents[k].dot((ca.points[k] - ca.points[k - 1]).normalized()), 0.999) << k;
  }
}

TEST(RobustStations, RingStartDoesNotMoveThem) {
  // A ring of 50 mm radius, its nodes starting at two different places.
  const double station = 0.0015;
  auto ring = [](double a0) {
    auto pts = arc(0.05, a0, a0 + 2 * M_PI);
    pts.pop_back();  // the ring's end is its start
    return pts;
  };
  const SeamCurve ca =
      anchored_stations(smooth_curve(ring(0.0), true, 0.006, 0.25 * station), station);
  const SeamCurve cb =
      anchored_stations(smooth_curve(ring(1.0), true, 0.006, 0.25 * station), station);
  ASSERT_GT(ca.points.size(), 150u);
  for (const auto& p : cb.points) EXPECT_LT(nearest(ca, p), 2e-5);
}

}  // namespace
}  // namespace groovetrace
