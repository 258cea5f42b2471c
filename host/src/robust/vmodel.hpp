#pragma once
// The robust method's V model of a cross-section (internal): a top curve, two walls, a root,
// and the signed distance of a profile point to it with its derivatives, for the
// Gauss-Newton fit in v_profile.cpp. Profile coordinates: u across the seam, v along the
// top normal (out of the workpiece), metres.

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace groovetrace::robust_detail {

/// Top curve height v (m) at u (m): q0 + q1 u + q2 u^2.
inline double top_at(const Eigen::Vector3d& q, double u) { return q[0] + q[1] * u + q[2] * u * u; }

/// The top curve fitted to profile points `pts` (m) by Tukey-reweighted least squares in v:
/// degree 2 gives q0 + q1 u + q2 u^2, degree 1 a line (q2 = 0). Returns the coefficients and
/// the robust sigma of the final fit's residuals (m). Defined in v_profile.cpp.
std::pair<Eigen::Vector3d, double> fit_poly(const std::vector<Eigen::Vector2d>& pts, int degree);

/// Robust sigma of residuals `r` (m): the rms of the smallest 80 % of |r| scaled to a
/// Gaussian's sigma (it does not collapse on depths quantized to 1 mm, as the MAD does).
double robust_sigma(const std::vector<double>& r);

/// Orthogonal (total least squares) line through profile points `pts` (m), Tukey-reweighted on
/// the perpendicular residual at `scale` (m): a point on it and its unit direction.
std::pair<Eigen::Vector2d, Eigen::Vector2d> fit_line(const std::vector<Eigen::Vector2d>& pts,
                                                     double scale);

/// The V model: a top curve v = q0 + q1 u + q2 u^2 (q2 held in fits) on the left, the same
/// raised by `step` on the right (plates set high-low; held in fits), a root vertex, and the
/// two edges where the walls leave the tops at u_left < root.u < u_right (m).
struct VModel {
  Eigen::Vector3d q{0, 0, 0};
  double step = 0;
  Eigen::Vector2d root{0, 0};
  double u_left = 0, u_right = 0;
  /// Height of the left (right = false) or right top at u (m).
  double top(double u, bool right) const { return top_at(q, u) + (right ? step : 0.0); }
  Eigen::Vector2d edge_left() const { return {u_left, top(u_left, false)}; }
  Eigen::Vector2d edge_right() const { return {u_right, top(u_right, true)}; }
};

/// The fitted parameters, in this order: root u, root v, u_left, u_right, q0, q1.
using Vec6 = Eigen::Matrix<double, 6, 1>;
enum Param { kRootU = 0, kRootV, kLeftU, kRightU, kQ0, kQ1 };

/// Piece of the model nearest to the profile point p (0 top-left, 1 wall-left, 2 wall-right,
/// 3 top-right) and the signed distance to it (m, positive above the V, out of the material).
/// With `grad`, also the distance's derivatives with respect to the parameters (Param order),
/// exact wherever the nearest piece does not change.
std::pair<int, double> nearest_piece(const Eigen::Vector2d& p, const VModel& m,
                                     Vec6* grad = nullptr);

}  // namespace groovetrace::robust_detail
