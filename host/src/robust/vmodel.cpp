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

// Signed distance of p to segment a-b (positive on the left of a->b) or to its nearer end.
// With `grad`, also its derivatives, given those of a and b (Ja, Jb): inside the segment,
// moving a by da moves the line at the foot by (1 - t) da (t: the foot's fraction along
// a-b), so d = n.(p - a) changes by -(1 - t) n.da - t n.db; at an end, d = +-|p - end|.
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b, const PointJacobian* Ja = nullptr,
                        const PointJacobian* Jb = nullptr, Vec6* grad = nullptr) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t_raw = len2 > 0 ? (p - a).dot(ab) / len2 : 0.0;
  const double t = std::clamp(t_raw, 0.0, 1.0);
  const Eigen::Vector2d foot = a + t * ab;
  const double d = (p - foot).norm();
  const double side = ab.x() * (p - a).y() - ab.y() * (p - a).x();
  const double s = side >= 0 ? 1.0 : -1.0;
  if (grad) {
    if (t_raw > 0 && t_raw < 1) {
      const Eigen::Vector2d n = Eigen::Vector2d(-ab.y(), ab.x()) / std::sqrt(len2);
      *grad = -((1 - t) * (n.transpose() * *Ja) + t * (n.transpose() * *Jb)).transpose();
    } else if (d > 0) {
      const Eigen::Vector2d dir = (p - foot) / d;
      *grad = -s * (dir.transpose() * (t_raw <= 0 ? *Ja : *Jb)).transpose();
    } else {
      grad->setZero();
    }
  }
  return s * d;
}

}  // namespace

std::pair<int, double> nearest_piece(const Eigen::Vector2d& p, const VModel& m, Vec6* grad) {
  const Eigen::Vector2d el = m.edge_left(), er = m.edge_right();
  // Walls: from the edge down to the root (left) and from the root up to the edge (right),
  // so that "left of the direction" is above the material on both.
  const double dl = segment_distance(p, el, m.root);
  const double dr = segment_distance(p, m.root, er);
  auto top_inside = [&](bool left) {
    const double u = p.x();
    return left ? u <= el.x() : u >= er.x();
  };
  auto top_dist = [&](bool left) {
    const double u = p.x();
    if (top_inside(left)) {
      const double slope = m.q[1] + 2 * m.q[2] * u;
      return (p.y() - m.top(u, !left)) / std::sqrt(1 + slope * slope);
    }
    const Eigen::Vector2d e = left ? el : er;
    const double d = (p - e).norm();
    return p.y() >= m.top(u, !left) ? d : -d;
  };
  const double tl = top_dist(true), tr = top_dist(false);
  int best = 0;
  double bd = tl;
  for (const auto& [k, d] : {std::pair<int, double>{1, dl}, {2, dr}, {3, tr}}) {
    if (std::abs(d) < std::abs(bd)) {
      best = k;
      bd = d;
    }
  }
  if (grad) {
    grad->setZero();
    if (best == 1 || best == 2) {
      const PointJacobian Je = edge_jacobian(m, best == 1), Jr = root_jacobian();
      if (best == 1)
        segment_distance(p, el, m.root, &Je, &Jr, grad);
      else
        segment_distance(p, m.root, er, &Jr, &Je, grad);
    } else if (top_inside(best == 0)) {
      const double u = p.x();
      const double slope = m.q[1] + 2 * m.q[2] * u;
      const double S = std::sqrt(1 + slope * slope);
      (*grad)[kQ0] = -1 / S;
      (*grad)[kQ1] = -u / S - (p.y() - m.top(u, best == 3)) * slope / (S * S * S);
    } else {
      const Eigen::Vector2d e = best == 0 ? el : er;
      const double d = (p - e).norm();
      if (d > 0) {
        const double s = bd >= 0 ? 1.0 : -1.0;
        *grad = -s * (((p - e) / d).transpose() * edge_jacobian(m, best == 0)).transpose();
      }
    }
  }
  return {best, bd};
}

}  // namespace groovetrace::robust_detail
