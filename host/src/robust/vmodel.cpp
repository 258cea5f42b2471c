// Distance of a profile point to the V model, and its derivatives (vmodel.hpp).

#include "robust/vmodel.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace groovetrace::robust_detail {
namespace {

// Derivatives of a point on the model with respect to the six parameters (rows u, v).
using PointJacobian = Eigen::Matrix<double, 2, 6>;

PointJacobian edge_jacobian(const VModel& m, bool left) {
  const double u = left ? m.u_left : m.u_right;
  PointJacobian J = PointJacobian::Zero();
  const int k = left ? kLeftU : kRightU;
  J(0, k) = 1;
  J(1, k) = m.q[1] + 2 * m.q[2] * u;
  J(1, kQ0) = 1;
  J(1, kQ1) = u;
  return J;
}

PointJacobian root_jacobian() {
  PointJacobian J = PointJacobian::Zero();
  J(0, kRootU) = 1;
  J(1, kRootV) = 1;
  return J;
}

// A profile point's foot on segment a-b: t_raw, the foot's fraction along a-b (0 at a, 1 at
// b, unclamped), and d, the signed distance to the segment or its nearer end (m, positive on
// the left of a->b). In plain doubles because the fit's cost evaluates it for every point at
// every trial step: with Eigen vectors passed by reference, AddressSanitizer's scope checks
// made this ten times slower than the arithmetic (a sanitized run spent half its time here).
struct SegmentFoot {
  double t_raw, d;
};

SegmentFoot segment_foot(double pu, double pv, double au, double av, double bu, double bv) {
  const double abu = bu - au, abv = bv - av, apu = pu - au, apv = pv - av;
  const double len2 = abu * abu + abv * abv;
  const double t_raw = len2 > 0 ? (apu * abu + apv * abv) / len2 : 0.0;
  const double t = std::clamp(t_raw, 0.0, 1.0);
  const double fu = pu - (au + t * abu), fv = pv - (av + t * abv);
  const double d = std::sqrt(fu * fu + fv * fv);
  return {t_raw, abu * apv - abv * apu >= 0 ? d : -d};
}

// Derivatives of the distance `f` of p to segment a-b, given those of a and b (Ja, Jb): inside
// the segment, moving a by da moves the line at the foot by (1 - t) da, so d = n.(p - a)
// changes by -(1 - t) n.da - t n.db; at an end, d = +-|p - end|.
Vec6 segment_gradient(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                      const SegmentFoot& f, const PointJacobian& Ja, const PointJacobian& Jb) {
  const Eigen::Vector2d ab = b - a;
  if (f.t_raw > 0 && f.t_raw < 1) {
    const double t = f.t_raw;
    const Eigen::Vector2d n = Eigen::Vector2d(-ab.y(), ab.x()) / std::sqrt(ab.squaredNorm());
    return -((1 - t) * (n.transpose() * Ja) + t * (n.transpose() * Jb)).transpose();
  }
  if (f.d == 0) return Vec6::Zero();
  const Eigen::Vector2d foot = a + std::clamp(f.t_raw, 0.0, 1.0) * ab;
  const Eigen::Vector2d dir = (p - foot) / std::abs(f.d);
  const double s = f.d > 0 ? 1.0 : -1.0;
  return -s * (dir.transpose() * (f.t_raw <= 0 ? Ja : Jb)).transpose();
}

// Signed distance of (pu, pv) to the left (right = false) or right top: along the top's normal
// above its own span, else to its edge (m, positive above the top).
double top_distance(double pu, double pv, const VModel& m, bool right) {
  const double eu = right ? m.u_right : m.u_left;
  const double top = m.top(pu, right);
  if (right ? pu >= eu : pu <= eu) {
    const double slope = m.q[1] + 2 * m.q[2] * pu;
    return (pv - top) / std::sqrt(1 + slope * slope);
  }
  const double du = pu - eu, dv = pv - m.top(eu, right);
  const double d = std::sqrt(du * du + dv * dv);
  return pv >= top ? d : -d;
}

// Derivatives of the distance bd of p to top `right` (see top_distance).
Vec6 top_gradient(const Eigen::Vector2d& p, const VModel& m, bool right, double bd) {
  Vec6 grad = Vec6::Zero();
  const double u = p.x();
  if (right ? u >= m.u_right : u <= m.u_left) {
    const double slope = m.q[1] + 2 * m.q[2] * u;
    const double S = std::sqrt(1 + slope * slope);
    grad[kQ0] = -1 / S;
    grad[kQ1] = -u / S - (p.y() - m.top(u, right)) * slope / (S * S * S);
    return grad;
  }
  const Eigen::Vector2d e = right ? m.edge_right() : m.edge_left();
  const double d = (p - e).norm();
  if (d > 0) {
    const double s = bd >= 0 ? 1.0 : -1.0;
    grad = -s * (((p - e) / d).transpose() * edge_jacobian(m, !right)).transpose();
  }
  return grad;
}

}  // namespace

std::pair<int, double> nearest_piece(const Eigen::Vector2d& p, const VModel& m, Vec6* grad) {
  const double pu = p.x(), pv = p.y(), ru = m.root.x(), rv = m.root.y();
  const double elv = m.top(m.u_left, false), erv = m.top(m.u_right, true);
  // Walls: from the edge down to the root (left) and from the root up to the edge (right),
  // so that "left of the direction" is above the material on both.
  const SegmentFoot wl = segment_foot(pu, pv, m.u_left, elv, ru, rv);
  const SegmentFoot wr = segment_foot(pu, pv, ru, rv, m.u_right, erv);
  int best = 0;
  double bd = top_distance(pu, pv, m, false);
  if (std::abs(wl.d) < std::abs(bd)) best = 1, bd = wl.d;
  if (std::abs(wr.d) < std::abs(bd)) best = 2, bd = wr.d;
  const double tr = top_distance(pu, pv, m, true);
  if (std::abs(tr) < std::abs(bd)) best = 3, bd = tr;
  if (grad) {
    const PointJacobian Jr = root_jacobian();
    if (best == 1)
      *grad = segment_gradient(p, m.edge_left(), m.root, wl, edge_jacobian(m, true), Jr);
    else if (best == 2)
      *grad = segment_gradient(p, m.root, m.edge_right(), wr, Jr, edge_jacobian(m, false));
    else
      *grad = top_gradient(p, m, best == 3, bd);
  }
  return {best, bd};
}

}  // namespace groovetrace::robust_detail
