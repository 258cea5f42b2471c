// Closed-form symmetric 3x3 eigen-solver: trigonometric eigenvalues, then eigenvectors of
// the best separated eigenvalue first so that repeated eigenvalues still give an
// orthonormal basis (the approach of D. Eberly, "A Robust Eigensolver for 3x3 Symmetric
// Matrices").
#include "core/eigen3.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

namespace groovetrace {
namespace {

// Unit vector spanning the null space of (A - lambda I) when that null space is 1-D: the
// largest cross product of two rows is perpendicular to both.
Eigen::Vector3d null_vector(const Eigen::Matrix3d& a, double lambda) {
  Eigen::Matrix3d m = a - lambda * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d r0 = m.row(0), r1 = m.row(1), r2 = m.row(2);
  const Eigen::Vector3d c01 = r0.cross(r1), c02 = r0.cross(r2), c12 = r1.cross(r2);
  const double d01 = c01.squaredNorm(), d02 = c02.squaredNorm(), d12 = c12.squaredNorm();
  if (d01 >= d02 && d01 >= d12 && d01 > 0) return c01 / std::sqrt(d01);
  if (d02 >= d12 && d02 > 0) return c02 / std::sqrt(d02);
  if (d12 > 0) return c12 / std::sqrt(d12);
  return Eigen::Vector3d::UnitX();  // rank <= 1 cannot happen for a simple eigenvalue
}

// Any orthonormal pair (u, v) perpendicular to unit w.
void complement(const Eigen::Vector3d& w, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  if (std::abs(w.x()) > std::abs(w.y())) {
    u = Eigen::Vector3d(-w.z(), 0, w.x()) / std::hypot(w.x(), w.z());
  } else {
    u = Eigen::Vector3d(0, w.z(), -w.y()) / std::hypot(w.y(), w.z());
  }
  v = w.cross(u);
}

// Eigenvector of lambda inside the plane perpendicular to evec0: reduce (A - lambda I) to
// that plane (2x2) and take its null direction.
Eigen::Vector3d second_vector(const Eigen::Matrix3d& a, const Eigen::Vector3d& evec0,
                              double lambda) {
  Eigen::Vector3d u, v;
  complement(evec0, u, v);
  const Eigen::Vector3d au = a * u, av = a * v;
  double m00 = u.dot(au) - lambda, m01 = u.dot(av), m11 = v.dot(av) - lambda;
  const double a00 = std::abs(m00), a01 = std::abs(m01), a11 = std::abs(m11);
  if (a00 >= a11) {
    const double mx = std::max(a00, a01);
    if (mx == 0) return u;
    if (a00 >= a01) {
      m01 /= m00;
      m00 = 1 / std::sqrt(1 + m01 * m01);
      m01 *= m00;
    } else {
      m00 /= m01;
      m01 = 1 / std::sqrt(1 + m00 * m00);
      m00 *= m01;
    }
    return (m01 * u - m00 * v).normalized();
  }
  const double mx = std::max(a11, a01);
  if (mx == 0) return u;
  if (a11 >= a01) {
    m01 /= m11;
    m11 = 1 / std::sqrt(1 + m01 * m01);
    m01 *= m11;
  } else {
    m11 /= m01;
    m01 = 1 / std::sqrt(1 + m11 * m11);
    m11 *= m01;
  }
  return (m11 * u - m01 * v).normalized();
}

}  // namespace

SymEigen3 eigen_sym3(const Eigen::Matrix3d& m_in) {
  Eigen::Matrix3d a = m_in.triangularView<Eigen::Upper>();
  a.triangularView<Eigen::StrictlyLower>() = a.transpose();
  SymEigen3 out;
  // Scaling keeps the cubic's coefficients near 1, whatever the units of the covariance.
  const double scale = a.cwiseAbs().maxCoeff();
  if (scale == 0 || !std::isfinite(scale)) {
    out.values = Eigen::Vector3d::Zero();
    out.vectors = Eigen::Matrix3d::Identity();
    if (!std::isfinite(scale)) out.values.setConstant(NAN);
    return out;
  }
  a /= scale;
  const double q = a.trace() / 3;
  const double p1 = a(0, 1) * a(0, 1) + a(0, 2) * a(0, 2) + a(1, 2) * a(1, 2);
  const double p2 = (a(0, 0) - q) * (a(0, 0) - q) + (a(1, 1) - q) * (a(1, 1) - q) +
                    (a(2, 2) - q) * (a(2, 2) - q) + 2 * p1;
  const double p = std::sqrt(p2 / 6);
  if (p < 1e-15) {  // a multiple of the identity: every basis is an eigenbasis
    out.values.setConstant(q * scale);
    out.vectors = Eigen::Matrix3d::Identity();
    return out;
  }
  const Eigen::Matrix3d b = (a - q * Eigen::Matrix3d::Identity()) / p;
  const double half_det = std::clamp(b.determinant() / 2, -1.0, 1.0);
  const double phi = std::acos(half_det) / 3;
  const double two_pi_3 = 2.0943951023931954923;
  const double l_max = q + 2 * p * std::cos(phi);
  const double l_min = q + 2 * p * std::cos(phi + two_pi_3);
  const double l_mid = 3 * q - l_max - l_min;

  // Start from the eigenvalue farthest from the other two: its null space is surely 1-D.
  Eigen::Vector3d v_max, v_mid, v_min;
  if (l_max - l_mid >= l_mid - l_min) {
    v_max = null_vector(a, l_max);
    v_mid = second_vector(a, v_max, l_mid);
    v_min = v_max.cross(v_mid);
  } else {
    v_min = null_vector(a, l_min);
    v_mid = second_vector(a, v_min, l_mid);
    v_max = v_mid.cross(v_min);
  }
  // acos loses half the digits where two eigenvalues meet (its slope is infinite at +-1);
  // the Rayleigh quotients of the (accurate) vectors restore full precision.
  std::array<std::pair<double, Eigen::Vector3d>, 3> pairs = {
      std::make_pair(v_min.dot(a * v_min), v_min), std::make_pair(v_mid.dot(a * v_mid), v_mid),
      std::make_pair(v_max.dot(a * v_max), v_max)};
  std::sort(pairs.begin(), pairs.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  for (int k = 0; k < 3; ++k) {
    out.values(k) = pairs[k].first * scale;
    out.vectors.col(k) = pairs[k].second;
  }
  return out;
}

Eigen::Vector3d smallest_eigenvector(const Eigen::Matrix3d& m) {
  return eigen_sym3(m).vectors.col(0);
}

}  // namespace groovetrace
