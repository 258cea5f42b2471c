// The analytic 3x3 eigen-solver against Eigen's iterative SelfAdjointEigenSolver.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <random>

#include "core/eigen3.hpp"

namespace groovetrace {
namespace {

// Checks A v = lambda v for each pair, orthonormality, ascending order and agreement of the
// eigenvalues with Eigen's solver, all relative to the matrix scale.
void expect_decomposition(const Eigen::Matrix3d& a, double tol) {
  const SymEigen3 e = eigen_sym3(a);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> ref(a);
  const double scale = std::max(1e-300, a.cwiseAbs().maxCoeff());
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(e.values(k), ref.eigenvalues()(k), tol * scale) << "value " << k << "\n" << a;
    const Eigen::Vector3d v = e.vectors.col(k);
    EXPECT_NEAR(v.norm(), 1.0, 1e-9);
    EXPECT_LE((a * v - e.values(k) * v).norm(), tol * scale) << "vector " << k << "\n" << a;
  }
  EXPECT_LE(e.values(0), e.values(1));
  EXPECT_LE(e.values(1), e.values(2));
  EXPECT_LE((e.vectors.transpose() * e.vectors - Eigen::Matrix3d::Identity()).norm(), 1e-9);
}

TEST(Eigen3, RandomSymmetricMatchesEigen) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int t = 0; t < 2000; ++t) {
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) m(r, c) = m(c, r) = u(rng);
    expect_decomposition(m, 1e-9);
  }
}

TEST(Eigen3, RandomCovariancesAtPointCloudScale) {
  // Covariances of millimetre-sized patches: entries around 1e-6 m^2, one direction flat.
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0, 1);
  for (int t = 0; t < 500; ++t) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    const Eigen::Vector3d axes(1e-3, 1e-3 * (0.2 + std::abs(g(rng))), 1e-6 * std::abs(g(rng)));
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    for (int k = 0; k < 50; ++k) {
      const Eigen::Vector3d p = r * axes.cwiseProduct(Eigen::Vector3d(g(rng), g(rng), g(rng)));
      m += p * p.transpose();
    }
    m /= 50;
    expect_decomposition(m, 1e-9);
    // The smallest eigenvector is the flat axis of the patch.
    EXPECT_GT(std::abs(smallest_eigenvector(m).dot(r.col(2))), 0.99);
  }
}

TEST(Eigen3, DegenerateMatrices) {
  expect_decomposition(Eigen::Matrix3d::Zero(), 1e-12);
  expect_decomposition(Eigen::Matrix3d::Identity() * 3.5, 1e-12);
  expect_decomposition(Eigen::Vector3d(1, 1, 2).asDiagonal(), 1e-12);  // double eigenvalue
  expect_decomposition(Eigen::Vector3d(1, 2, 2).asDiagonal(), 1e-12);
  expect_decomposition(Eigen::Vector3d(0, 0, 1).asDiagonal(), 1e-12);  // rank 1
  expect_decomposition(Eigen::Vector3d(1e-20, 1, 1e20).asDiagonal(), 1e-9);
  // A rank-1 matrix in a rotated basis: n n^T.
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 3).normalized();
  expect_decomposition(n * n.transpose(), 1e-9);
  // Rank 2: a perfect plane's covariance; its smallest eigenvector is the plane normal.
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  const Eigen::Matrix3d plane = a * a.transpose() + 0.5 * b * b.transpose();
  expect_decomposition(plane, 1e-9);
  EXPECT_NEAR(std::abs(smallest_eigenvector(plane).dot(n)), 1.0, 1e-9);
  // Nearly repeated eigenvalues.
  expect_decomposition(Eigen::Vector3d(1, 1 + 1e-12, 2).asDiagonal(), 1e-9);
}

TEST(Eigen3, RotatedDegenerateMatrices) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  const std::vector<Eigen::Vector3d> spectra = {{1, 1, 1}, {0, 1, 1},    {0, 0, 1},
                                                {2, 2, 5}, {1e-8, 1, 1}, {0, 0, 0}};
  for (const auto& s : spectra) {
    for (int t = 0; t < 100; ++t) {
      const Eigen::Matrix3d r =
          Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
      expect_decomposition(r * s.asDiagonal() * r.transpose(), 1e-9);
    }
  }
}

}  // namespace
}  // namespace groovetrace
