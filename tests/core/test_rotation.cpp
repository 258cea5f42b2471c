// Rotation vectors: round trips against Eigen's AngleAxis, the ends of the angle range, and
// continuity of paths that pass through angle pi.

#include <gtest/gtest.h>

#include <cmath>
#include <groovetrace/rotation.hpp>
#include <random>

namespace {

using groovetrace::quaternion_from_rotation_vector;
using groovetrace::rotation_vector;
using groovetrace::rotation_vector_near;

constexpr double kPi = 3.14159265358979323846;

Eigen::Quaterniond random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  return q.normalized();
}

Eigen::Vector3d random_axis(std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
}

/// Angle (rad) of the rotation taking a to b; 0 when they are the same rotation.
double rotation_distance(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.normalized().angularDistance(b.normalized());
}

TEST(RotationVector, RandomRotationsMatchAngleAxisAndRoundTrip) {
  std::mt19937 rng(7);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Quaterniond q = random_rotation(rng);
    const Eigen::Vector3d rv = rotation_vector(q);
    EXPECT_LE(rv.norm(), kPi + 1e-12);
    const Eigen::AngleAxisd aa(q);  // Eigen's angle is in [0, pi] as well
    if (aa.angle() < kPi - 1e-6) {
      EXPECT_LT((rv - aa.angle() * aa.axis()).norm(), 1e-12) << "k=" << k;
    }
    EXPECT_LT(rotation_distance(quaternion_from_rotation_vector(rv), q), 1e-12) << "k=" << k;
  }
}

TEST(RotationVector, QuaternionFromVectorMatchesAngleAxisBeyondPi) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(0.0, 3.0 * kPi);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d axis = random_axis(rng);
    const double a = angle(rng);
    const Eigen::Quaterniond expected(Eigen::AngleAxisd(a, axis));
    EXPECT_LT(rotation_distance(quaternion_from_rotation_vector(a * axis), expected), 1e-12);
  }
  const Eigen::Quaterniond identity = quaternion_from_rotation_vector(Eigen::Vector3d::Zero());
  EXPECT_EQ(identity.w(), 1.0);
  EXPECT_EQ(identity.vec().norm(), 0.0);
}

TEST(RotationVector, EndsOfTheAngleRange) {
  std::mt19937 rng(3);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d axis = random_axis(rng);
    // Built by hand (not through AngleAxis) so the test owns the expected value.
    auto about_axis = [&](double angle) {
      Eigen::Quaterniond q;
      q.w() = std::cos(0.5 * angle);
      q.vec() = std::sin(0.5 * angle) * axis;
      return q;
    };
    EXPECT_EQ(rotation_vector(about_axis(0.0)).norm(), 0.0);
    // Tiny angles: the vector must keep its relative precision, not collapse to 0.
    for (double small : {1e-9, 1e-12, 1e-6}) {
      const Eigen::Vector3d rv = rotation_vector(about_axis(small));
      EXPECT_LT((rv - small * axis).norm(), 1e-10 * small) << small;
      EXPECT_LT((quaternion_from_rotation_vector(rv).vec() - about_axis(small).vec()).norm(),
                1e-10 * small);
    }
    const Eigen::Vector3d below = rotation_vector(about_axis(kPi - 1e-6));
    EXPECT_LT((below - (kPi - 1e-6) * axis).norm(), 1e-12);
    // At pi both signs of the axis are the principal vector.
    const Eigen::Vector3d at = rotation_vector(about_axis(kPi));
    EXPECT_NEAR(at.norm(), kPi, 1e-12);
    EXPECT_NEAR(std::abs(at.normalized().dot(axis)), 1.0, 1e-12);
    // Past pi (w < 0) the principal vector turns to the other axis sign, angle below pi.
    const Eigen::Vector3d beyond = rotation_vector(about_axis(kPi + 1e-6));
    EXPECT_LT((beyond - (-(kPi - 1e-6)) * axis).norm(), 1e-12);
    EXPECT_LT(rotation_distance(quaternion_from_rotation_vector(beyond), about_axis(kPi + 1e-6)),
              1e-12);
  }
}

