#pragma once
// Closed-form eigen-decomposition of symmetric 3x3 matrices (the covariance of a
// neighbourhood). Analytic so that the same arithmetic runs in the OpenCL kernels.

#include <Eigen/Core>

namespace groovetrace {

/// Eigenvalues in ascending order and the matching unit eigenvectors (columns).
struct SymEigen3 {
  Eigen::Vector3d values;
  Eigen::Matrix3d vectors;
};

/// Eigen-decomposition of a symmetric 3x3 matrix (only the upper triangle is read).
/// Robust for repeated and zero eigenvalues: returned vectors are always orthonormal.
SymEigen3 eigen_sym3(const Eigen::Matrix3d& m);

/// Unit eigenvector of the smallest eigenvalue (the plane normal of a covariance).
Eigen::Vector3d smallest_eigenvector(const Eigen::Matrix3d& m);

}  // namespace groovetrace
