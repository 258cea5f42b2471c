// UR rotation vectors (axis * angle, rad) from and to quaternions, with the branch choice
// that keeps a path continuous through angle pi.

#include <cmath>
#include <groovetrace/rotation.hpp>

namespace groovetrace {

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

Eigen::Vector3d rotation_vector(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  // q and -q are the same rotation; w >= 0 selects the half angle in [0, pi/2], so the
  // angle lands in [0, pi].
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double s = v.norm();  // sin(angle / 2)
  if (s == 0.0) return Eigen::Vector3d::Zero();
  // atan2 keeps full precision at both ends, where acos(w) or asin(s) would lose digits.
  const double angle = 2.0 * std::atan2(s, q.w());
  return v * (angle / s);
}

Eigen::Vector3d rotation_vector_near(const Eigen::Quaterniond& q, const Eigen::Vector3d& previous) {
  const Eigen::Vector3d principal = rotation_vector(q);
  const double angle = principal.norm();
  Eigen::Vector3d axis;
  if (angle > 0.0) {
    axis = principal / angle;
  } else if (previous.norm() > 0.0) {
    // The identity has no axis: any vector of length 2 pi is it too. The one nearest to
    // `previous` points along it, which is what axis * (0 - 2 pi) below gives.
    axis = -previous.normalized();
  } else {
    return principal;
  }
  // (-axis) * (2 pi - angle) == axis * (angle - 2 pi), so these two cover both axis signs.
  const Eigen::Vector3d alternative = axis * (angle - 2.0 * kPi);
  return (alternative - previous).squaredNorm() < (principal - previous).squaredNorm() ? alternative
                                                                                       : principal;
}

Eigen::Quaterniond quaternion_from_rotation_vector(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  // sin(angle/2)/angle, by its series where the division would be 0/0.
  const double k = angle < 1e-8 ? 0.5 - angle * angle / 48.0 : std::sin(0.5 * angle) / angle;
  Eigen::Quaterniond q;
  q.w() = std::cos(0.5 * angle);
  q.vec() = v * k;
  return q.normalized();
}

}  // namespace groovetrace