TEST(RotationVector, NonUnitQuaternionIsNormalized) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()));
  Eigen::Quaterniond scaled = q;
  scaled.coeffs() *= 3.0;
  EXPECT_LT((rotation_vector(scaled) - 0.7 * Eigen::Vector3d::UnitY()).norm(), 1e-12);
  scaled.coeffs() *= -1.0;  // -q is the same rotation
  EXPECT_LT((rotation_vector(scaled) - 0.7 * Eigen::Vector3d::UnitY()).norm(), 1e-12);
}

TEST(RotationVectorNear, FixedAxisSweepThroughPiIsTheContinuousAngle) {
  std::mt19937 rng(5);
  const Eigen::Vector3d axis = random_axis(rng);
  const int steps = 400;
  const double from = kPi - 0.2, to = kPi + 0.2;
  const double step = (to - from) / steps;
  Eigen::Vector3d previous = rotation_vector(Eigen::Quaterniond(Eigen::AngleAxisd(from, axis)));
  for (int k = 1; k <= steps; ++k) {
    const double angle = from + k * step;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, axis));
    const Eigen::Vector3d rv = rotation_vector_near(q, previous);
    // Continuing the sweep beyond pi means |rv| > pi: axis * angle exactly.
    EXPECT_LT((rv - angle * axis).norm(), 1e-9) << "angle=" << angle;
    EXPECT_LT((rv - previous).norm(), step * (1.0 + 1e-6));
    EXPECT_LT(rotation_distance(quaternion_from_rotation_vector(rv), q), 1e-12);
    previous = rv;
  }
}

TEST(RotationVectorNear, HalfTurnsWithTurningAxisStayContinuous) {
  // A torch pointing straight down whose heading turns: Rz(psi) Rx(pi) is a half turn about a
  // turning horizontal axis, the case where the principal vector's sign is arbitrary.
  const int steps = 300;
  const double step = 1.0 / steps;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int k = 0; k <= steps; ++k) {
    const double psi = -0.5 + k * step;
    const Eigen::Quaterniond q = Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX());
    const Eigen::Vector3d rv = k == 0 ? rotation_vector(q) : rotation_vector_near(q, previous);
    EXPECT_NEAR(rv.norm(), kPi, 1e-9);
    EXPECT_LT(rotation_distance(quaternion_from_rotation_vector(rv), q), 1e-12);
    // The axis turns by psi / 2: the vector moves pi * step / 2 per step, never 2 pi.
    if (k > 0) {
      EXPECT_LT((rv - previous).norm(), 0.5 * kPi * step * (1.0 + 1e-6)) << k;
    }
    previous = rv;
  }
}

TEST(RotationVectorNear, RandomWalkNearPiHasNoJumps) {
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  const double sigma = 0.01;  // rad per step and axis
  Eigen::Quaterniond q(Eigen::AngleAxisd(kPi - 0.05, random_axis(rng)));
  Eigen::Vector3d previous = rotation_vector(q);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d delta(sigma * g(rng), sigma * g(rng), sigma * g(rng));
    q = (quaternion_from_rotation_vector(delta) * q).normalized();
    const Eigen::Vector3d rv = rotation_vector_near(q, previous);
    EXPECT_LT(rotation_distance(quaternion_from_rotation_vector(rv), q), 1e-12);
    // The map's stretch is at most about 3 for |rv| < 1.5 pi; a branch jump is about 2 pi.
    EXPECT_LT((rv - previous).norm(), 4.0 * delta.norm() + 1e-12) << "k=" << k;
    previous = rv;
  }
}

TEST(RotationVectorNear, IdentityAndPrincipalCases) {
  const Eigen::Quaterniond identity = Eigen::Quaterniond::Identity();
  EXPECT_EQ(rotation_vector_near(identity, Eigen::Vector3d::Zero()).norm(), 0.0);
  // Identity next to a vector of length near 2 pi: the 2 pi vector is the continuous one.
  const Eigen::Vector3d near_full_turn(0.0, 0.0, 2.0 * kPi - 0.01);
  const Eigen::Vector3d rv = rotation_vector_near(identity, near_full_turn);
  EXPECT_LT((rv - Eigen::Vector3d(0.0, 0.0, 2.0 * kPi)).norm(), 1e-12);
  // Small rotations stay principal.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  EXPECT_LT(
      (rotation_vector_near(q, Eigen::Vector3d(0.25, 0.0, 0.0)) - Eigen::Vector3d(0.3, 0.0, 0.0))
          .norm(),
      1e-12);
}

}  // namespace
