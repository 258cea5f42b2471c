// The V model's point distance (robust/vmodel.cpp): its analytic derivatives, which drive the
// cross-section fit, against central differences of the distance itself.
#include <gtest/gtest.h>

#include <random>

#include "robust/vmodel.hpp"

namespace groovetrace::robust_detail {
namespace {

VModel curved_v() {
  VModel m;
  m.q = {0.0005, 0.12, 3.0};  // a tilted, bent top (m, -, 1/m)
  m.root = {0.0008, -0.0045};
  m.u_left = -0.0042;
  m.u_right = 0.0061;
  return m;
}

TEST(RobustVModel, GradientMatchesCentralDifferencesOnEveryPiece) {
  const VModel m = curved_v();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.02, 0.02), v(-0.008, 0.006);
  const double h = 1e-8;  // m; the distance is piecewise smooth at this scale
  int checked[4] = {0, 0, 0, 0};
  for (int trial = 0; trial < 4000; ++trial) {
    const Eigen::Vector2d p(u(rng), v(rng));
    Vec6 grad;
    const auto [piece, d] = nearest_piece(p, m, &grad);
    EXPECT_DOUBLE_EQ(d, nearest_piece(p, m).second);
    Vec6 numeric;
    bool same_piece = true;
    for (int j = 0; j < 6; ++j) {
      auto shifted = [&](double dx) {
        VModel s = m;
        double* x[6] = {&s.root.x(), &s.root.y(), &s.u_left, &s.u_right, &s.q[0], &s.q[1]};
        *x[j] += dx;
        const auto r = nearest_piece(p, s);
        same_piece = same_piece && r.first == piece;
        return r.second;
      };
      numeric[j] = (shifted(h) - shifted(-h)) / (2 * h);
    }
    // Points within h of a piece boundary (or an end of a segment) have no derivative.
    if (!same_piece) continue;
    ++checked[piece];
    for (int j = 0; j < 6; ++j) {
      EXPECT_NEAR(grad[j], numeric[j], 1e-5 + 1e-5 * std::abs(numeric[j]))
          << "piece " << piece << " parameter " << j << " at (" << p.x() << ", " << p.y() << ")";
    }
  }
  for (int k = 0; k < 4; ++k) EXPECT_GT(checked[k], 50) << "piece " << k;
}

TEST(RobustVModel, DistanceIsSignedOutOfTheMaterial) {
  const VModel m = curved_v();
  // Above the root, inside the opening: positive; below a wall: negative; below the top: neg.
  EXPECT_GT(nearest_piece({0.0008, -0.002}, m).second, 0);
  EXPECT_LT(nearest_piece({-0.002, -0.004}, m).second, 0);
  EXPECT_LT(nearest_piece({-0.015, -0.003}, m).second, 0);
  EXPECT_EQ(nearest_piece({-0.015, -0.003}, m).first, 0);
  EXPECT_EQ(nearest_piece({0.015, 0.004}, m).first, 3);
}

}  // namespace
}  // namespace groovetrace::robust_detail
