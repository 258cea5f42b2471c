// Seams as ordered curves (robust/node_order.cpp, robust/curve.cpp): order along the seam's own
// curve, rings closed, L-corners kept, parallel seams apart.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "robust/context.hpp"
#include "robust/stages.hpp"

namespace groovetrace {
namespace {

struct Nodes {
  std::vector<Eigen::Vector3d> points, tangents;
  std::vector<double> arc;  // true arc length of each node
};

// Nodes every ~1 mm along a polyline (m), shuffled, with lateral jitter.
Nodes sample(const std::vector<Eigen::Vector3d>& poly, bool closed, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, jitter);
  Nodes n;
  double s0 = 0;
  const std::size_t m = poly.size();
  for (std::size_t k = 0; k + 1 < m + (closed ? 1 : 0); ++k) {
    const Eigen::Vector3d a = poly[k], b = poly[(k + 1) % m];
    const double len = (b - a).norm();
    const Eigen::Vector3d t = (b - a) / len;
    for (double s = 0; s < len; s += 0.001) {
      n.points.push_back(a + s * t + Eigen::Vector3d(gauss(rng), gauss(rng), 0));
      n.tangents.push_back(t);
      n.arc.push_back(s0 + s);
    }
    s0 += len;
  }
  std::vector<std::size_t> order(n.points.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::shuffle(order.begin(), order.end(), rng);
  Nodes out;
  for (std::size_t k : order) {
    out.points.push_back(n.points[k]);
    out.tangents.push_back(n.tangents[k]);
    out.arc.push_back(n.arc[k]);
  }
  return out;
}

TEST(RobustSeamGraph, LCornerComesOutInOrder) {
  const Nodes n = sample({{-0.06, 0, 0}, {0.03, 0, 0}, {0.03, 0.08, 0}}, false, 0.0002, 1);
  const auto paths = order_nodes(n.points, n.tangents, 0.015, 5);
  ASSERT_EQ(paths.size(), 1u);
  const NodePath& p = paths[0];
  EXPECT_FALSE(p.closed);
  EXPECT_GT(p.nodes.size(), 0.9 * n.points.size());
  // Monotonic in the true arc length (either way), no back-and-forth beyond the jitter.
  const double sign = n.arc[p.nodes.back()] > n.arc[p.nodes.front()] ? 1.0 : -1.0;
  int reversals = 0;
  for (std::size_t k = 1; k < p.nodes.size(); ++k) {
    if (sign * (n.arc[p.nodes[k]] - n.arc[p.nodes[k - 1]]) < -0.002) ++reversals;
  }
  EXPECT_EQ(reversals, 0);

  // The smoothed curve keeps the corner where the legs meet.
  std::vector<Eigen::Vector3d> ordered;
  for (int v : p.nodes) ordered.push_back(n.points[v]);
  const SeamCurve c = smooth_curve(ordered, false, 0.006, 0.0015);
  ASSERT_EQ(c.corners.size(), 1u);
  EXPECT_NEAR(c.length, 0.17, 0.004);
  double nearest = INFINITY;
  for (const auto& q : c.points)
    nearest = std::min(nearest, (q - Eigen::Vector3d(0.03, 0, 0)).norm());
  EXPECT_LT(nearest, 0.001);
}

TEST(RobustSeamGraph, RingIsClosed) {
  std::vector<Eigen::Vector3d> circle;
  for (int k = 0; k < 120; ++k) {
    const double a = 2 * M_PI * k / 120;
    circle.emplace_back(0.04 * std::cos(a), 0.04 * std::sin(a), 0);
  }
  const Nodes n = sample(circle, true, 0.0002, 2);
  const auto paths = order_nodes(n.points, n.tangents, 0.015, 5);
  ASSERT_EQ(paths.size(), 1u);
  EXPECT_TRUE(paths[0].closed);
  std::vector<Eigen::Vector3d> ordered;
  for (int v : paths[0].nodes) ordered.push_back(n.points[v]);
  const SeamCurve c = smooth_curve(ordered, true, 0.006, 0.0015);
  EXPECT_TRUE(c.closed);
  EXPECT_TRUE(c.corners.empty());
  EXPECT_NEAR(c.length, 2 * M_PI * 0.04, 0.003);
  for (const auto& q : c.points) EXPECT_NEAR(std::hypot(q.x(), q.y()), 0.04, 3e-4);
}

TEST(RobustSeamGraph, ParallelSeamsStayApartAndOpenSeamsOpen) {
  Nodes a = sample({{-0.1, -0.01, 0}, {0.1, -0.01, 0}}, false, 0.0002, 3);
  const Nodes b = sample({{-0.1, 0.01, 0}, {0.1, 0.01, 0}}, false, 0.0002, 4);
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  a.tangents.insert(a.tangents.end(), b.tangents.begin(), b.tangents.end());
  // 20 mm apart, a link of 15 mm reaches across: only along-seam links may join.
  const auto paths = order_nodes(a.points, a.tangents, 0.015, 5);
  ASSERT_EQ(paths.size(), 2u);
  for (const auto& p : paths) {
    EXPECT_FALSE(p.closed);
    double y = 0;
    for (int v : p.nodes) y += a.points[v].y();
    y /= static_cast<double>(p.nodes.size());
    for (int v : p.nodes) EXPECT_NEAR(a.points[v].y(), y, 0.002);
  }
}

TEST(RobustSeamGraph, SCurveIsSmoothWithoutCorners) {
  // Two tangent 60 mm arcs turning 60 deg each way.
  std::vector<Eigen::Vector3d> s;
  for (int k = 0; k <= 60; ++k) {
    const double a = M_PI / 3 * k / 60;
    s.emplace_back(0.06 * std::sin(a), 0.06 * (1 - std::cos(a)), 0);
  }
  const Eigen::Vector3d mid = s.back();
  for (int k = 1; k <= 60; ++k) {
    const double a = M_PI / 3 * k / 60;
    const Eigen::Vector3d off(0.06 * std::sin(a), -0.06 * (1 - std::cos(a)), 0);
    s.push_back(mid + Eigen::AngleAxisd(M_PI / 3, Eigen::Vector3d::UnitZ()) * off);
  }
  const Nodes n = sample(s, false, 0.0002, 5);
  const auto paths = order_nodes(n.points, n.tangents, 0.015, 5);
  ASSERT_EQ(paths.size(), 1u);
  std::vector<Eigen::Vector3d> ordered;
  for (int v : paths[0].nodes) ordered.push_back(n.points[v]);
  const SeamCurve c = smooth_curve(ordered, false, 0.006, 0.0015);
  EXPECT_TRUE(c.corners.empty());
  EXPECT_NEAR(c.length, 2 * 0.06 * M_PI / 3, 0.004);
}

// A straight seam whose node path makes one sharp excursion (a stray node cluster beside the
// seam, seen on far, tilted 640x480 scans): the chords turn at its tip, the legs do not, so
// there is no corner and the curve stays near the seam's line beyond the excursion.
TEST(RobustSeamGraph, ExcursionOfTheNodePathIsNotACorner) {
  std::vector<Eigen::Vector3d> ordered;
  for (double x = -0.1; x <= 0.1; x += 0.001) {
    ordered.emplace_back(x, 0.009 * std::max(0.0, 1 - std::abs(x) / 0.005), 0);
  }
  const SeamCurve c = smooth_curve(ordered, false, 0.006, 0.0015);
  EXPECT_TRUE(c.corners.empty());
  for (const auto& q : c.points) {
    if (std::abs(q.x()) > 0.02) {
      EXPECT_LT(std::abs(q.y()), 0.0005) << q.transpose();
    }
  }
}

// A straight seam read in two stretches 22 mm apart (a clamp beside it stopped the tracking),
// its roots every 1.5 mm scattered by 1.5 mm across and in depth, as at 640x480 and 0.55 m.
// Each stretch's end must still point at the other: the chord from the end to the root 10 mm
// in turned up to 33 deg there and kept a sweep scan's two stretches apart (robust/merge.cpp,
// end_direction); over these 20 draws it failed in 4.
TEST(RobustSeamGraph, NoisyStretchesOfOneSeamContinueEachOther) {
  auto stretch = [](double from, double to, std::mt19937& rng) {
    std::normal_distribution<double> scatter(0.0, 0.0015);
    SeamCandidate s;
    for (double x = from; x < to; x += 0.0015) {
      GrooveSection g;
      g.root = Eigen::Vector3d(x, scatter(rng), 0.5 + scatter(rng));
      s.sections.push_back(g);
    }
    return s;
  };
  for (unsigned seed = 0; seed < 20; ++seed) {
    std::mt19937 rng(seed);
    const SeamCandidate a = stretch(-0.15, -0.05, rng), b = stretch(-0.028, 0.1, rng);
    EXPECT_LT(robust_detail::collinear_gap(a, b), 0.03) << "seed " << seed;
    // A stretch beside, not ahead: 40 mm across the first one's end.
    SeamCandidate c = stretch(-0.04, 0.06, rng);
    for (auto& g : c.sections) g.root.y() += 0.04;
    EXPECT_EQ(robust_detail::collinear_gap(a, c), INFINITY) << "seed " << seed;
  }
}

// Past a clamp standing on the groove, a stretch too short to stand alone (12 mm, under
// min_length) is kept where it continues an accepted seam: in its line beyond an open end, of
// its width and depth, within 10 scales. Roots scatter by 0.3 mm as at 640x480 and 0.35 m.
TEST(RobustSeamGraph, AShortStretchBeyondAClampContinuesTheSeam) {
  std::mt19937 rng(7);
  std::normal_distribution<double> scatter(0.0, 0.0003);
  auto stretch = [&](double from, double to, double y, double width, const char* reason) {
    SeamCandidate s;
    for (double x = from; x < to; x += 0.0015) {
      GrooveSection g;
      g.root = Eigen::Vector3d(x, y + scatter(rng), 0.35 + scatter(rng));
      s.sections.push_back(g);
    }
    s.width = width;
    s.depth = 0.008;
    s.accepted = reason == nullptr;
    s.reason = reason ? reason : "";
    return s;
  };
  std::vector<SeamCandidate> seams;
  seams.push_back(stretch(-0.15, 0.05, 0, 0.010, nullptr));         // the seam, to a clamp
  seams.push_back(stretch(0.100, 0.112, 0, 0.009, kTooShort));      // beyond the clamp
  seams.push_back(stretch(-0.212, -0.2, 0, 0.011, kTooShort));      // beyond the other end
  seams.push_back(stretch(0.100, 0.112, 0.004, 0.010, kTooShort));  // 4 mm beside the line
  seams.push_back(stretch(0.100, 0.112, 0, 0.016, kTooShort));      // a wider groove
  seams.push_back(stretch(0.160, 0.172, 0, 0.010, kTooShort));      // 110 mm on: too far
  seams.push_back(stretch(-0.05, -0.038, 0, 0.010, kTooShort));     // on the seam, not beyond
  seams.push_back(stretch(0.100, 0.112, 0, 0.010, "width or opening varies along the seam"));
  robust_detail::accept_continuations(seams, 0.010);
  const bool expected[] = {true, true, true, false, false, false, false, false};
  for (std::size_t k = 0; k < seams.size(); ++k) EXPECT_EQ(seams[k].accepted, expected[k]) << k;
  EXPECT_TRUE(seams[1].reason.empty());
  EXPECT_EQ(seams[1].continues, 0);
  EXPECT_EQ(seams[0].continues, -1);
  EXPECT_EQ(seams[3].reason, kTooShort);
}

// A continuation is exported with the seam it continues and does not count against
// max_seams; one whose seam is not exported is not either.
TEST(RobustSeamGraph, AContinuationIsExportedWithItsSeam) {
  std::vector<SeamCandidate> seams(5);
  for (int k = 0; k < 5; ++k) {
    seams[k].id = 10 + k;
    seams[k].accepted = k < 4;
  }
  seams[2].continues = 10;  // of the best seam
  seams[3].continues = 11;  // of the second
  const std::vector<bool> one = exported_seams(seams, 1), two = exported_seams(seams, 2);
  EXPECT_EQ(one, std::vector<bool>({true, false, true, false, false}));
  EXPECT_EQ(two, std::vector<bool>({true, true, true, true, false}));
}

}  // namespace
}  // namespace groovetrace
