// Stage 2 of the robust method: the V model fitted to one cross-section of the seam.
//
// The profile is (u across, v height): top surface, two walls. The top is fitted first, from
// the outer half of the window where no groove lies, as a robust quadratic (a pipe's crown
// bends 2-4 mm over a 20 mm window). Points clearly below it are the groove; from their run a
// first V (root at the deepest points, edges at the run's ends) is refined as a whole - root,
// both edges, the top's offset and slope - on the points' orthogonal distances (walls are
// steep, so residuals in v alone would weigh them wrongly). The rims and the root are left out
// of the fit: stereo matching rounds both off, and the root gap is not a wall. Root = the
// walls' intersection, edges = walls meet top.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/stats.hpp"
#include "robust/stages.hpp"
#include "robust/vmodel.hpp"

namespace groovetrace {

using robust_detail::fit_line;
using robust_detail::fit_poly;
using robust_detail::kLeftU;
using robust_detail::kQ0;
using robust_detail::kQ1;
using robust_detail::kRightU;
using robust_detail::kRootU;
using robust_detail::kRootV;
using robust_detail::nearest_piece;
using robust_detail::robust_sigma;
using robust_detail::top_at;
using robust_detail::Vec6;
using robust_detail::VModel;

// Robust sigma of residuals: the rms of the smallest 80% of |r|, scaled to a Gaussian's sigma
// (0.6616 sigma for a Gaussian). Unlike the MAD it does not collapse to zero on depths
// quantized to 1 mm, where most of a flat's points share one value.
double robust_detail::robust_sigma(const std::vector<double>& r) {
  if (r.empty()) return 0.0;
  std::vector<double> a(r.size());
  for (std::size_t k = 0; k < r.size(); ++k) a[k] = r[k] * r[k];
  const std::size_t keep = std::max<std::size_t>(1, (r.size() * 8) / 10);
  std::nth_element(a.begin(), a.begin() + (keep - 1), a.end());
  double ss = 0;
  for (std::size_t k = 0; k < keep; ++k) ss += a[k];
  return std::sqrt(ss / keep) / 0.6616;
}

// Orthogonal (total least squares) line through `pts`, Tukey-reweighted on the perpendicular
// residual: returns a point on it and its unit direction.
std::pair<Eigen::Vector2d, Eigen::Vector2d> robust_detail::fit_line(
    const std::vector<Eigen::Vector2d>& pts, double scale) {
  std::vector<double> w(pts.size(), 1.0);
  Eigen::Vector2d c(0, 0), d(1, 0);
  for (int iter = 0; iter < 5; ++iter) {
    double sw = 0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (std::size_t k = 0; k < pts.size(); ++k) {
      sw += w[k];
      mean += w[k] * pts[k];
    }
    if (!(sw > 0)) break;
    mean /= sw;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (std::size_t k = 0; k < pts.size(); ++k) {
      cov += w[k] * (pts[k] - mean) * (pts[k] - mean).transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    c = mean;
    d = eig.eigenvectors().col(1).normalized();
    const Eigen::Vector2d nrm(-d.y(), d.x());
    for (std::size_t k = 0; k < pts.size(); ++k)
      w[k] = tukey_weight_or_one((pts[k] - c).dot(nrm), kTukeyC * scale);
  }
  return {c, d};
}

// Iteratively reweighted least squares, six rounds, each weighting by the last one's residuals.
std::pair<Eigen::Vector3d, double> robust_detail::fit_poly(const std::vector<Eigen::Vector2d>& pts,
                                                           int degree) {
  const int m = degree + 1;
  std::vector<double> w(pts.size(), 1.0);
  Eigen::Vector3d q = Eigen::Vector3d::Zero();
  double sigma = 0;
  for (int iter = 0; iter < 6; ++iter) {
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const double u = pts[k].x();
      const Eigen::Vector3d row(1, u, u * u);
      A.topLeftCorner(m, m) += w[k] * row.head(m) * row.head(m).transpose();
      b.head(m) += w[k] * pts[k].y() * row.head(m);
    }
    Eigen::Vector3d sol = Eigen::Vector3d::Zero();
    sol.head(m) = A.topLeftCorner(m, m).ldlt().solve(b.head(m));
    if (!sol.allFinite()) break;
    q = sol;
    std::vector<double> r(pts.size());
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const double u = pts[k].x();
      r[k] = pts[k].y() - (q[0] + q[1] * u + q[2] * u * u);
    }
    sigma = robust_sigma(r);
    for (std::size_t k = 0; k < r.size(); ++k)
      w[k] = tukey_weight_or_one(r[k], kTukeyC * std::max(sigma, 1e-7));
  }
  return {q, sigma};
}

namespace {

// The heights of two top sides `lo` (left) and `hi` (right) as one curve a + b u + c u^2 with
// the right side raised by a step: (a, b, c, step), Tukey-reweighted as fit_poly; `m` = 4
// fits c, 3 holds it at 0.
Eigen::Vector4d fit_stepped_top(const std::vector<Eigen::Vector2d>& lo,
                                const std::vector<Eigen::Vector2d>& hi, int m) {
  const auto row = [m](double u, bool right) {
    return Eigen::Vector4d(1, u, m == 4 ? u * u : 0.0, right ? 1.0 : 0.0);
  };
  std::vector<double> w(lo.size() + hi.size(), 1.0), r(w.size());
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  for (int iter = 0; iter < 6; ++iter) {
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    Eigen::Vector4d b = Eigen::Vector4d::Zero();
    for (std::size_t k = 0; k < w.size(); ++k) {
      const bool right = k >= lo.size();
      const Eigen::Vector2d& p = right ? hi[k - lo.size()] : lo[k];
      A += w[k] * row(p.x(), right) * row(p.x(), right).transpose();
      b += w[k] * p.y() * row(p.x(), right);
    }
    if (m == 3) A(2, 2) = 1.0;  // c held at 0
    const Eigen::Vector4d sol = A.ldlt().solve(b);
    if (!sol.allFinite()) break;
    x = sol;
    for (std::size_t k = 0; k < w.size(); ++k) {
      const bool right = k >= lo.size();
      const Eigen::Vector2d& p = right ? hi[k - lo.size()] : lo[k];
      r[k] = p.y() - row(p.x(), right).dot(x);
    }
    const double sigma = std::max(robust_sigma(r), 1e-7);
    for (std::size_t k = 0; k < w.size(); ++k) w[k] = tukey_weight_or_one(r[k], kTukeyC * sigma);
  }
  return x;
}

// Angle (deg) by which `wall` (unit, from the edge towards the root) dips below the top's
// tangent `inward` (unit, along the top towards the groove). Positive: into the material.
double dip_deg(const Eigen::Vector2d& inward, const Eigen::Vector2d& wall, bool left) {
  const double cross = inward.x() * wall.y() - inward.y() * wall.x();
  return rad_to_deg(std::atan2(left ? -cross : cross, inward.dot(wall)));
}

// Squared distance of p to (u, v) (m^2), in plain doubles as in vmodel.cpp: the fit's cost
// asks near_vertex for every point at every trial step.
double squared_distance(const Eigen::Vector2d& p, double u, double v) {
  const double du = p.x() - u, dv = p.y() - v;
  return du * du + dv * dv;
}

bool near_vertex(const Eigen::Vector2d& p, const VModel& m, double zone) {
  const double z2 = zone * zone;
  return squared_distance(p, m.root.x(), m.root.y()) < z2 ||
         squared_distance(p, m.u_left, m.top(m.u_left, false)) < z2 ||
         squared_distance(p, m.u_right, m.top(m.u_right, true)) < z2;
}

using Mat6 = Eigen::Matrix<double, 6, 6>;

// How the V's walls are tied in a fit (VFit): free; symmetric (both dip alike about the top
// normal through the root); or one side square (a single bevel's: its wall straight down from
// its edge to the root, in a profile levelled to the top).
enum class Tie { free, symmetric, square_left, square_right };

// The V's parameters as the Gauss-Newton fit moves them. Free: x = (root u, root v, u_left,
// u_right, q0, q1). Symmetric: x[2] is the half width h and x[3] is unused (held at 0); the
// edges lie at u_c -+ h, u_c the foot of the top normal through the root (on the top's tangent
// line there), so both walls dip alike. Square: the square side's edge lies a hair outside the
// root's u (kept out of x: its entry is held at 0). The top's curvature q2 is held at the
// start's.
struct VParams {
  VModel start;
  Tie tie;
  // The square side's edge lies this far (m) outside the root, keeping the vertex order.
  static constexpr double kHair = 1e-6;

  // u_c, with s the top's slope at the root and g its height above the root:
  // u_c = root u - s g / (1 + s^2).
  double centre_u(const Vec6& x) const {
    const double s = x[5] + 2 * start.q[2] * x[0];
    const double gap = x[4] + x[5] * x[0] + start.q[2] * x[0] * x[0] - x[1];
    return x[0] - s * gap / (1 + s * s);
  }

  Vec6 pack(const VModel& v) const {
    Vec6 x;
    x << v.root.x(), v.root.y(), v.u_left, v.u_right, v.q[0], v.q[1];
    if (tie == Tie::symmetric) {
      x[2] = 0.5 * (v.u_right - v.u_left);
      x[3] = 0;
    }
    if (tie == Tie::square_left) x[2] = 0;
    if (tie == Tie::square_right) x[3] = 0;
    return x;
  }

  VModel unpack(const Vec6& x) const {
    VModel v = start;
    v.root = {x[0], x[1]};
    v.u_left = x[2];
    v.u_right = x[3];
    v.q[0] = x[4];
    v.q[1] = x[5];
    if (tie == Tie::symmetric) {
      const double uc = centre_u(x);
      v.u_left = uc - x[2];
      v.u_right = uc + x[2];
    }
    if (tie == Tie::square_left) v.u_left = x[0] - kHair;
    if (tie == Tie::square_right) v.u_right = x[0] + kHair;
    return v;
  }

  // d(free parameters) / d(x), for the chain rule: the identity when free.
  Mat6 chain(const Vec6& x) const {
    Mat6 M = Mat6::Identity();
    if (tie == Tie::square_left || tie == Tie::square_right) {
      const int k = tie == Tie::square_left ? kLeftU : kRightU;
      M.row(k).setZero();
      M(k, kRootU) = 1;
    }
    if (tie != Tie::symmetric) return M;
    const double s = x[5] + 2 * start.q[2] * x[0];
    const double g = x[4] + x[5] * x[0] + start.q[2] * x[0] * x[0] - x[1];
    const double n = 1 + s * s;
    const double df_ds = g * (1 - s * s) / (n * n), df_dg = s / n;
    Vec6 du = Vec6::Zero();  // d u_c / d x
    du[0] = 1 - (df_ds * 2 * start.q[2] + df_dg * s);
    du[1] = df_dg;
    du[4] = -df_dg;
    du[5] = -(df_ds + df_dg * x[0]);
    M.setZero();
    M(kRootU, 0) = 1;
    M(kRootV, 1) = 1;
    M(kQ0, 4) = 1;
    M(kQ1, 5) = 1;
    M.row(kLeftU) = du.transpose();
    M.row(kRightU) = du.transpose();
    M(kLeftU, 2) -= 1;
    M(kRightU, 2) += 1;
    return M;
  }
};

// The robust cost of `v`: Tukey's rho of each point's distance at scale c (normalised to 1 at
// and beyond c), the points near the three vertices left out.
double tukey_cost(const std::vector<Eigen::Vector2d>& pts, const VModel& v, double c, double zone) {
  double sum = 0;
  for (const auto& p : pts) {
    if (near_vertex(p, v, zone)) continue;
    const double r = nearest_piece(p, v).second / c;
    const double a = 1 - r * r;
    sum += std::abs(r) >= 1 ? 1.0 : 1 - a * a * a;
  }
  return sum;
}

// The damped Gauss-Newton step from x, Tukey-weighted at scale c.
Vec6 gauss_newton_step(const std::vector<Eigen::Vector2d>& pts, const VParams& par, const Vec6& x,
                       double c, double zone) {
  const VModel cur = par.unpack(x);
  const Mat6 M = par.chain(x);
  Mat6 JtJ = Mat6::Zero();
  Vec6 Jtr = Vec6::Zero();
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (near_vertex(pts[k], cur, zone)) continue;
    Vec6 J;
    const double r = nearest_piece(pts[k], cur, &J).second;
    J = (M.transpose() * J).eval();
    const double w = tukey_weight_or_one(r, c);
    if (w <= 0) continue;
    JtJ += w * J * J.transpose();
    Jtr += w * J * r;
  }
  // Marquardt damping, relative to each parameter's own curvature (the slope q1 is
  // dimensionless, the rest metres: a damping shared by all would freeze the slope), plus a
  // floor that keeps unconstrained directions (a wall without points) still.
  const double floor = 1e-9 * JtJ.diagonal().maxCoeff() + 1e-12;
  JtJ.diagonal() = JtJ.diagonal() * (1 + 1e-3) + Vec6::Constant(floor);
  return -JtJ.ldlt().solve(Jtr);
}

// Gauss-Newton steps at Tukey scale c, each halved until the cost drops (the edges staying on
// either side of the root), until a step no longer gains. False when a step is not finite.
bool descend(const std::vector<Eigen::Vector2d>& pts, const VParams& par, double c, double zone,
             Vec6& x) {
  double f = tukey_cost(pts, par.unpack(x), c, zone);
  for (int iter = 0; iter < 30; ++iter) {
    const Vec6 step = gauss_newton_step(pts, par, x, c, zone);
    if (!step.allFinite()) return false;
    double t = 1.0;
    bool improved = false;
    for (int half = 0; half < 8; ++half, t *= 0.5) {
      const Vec6 xn = x + t * step;
      const VModel vn = par.unpack(xn);
      if (!(vn.u_left < vn.root.x() && vn.root.x() < vn.u_right)) continue;
      const double fn = tukey_cost(pts, vn, c, zone);
      if (fn < f) {
        x = xn;
        improved = f - fn > 1e-6 * (1 + f);
        f = fn;
        break;
      }
    }
    if (!improved || (t * step).norm() < 1e-6) break;
  }
  return true;
}

// Gauss-Newton on (root u, root v, u_left, u_right, q0, q1) with analytic derivatives and
// Tukey weights from the current residuals (at scale `scale`, m), the points within `zone` (m)
// of a vertex left out; `tie` as in VParams. False, `m` untouched, when it diverges.
bool refine_v(const std::vector<Eigen::Vector2d>& pts, VModel& m, double scale, double zone,
              double coarse, Tie tie) {
  const VParams par{m, tie};
  Vec6 x = par.pack(m);
  // Graduated: a wide Tukey window first (`coarse`, m), so that a start a few millimetres off
  // still sees the walls, then halving down to the noise.
  for (double stage = std::max(coarse, scale);; stage = std::max(scale, 0.5 * stage)) {
    if (!descend(pts, par, kTukeyC * stage, zone, x)) return false;
    if (stage <= scale) break;
  }
  m = par.unpack(x);
  return m.root.allFinite() && std::isfinite(m.u_left) && std::isfinite(m.u_right);
}

// First crossing of the ray from `from` along unit `dir` with v = q0 + q1 u + q2 u^2.
bool meet_top(const Eigen::Vector2d& from, const Eigen::Vector2d& dir, const Eigen::Vector3d& q,
              Eigen::Vector2d& out) {
  // f(t) = top(u(t)) - v(t) = A t^2 + B t + C; the first root t > 0.
  const double u = from.x(), v = from.y(), du = dir.x(), dv = dir.y();
  const double A = q[2] * du * du;
  const double B = q[1] * du + 2 * q[2] * u * du - dv;
  const double C = q[0] + q[1] * u + q[2] * u * u - v;
  double t = NAN;
  if (std::abs(A) < 1e-12) {
    if (std::abs(B) > 1e-12) t = -C / B;
  } else {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0) {
      const double s = std::sqrt(disc);
      const double t1 = (-B - s) / (2 * A), t2 = (-B + s) / (2 * A);
      const double lo = std::min(t1, t2), hi = std::max(t1, t2);
      t = lo > 0 ? lo : hi;
    }
  }
  if (!(t > 0) || !std::isfinite(t)) return false;
  out = from + t * dir;
  return true;
}

struct PieceStats {
  int count[4] = {0, 0, 0, 0};  // points fitting each piece (Tukey inliers)
  double wall_rms = 0;          // rms distance of the wall inliers
  double top_sigma = 0;         // robust sigma of the top inliers
  double top_outliers = 0;      // share of the outer points that do not fit the top
  double inside = 0;            // share of the opening's points inside the walls (in_walls)
};

// Half the widest root opening a joint has (m): a root gap's slot shows the table below the
// walls within this of the root, plus the vertex zone.
constexpr double kMaxHalfGap = 0.0015;

// Whether profile point p (signed distance r to `m`) lies inside the walls of `m`, clearly
// (beyond the Tukey cut c) and away from the root (beyond a fifth of the opening, and beyond
// the vertex zone and the widest root gap): a V shows no points there, a channel with a floor
// does (score.cpp, kMaxFloored).
bool in_walls(const Eigen::Vector2d& p, double r, const VModel& m, double c, double zone) {
  const double keep = std::max(0.2 * (m.u_right - m.u_left), zone + kMaxHalfGap);
  return r < -c && std::abs(p.x() - m.root.x()) > keep;
}

PieceStats piece_stats(const std::vector<Eigen::Vector2d>& pts, const VModel& m, double scale,
                       double zone) {
  PieceStats st;
  double ss = 0;
  int nw = 0, outer = 0, outer_bad = 0, opening = 0, inside = 0;
  std::vector<double> top_r;
  const double c = kTukeyC * scale;
  for (const auto& p : pts) {
    const auto [piece, r] = nearest_piece(p, m);
    const bool is_top = piece == 0 || piece == 3;
    if (is_top && (p.x() < m.u_left - zone || p.x() > m.u_right + zone)) {
      ++outer;
      if (std::abs(r) >= c) ++outer_bad;
    }
    if (p.x() > m.u_left && p.x() < m.u_right) {
      ++opening;
      inside += in_walls(p, r, m, c, zone);
    }
    if (near_vertex(p, m, zone) || std::abs(r) >= c) continue;
    ++st.count[piece];
    if (is_top) {
      top_r.push_back(r);
    } else {
      ss += r * r;
      ++nw;
    }
  }
  st.wall_rms = nw > 0 ? std::sqrt(ss / nw) : 0;
  st.top_sigma = robust_sigma(top_r);
  st.top_outliers = outer > 0 ? static_cast<double>(outer_bad) / outer : 1.0;
  st.inside = opening > 0 ? static_cast<double>(inside) / opening : 0.0;
  return st;
}

// A two-wall V needs this many points on each wall; a one-wall V twice as many on its wall.
constexpr int kMinWall = 4;
// A wall may dip into the material up to a little past vertical (a single bevel's square side,
// measured with noise); beyond, it overhangs. A step down to a table is told by its two top
// sides at different heights, not by its dip.
constexpr double kMaxDipDeg = 95.0;
// The two top sides may differ in height by this share of the depth (plates set high-low) or
// by twice the noise band tau; more is a step down to a table.
constexpr double kMaxStepShare = 0.5;
// A wall facing the sensor at less than this incidence returns points (the D415 drops out from
// about 75 deg).
constexpr double kShownIncidenceDeg = 65.0;

// What the steps of one profile's fit share: the window's points and the scales the top
// surface's noise sets (all in m).
struct ProfileFit {
  std::vector<Eigen::Vector2d> pts;    // the finite points within |u| <= W
  std::vector<Eigen::Vector2d> outer;  // those with |u| >= W / 2, where the top lies
  double W = 0;                        // half window
  double sigma = 0;                    // robust sigma of the top's residuals
  double tau = 0;                      // points within tau of the top are top
  double scale = 0;                    // Tukey scale of the V fit
  double vertex_zone = 0;              // points this near a vertex stay out of the fits
  double top_step = 0;                 // right top side's line minus the left's at u = 0
  bool stepped = false;                // fit the tops with a step (VFit::stepped)
  double seam_step = NAN;              // the seam's step (VFit::step)
  double step = 0;                     // the step held in the fit (stepped), or 0
  Eigen::Vector2d view{0, 1};          // unit, towards the sensor
  // Height of the top `q` at u on the side of u = 0 where u lies.
  double top(const Eigen::Vector3d& q, double u) const { return top_at(q, u) + (u > 0 ? step : 0); }
};

// Each side's top on its own, as a line from the outer half: a real groove's two top sides
// continue each other (curved or not, their lines meet above the centre at one height); a
// step down to a table fitted by one tilted line does not, and plates set high-low differ by
// their misalignment. The right line's height minus the left's at u = 0 (m); 0 without three
// points on each side.
double top_step(const std::vector<Eigen::Vector2d>& outer) {
  std::vector<Eigen::Vector2d> lo, hi;
  for (const auto& p : outer) (p.x() < 0 ? lo : hi).push_back(p);
  if (lo.size() < 3 || hi.size() < 3) return 0;
  const Eigen::Vector3d ql = fit_poly(lo, 1).first, qr = fit_poly(hi, 1).first;
  return qr[0] - ql[0];
}

// 1. The top surface `q` from the outer half of the window. A quadratic needs both sides; its
//    curvature is bounded (radius >= W) so that it cannot bend into the groove. False without
//    three points on either side.
bool fit_top(ProfileFit& f, Eigen::Vector3d& q) {
  int n_left = 0, n_right = 0;
  for (const auto& p : f.pts) {
    if (std::abs(p.x()) >= 0.5 * f.W) {
      f.outer.push_back(p);
      (p.x() < 0 ? n_left : n_right) += 1;
    }
  }
  if (n_left < 3 && n_right < 3) return false;
  f.top_step = top_step(f.outer);
  f.step = !f.stepped ? 0.0 : std::isnan(f.seam_step) ? f.top_step : f.seam_step;
  // The right side lowered by the step (a copy only when there is one: this runs per section).
  std::vector<Eigen::Vector2d> lowered;
  if (f.step != 0.0) {
    lowered = f.outer;
    for (auto& p : lowered) p.y() -= f.top(Eigen::Vector3d::Zero(), p.x());
  }
  const std::vector<Eigen::Vector2d>& level = f.step != 0.0 ? lowered : f.outer;
  std::pair<Eigen::Vector3d, double> top = fit_poly(level, n_left >= 3 && n_right >= 3 ? 2 : 1);
  if (std::abs(top.first[2]) > 0.5 / f.W) top = fit_poly(level, 1);
  q = top.first;
  f.sigma = top.second;
  // Points within tau of the top are top; tau covers the sensor noise with a floor for
  // noise-free scans (2% of the window, 0.4 mm at the default scale).
  f.tau = std::max(3.0 * f.sigma, 0.02 * f.W);
  return true;
}

// 2. The groove: the run of points clearly below the top `q` that holds the deepest point near
//    the centre (the most depth summed over a run reaching into the central half). Runs split
//    at gaps in u (other dips, the table beyond an edge). Empty, `why` set, when none.
std::vector<Eigen::Vector2d> groove_run(const ProfileFit& f, const Eigen::Vector3d& q,
                                        std::string& why) {
  std::vector<Eigen::Vector2d> below;
  for (const auto& p : f.pts) {
    if (p.y() - f.top(q, p.x()) < -f.tau) below.push_back(p);
  }
  if (below.size() < 6) {
    why = "nothing below the top surface";
    return {};
  }
  std::sort(below.begin(), below.end(),
            [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); });
  const double gap = 0.15 * f.W;
  std::size_t best_lo = 0, best_hi = 0;
  double best_mass = -1;
  for (std::size_t lo = 0; lo < below.size();) {
    std::size_t hi = lo + 1;
    while (hi < below.size() && below[hi].x() - below[hi - 1].x() <= gap) ++hi;
    double mass = 0;
    bool central = false;
    for (std::size_t k = lo; k < hi; ++k) {
      mass += f.top(q, below[k].x()) - below[k].y();
      central = central || std::abs(below[k].x()) <= 0.5 * f.W;
    }
    if (central && mass > best_mass) {
      best_mass = mass;
      best_lo = lo;
      best_hi = hi;
    }
    lo = hi;
  }
  if (best_mass < 0 || best_hi - best_lo < 6) {
    why = "no groove near the centre";
    return {};
  }
  return {below.begin() + best_lo, below.begin() + best_hi};
}

// 3. The initial V from the groove's run (sorted by u) under the top `q`: root at its deepest
//    points, edges at its ends.
VModel initial_v(const std::vector<Eigen::Vector2d>& groove, const Eigen::Vector3d& q,
                 const ProfileFit& f) {
  const double W = f.W;
  std::vector<double> depths, deep_u;
  for (const auto& p : groove) depths.push_back(f.top(q, p.x()) - p.y());
  std::vector<double> sorted_depths = depths;
  std::sort(sorted_depths.begin(), sorted_depths.end());
  const double d90 = sorted_depths[(sorted_depths.size() * 9) / 10];
  for (std::size_t k = 0; k < groove.size(); ++k) {
    if (depths[k] >= 0.8 * d90) deep_u.push_back(groove[k].x());
  }
  const double u0 = upper_median(deep_u);
  VModel m;
  m.q = q;
  m.step = f.step;
  m.root = Eigen::Vector2d(u0, f.top(q, u0) - d90);
  m.u_left = std::min(groove.front().x(), u0 - 0.1 * W);
  m.u_right = std::max(groove.back().x(), u0 + 0.1 * W);
  return m;
}

// The tops beyond a two-wall V's fitted edges (a vertex zone out, within the window): one
// curve with a step at the groove, v = a + b u + c u^2 + step [right side], Tukey-reweighted
// (c held at 0 when it would bend more than the top's bound, |c| <= 0.5 / W). On the sweep's
// noisy 1.5 mm high-low scans a station's step read so scatters a third less than the outer
// half's lines' (top_step), from more points. Also each side's line slope there
// (right minus left, dv/du): plates set high-low stay parallel; the two sides of a curved
// part seen at a slant diverge, and their lines then differ in height by a millimetre or two.
struct TopSides {
  double step = 0.0;
  double bend = NAN;  // NaN without three points on each side
};

TopSides top_sides(const ProfileFit& f, const VModel& v) {
  std::vector<Eigen::Vector2d> lo, hi;
  for (const auto& p : f.pts) {
    if (p.x() < v.u_left - f.vertex_zone) lo.push_back(p);
    if (p.x() > v.u_right + f.vertex_zone) hi.push_back(p);
  }
  if (lo.size() < 3 || hi.size() < 3) return {f.top_step, NAN};
  TopSides out;
  out.bend = fit_poly(hi, 1).first[1] - fit_poly(lo, 1).first[1];
  for (int m : {4, 3}) {  // with the quadratic term, then without
    const Eigen::Vector4d x = fit_stepped_top(lo, hi, m);
    out.step = x[3];
    if (m == 3 || std::abs(x[2]) <= 0.5 / f.W) break;
  }
  return out;
}

// The profile's quantities for the V `v`: edges, point counts, width, depth, the walls' dips,
// opening and bisector. `fallback_noise` (m) when the top has no inliers.
VProfile describe_v(const VModel& v, const PieceStats& st, double fallback_noise) {
  VProfile o;
  const Eigen::Vector2d el = v.edge_left(), er = v.edge_right();
  o.top = v.q;
  o.root = v.root;
  o.edge_left = el;
  o.edge_right = er;
  o.top_left = st.count[0];
  o.wall_left = st.count[1];
  o.wall_right = st.count[2];
  o.top_right = st.count[3];
  o.rms = st.wall_rms;
  o.noise = st.top_sigma > 0 ? st.top_sigma : fallback_noise;
  o.width = (er - el).norm();
  // Below the lower top (high-low plates: the depth of the joint's lower side).
  o.depth = std::min(v.top(v.root.x(), false), v.top(v.root.x(), true)) - v.root.y();
  const Eigen::Vector2d to_root_l = (v.root - el).normalized();
  const Eigen::Vector2d to_root_r = (v.root - er).normalized();
  const Eigen::Vector2d tl = Eigen::Vector2d(1, v.q[1] + 2 * v.q[2] * el.x()).normalized();
  const Eigen::Vector2d tr = Eigen::Vector2d(1, v.q[1] + 2 * v.q[2] * er.x()).normalized();
  o.wall_left_deg = dip_deg(tl, to_root_l, true);
  o.wall_right_deg = dip_deg(-tr, to_root_r, false);
  o.opening_deg = rad_to_deg(std::acos(std::clamp(to_root_l.dot(to_root_r), -1.0, 1.0)));
  o.bisector = (-to_root_l - to_root_r).normalized();
  return o;
}

// 5. Is it a V? Both walls dip into the material at a plausible angle (a vertical step to a
//    table is ~90 deg, a convex edge negative), both top sides and both walls (`wall_min`
//    points each) carry points, the groove lies inside the window and is deeper than the
//    noise. Why not, or nullptr when it is.
const char* why_not_v(const VProfile& o, const PieceStats& st, const ProfileFit& f, int wall_min) {
  const Eigen::Vector2d &el = o.edge_left, &er = o.edge_right;
  if (!o.root.allFinite() || !el.allFinite() || !er.allFinite()) return "V fit did not converge";
  if (o.wall_left_deg < 3 || o.wall_right_deg < 3) return "a wall is too flat";
  if (o.wall_left_deg > kMaxDipDeg || o.wall_right_deg > kMaxDipDeg) return "a wall overhangs";
  if (o.top_left < 3 || o.top_right < 3) return "a top surface is missing";
  if (o.wall_left < wall_min || o.wall_right < wall_min) return "a wall is missing";
  if (o.depth < 1.5 * f.tau) return "too shallow for the noise";
  if (el.x() < -0.9 * f.W || er.x() > 0.9 * f.W || el.x() >= er.x()) {
    return "groove leaves the window";
  }
  if (o.rms > 0.35 * o.depth) return "walls are not straight";
  if (st.top_outliers > 0.5) return "top surfaces disagree";
  if (std::abs(f.top_step) > std::max(2 * f.tau, kMaxStepShare * o.depth)) {
    return "top surfaces at different heights (a step)";
  }
  return nullptr;
}

// The profile of the V `v` and whether it is one (see why_not_v). `one_wall`: one wall's
// points are not required. The tops beyond the edges are left to with_top_sides.
VProfile judge_v(const VModel& v, bool one_wall, const ProfileFit& f) {
  const PieceStats st = piece_stats(f.pts, v, f.scale, f.vertex_zone);
  VProfile o = describe_v(v, st, f.sigma);
  o.one_wall = one_wall;
  o.misalignment = o.outer_step = f.top_step;
  o.inside = st.inside;
  const char* why = why_not_v(o, st, f, one_wall ? 0 : kMinWall);
  if (why) {
    o.why = why;
    return o;
  }
  o.ok = true;
  return o;
}

// The two-wall V `o` that passed (model `m`) with the step and bend of the tops beyond its
// edges. Fitted once per station, for the V it returns: only those sections' steps and bends
// are read (score.cpp, trace.cpp, outputs), and a station judges up to three V's.
VProfile with_top_sides(VProfile o, const ProfileFit& f, const VModel& m) {
  const TopSides sides = top_sides(f, m);
  o.misalignment = sides.step;
  o.top_bend = sides.bend;
  return o;
}

// The top of `m` on its right (or left) side as one curve's coefficients.
Eigen::Vector3d side_top(const VModel& m, bool right) {
  Eigen::Vector3d q = m.q;
  if (right) q[0] += m.step;
  return q;
}

// The wall of the failed V `m` on the seen side, refitted alone (the failed fit's root may have
// been dragged by strays): `edge` where it meets the top, `up` the unit direction up the wall
// towards it. False with too few wall points or no crossing.
bool seen_wall(const VModel& m, const ProfileFit& f, bool left_missing, Eigen::Vector2d& edge,
               Eigen::Vector2d& up) {
  std::vector<Eigen::Vector2d> wall_pts;
  for (const auto& p : f.pts) {
    if (near_vertex(p, m, f.vertex_zone)) continue;
    const auto [piece, r] = nearest_piece(p, m);
    if (piece == (left_missing ? 2 : 1) && std::abs(r) < kTukeyC * f.scale) wall_pts.push_back(p);
  }
  if (wall_pts.size() < static_cast<std::size_t>(2 * kMinWall)) return false;
  const auto [wc, wd] = fit_line(wall_pts, f.scale);
  up = (left_missing ? wd.x() > 0 : wd.x() < 0) ? wd : Eigen::Vector2d(-wd);
  return meet_top(wc, up, side_top(m, left_missing), edge);
}

// The unseen wall's rim, u (m): the top on that side ends there (its innermost point, plus half
// the spacing of the top points). From the outside in, the top's run of points ends at the
// first wide gap (the groove); points beyond it near the top's height are the seen wall's rim.
// False with fewer than three top points on that side.
bool unseen_rim(const Eigen::Vector3d& q, const ProfileFit& f, bool left_missing,
                const Eigen::Vector2d& seen_edge, double& edge) {
  std::vector<double> tops;  // distance inwards: u on the left, -u on the right
  for (const auto& p : f.pts) {
    if (std::abs(p.y() - top_at(q, p.x())) > f.tau) continue;
    if (left_missing ? p.x() < seen_edge.x() - f.vertex_zone
                     : p.x() > seen_edge.x() + f.vertex_zone) {
      tops.push_back(left_missing ? p.x() : -p.x());
    }
  }
  if (tops.size() < 3) return false;
  std::sort(tops.begin(), tops.end());
  std::vector<double> gaps;
  for (std::size_t k = 1; k < tops.size(); ++k) gaps.push_back(tops[k] - tops[k - 1]);
  const double spacing = upper_median(gaps);
  std::size_t last = 0;
  while (last + 1 < tops.size() &&
         tops[last + 1] - tops[last] <= std::max(3 * spacing, 0.1 * f.W)) {
    ++last;
  }
  edge = (tops[last] + 0.5 * spacing) * (left_missing ? 1 : -1);
  return true;
}

// `one`'s opening from the unseen rim at u = `edge` to the seen wall's rim, and its root where
// the top normal through the top at u = `uc` meets the seen wall (running `up` to its rim).
// With `lean_out` (uc the rim of a bevel's square side), where that normal leans out of the
// opening (a frame tilted against the top by a few degrees: 0.4 mm at 8 mm depth), the rim
// moves out with the root, which keeps the model's vertex order. False when the two are
// parallel or the root falls outside the opening.
bool root_below(const Eigen::Vector2d& seen_edge, const Eigen::Vector2d& up, double edge, double uc,
                bool lean_out, bool left_missing, VModel& one) {
  const Eigen::Vector2d centre(uc, top_at(one.q, uc));
  const double slope = one.q[1] + 2 * one.q[2] * uc;
  Eigen::Matrix2d M;
  M.col(0) = Eigen::Vector2d(slope, -1).normalized();  // down the top normal
  M.col(1) = up;
  if (std::abs(M.determinant()) < 1e-6) return false;
  const Eigen::Vector2d ts = M.inverse() * (seen_edge - centre);
  one.root = centre + ts.x() * M.col(0);
  const double hair = 1e-6;
  one.u_left = left_missing ? edge : seen_edge.x();
  one.u_right = left_missing ? seen_edge.x() : edge;
  if (lean_out && left_missing) one.u_left = std::min(one.u_left, one.root.x() - hair);
  if (lean_out && !left_missing) one.u_right = std::max(one.u_right, one.root.x() + hair);
  return one.u_left < one.root.x() && one.root.x() < one.u_right;
}

// Whether the unseen wall, were it the mirror image of the seen one (running `up`) about the top
// normal at u = `uc`, would face the sensor at less than kShownIncidenceDeg: then it would
// have returned points, so it is not there and that side is square (a single bevel).
bool mirror_would_show(const ProfileFit& f, const Eigen::Vector3d& q, double uc,
                       const Eigen::Vector2d& up, bool left_missing) {
  const Eigen::Vector2d n_top = Eigen::Vector2d(-(q[1] + 2 * q[2] * uc), 1).normalized();
  const Eigen::Vector2d mirror = 2 * up.dot(n_top) * n_top - up;
  // The mirror wall's face towards the groove: a quarter turn towards the seen wall.
  const Eigen::Vector2d face = left_missing ? Eigen::Vector2d(mirror.y(), -mirror.x())
                                            : Eigen::Vector2d(-mirror.y(), mirror.x());
  return face.dot(f.view) > std::cos(deg_to_rad(kShownIncidenceDeg));
}

// Whether the seen wall of a square-sided `one` runs down to its foot: a square side hidden
// because the sensor looks along it sees the other wall to the bottom. A wall that ends far
// above the root is something else (a plate standing on a plate at 40 mm put a "foot" metres
// below a steep face).
bool reaches_foot(const std::vector<Eigen::Vector2d>& groove, const VModel& one,
                  const ProfileFit& f) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& p : groove) lowest = std::min(lowest, p.y());
  const double depth = one.top(one.root.x(), false) - one.root.y();
  return lowest - one.root.y() <= std::max(2 * f.vertex_zone, 0.2 * depth);
}

// 6. One wall seen, the other returned no or a few stray points (which the two-wall fit `m`
//    then bends into a vertical or flat wall): the unseen wall's edge is where the top surface
//    ends, half a sample spacing past the last top point. Hidden at a grazing angle, the V is
//    symmetric about the top normal through the opening's centre, so the root lies where that
//    axis meets the seen wall; hidden though its mirror image would face the sensor, that side
//    is square (a single bevel seen along its square side) and the root is at its foot. Where
//    the seam's first pass has decided (`mode`), that decides: a V's hidden wall is grazing
//    (at 640x480 and a 15 deg tilt, the seen wall's noisy dip made its mirror "show" in a few
//    sections, each then rooted at the rim's foot), a bevel's hidden side is its square one.
//    `two_wall` (m's profile) when that does not apply or fails to fit.
VProfile one_wall_v(const VModel& m, const VProfile& two_wall, const ProfileFit& f,
                    const std::vector<Eigen::Vector2d>& groove, const VFit& mode) {
  auto seen = [](int points, double dip) {
    return points >= 2 * kMinWall && dip >= 8 && dip <= kMaxDipDeg;
  };
  const bool left_seen = seen(two_wall.wall_left, two_wall.wall_left_deg);
  const bool right_seen = seen(two_wall.wall_right, two_wall.wall_right_deg);
  if (left_seen == right_seen) return two_wall;
  const bool left_missing = right_seen;
  Eigen::Vector2d seen_edge, up;
  double edge = 0;
  VModel one = m;
  if (!seen_wall(m, f, left_missing, seen_edge, up) ||
      !unseen_rim(side_top(m, !left_missing), f, left_missing, seen_edge, edge)) {
    return two_wall;
  }
  const double centre = 0.5 * (edge + seen_edge.x());
  const bool square = mode.symmetric     ? false
                      : mode.square != 0 ? mode.square == (left_missing ? -1 : 1)
                                         : mirror_would_show(f, m.q, centre, up, left_missing);
  // A square side's foot lies below its rim; on a seam known to be a bevel its rim moves out
  // with a foot that leans out, elsewhere the foot must lie (a hair) inside the opening.
  const bool lean_out = square && mode.square != 0;
  const double inside = square && !lean_out ? 1e-3 * f.W * (left_missing ? 1 : -1) : 0.0;
  if (!root_below(seen_edge, up, edge, square ? edge + inside : centre, lean_out, left_missing,
                  one) ||
      (square && !reaches_foot(groove, one, f))) {
    return two_wall;
  }
  VProfile alt = judge_v(one, true, f);
  alt.square_side = square;
  if (!alt.ok) alt.why = "one wall: " + alt.why;
  return alt;
}

// Height of the V `m`'s wall at u (m), between its edges: the line from the root to the
// edge on u's side.
double wall_height(const VModel& m, double u) {
  const Eigen::Vector2d e = u < m.root.x() ? m.edge_left() : m.edge_right();
  const double run = e.x() - m.root.x();
  if (std::abs(run) < 1e-9) return m.root.y();
  return m.root.y() + (e.y() - m.root.y()) * (u - m.root.x()) / run;
}

// 7. The root gap (m). Where the walls end at root faces, the slot between them shows the
//    table below the walls; a sharp V blurred by stereo matching reads above its walls there,
//    not below. The rays into the opening (w: across the view) sample the groove; each ray in
//    the groove's lower half that lands more than `band` (m) below the walls covers half the
//    way to its neighbours in w, and their sum, taken back to the top by the view's slant, is
//    the gap. Missed (0): a slot narrower than the blur, which reads shallow, and one seen at a
//    slant, whose rays meet its side faces just below the root faces. `rest`: the points of
//    the window not in the slot.
double root_gap(const VModel& m, const ProfileFit& f, double band, double depth,
                std::vector<Eigen::Vector2d>& rest) {
  const Eigen::Vector2d across(f.view.y(), -f.view.x());  // w: across the view
  const double wl = m.edge_left().dot(across), wr = m.edge_right().dot(across);
  const double lo = std::min(wl, wr), hi = std::max(wl, wr);
  std::vector<std::pair<double, bool>> rays;  // w, deep
  rest.clear();
  for (const auto& p : f.pts) {
    const double w = p.dot(across);
    const double above_root = wall_height(m, p.x()) - m.root.y();
    const bool low = p.x() > m.u_left && p.x() < m.u_right && above_root < 0.5 * depth;
    const bool ray = w > lo && w < hi;
    const bool deep = ray && low && nearest_piece(p, m).second < -band;
    if (ray) rays.push_back({w, deep});
    if (!deep) rest.push_back(p);
  }
  const double slant = std::abs(f.view.y());
  if (rays.size() < 2 * kMinWall || slant < 0.2) return 0.0;
  std::sort(rays.begin(), rays.end());
  double covered = 0;  // w covered by the deep rays: each takes half the way to its neighbours
  for (std::size_t k = 0; k < rays.size(); ++k) {
    if (!rays[k].second) continue;
    const double prev = k > 0 ? rays[k - 1].first : lo;
    const double next = k + 1 < rays.size() ? rays[k + 1].first : hi;
    covered += 0.5 * (next - prev);
  }
  return covered / slant;
}

// Steps 3 and 4: the V from the groove's run, refined free, then tied as `tie` where that
// fit converges. False, `m` unusable, when the free fit diverges.
bool refine_from(const std::vector<Eigen::Vector2d>& groove, const Eigen::Vector3d& q,
                 const ProfileFit& f, Tie tie, VModel& m) {
  m = initial_v(groove, q, f);
  if (!refine_v(f.pts, m, f.scale, f.vertex_zone, 0.1 * f.W, Tie::free)) return false;
  if (tie == Tie::free) return true;
  VModel tied = m;
  if (tie != Tie::symmetric) {  // the square side's edge straight above the root
    (tie == Tie::square_left ? tied.u_left : tied.u_right) =
        tied.root.x() + (tie == Tie::square_left ? -1 : 1) * VParams::kHair;
  }
  if (refine_v(f.pts, tied, f.scale, f.vertex_zone, 0.1 * f.W, tie)) m = tied;
  return true;
}

// A root gap seen straight through shows the table (a plate's thickness below the root
// faces) in a strip under the slot. Where no blur fills it, that strip holds the run's deepest
// tenth of points and the first V is seeded on the table, its walls overhanging (a clean
// 6 mm 50 deg V with a 0.5 mm gap at 0.45 m, 5 deg off square: no section passed, exit 4).
// So when the first V overhangs and the run's deepest point lies below every point beyond
// the widest half gap from it by more than kMinSlotJump noise bands, the run is seeded again
// without those points; the refit sees every point and the Tukey weights leave the strip out.
// There the strip lay 14-19 bands deeper; in the sweep's noisy scans the deepest points of
// overhanging V's lie within 2 (seeding every overhanging V again moved 8 of its 131 scans,
// 6 for the worse: a clamp's or a shadow's edge taken for a wall). Returns the judgement,
// `m` its model.
constexpr double kMinSlotJump = 4.0;

VProfile past_the_slot(const std::vector<Eigen::Vector2d>& groove, const Eigen::Vector3d& q,
                       const ProfileFit& f, Tie tie, VModel& m, const VProfile& failed) {
  if (failed.why != "a wall overhangs") return failed;
  const auto depth = [&](const Eigen::Vector2d& p) { return f.top(q, p.x()) - p.y(); };
  std::size_t deepest = 0;
  for (std::size_t k = 1; k < groove.size(); ++k) {
    if (depth(groove[k]) > depth(groove[deepest])) deepest = k;
  }
  std::vector<Eigen::Vector2d> rest;
  double rest_depth = 0;
  for (const auto& p : groove) {
    if (std::abs(p.x() - groove[deepest].x()) <= kMaxHalfGap) continue;
    rest.push_back(p);
    rest_depth = std::max(rest_depth, depth(p));
  }
  VModel again;
  if (rest.size() < 6 || depth(groove[deepest]) - rest_depth < kMinSlotJump * f.tau ||
      !refine_from(rest, q, f, tie, again))
    return failed;
  const VProfile judged = judge_v(again, false, f);
  if (!judged.ok) return failed;
  m = again;
  return judged;
}

// The two-wall V `two_wall` (model `m`, fitted tied by `tie`) with its root gap measured. On
// a seam with a gap (`refit_seam`), the slot's points drag the walls' fit down towards them (2 mm
// of table seen 3 mm below the root faces moved the root 0.5 mm), so the V is refitted
// without them.
VProfile with_root_gap(VModel& m, const ProfileFit& f, Tie tie, VProfile two_wall,
                       bool refit_seam) {
  // Twice the walls' rms: depths quantized to 1 mm put a wall's points on a staircase.
  const double band = 2 * std::max(two_wall.rms, f.sigma);
  std::vector<Eigen::Vector2d> rest;
  two_wall.gap = root_gap(m, f, band, two_wall.depth, rest);
  if (!refit_seam || !(two_wall.gap > 0)) return two_wall;
  VModel refit = m;
  if (!refine_v(rest, refit, f.scale, f.vertex_zone, 0.1 * f.W, tie)) return two_wall;
  VProfile again = judge_v(refit, false, f);
  if (!again.ok) return two_wall;
  again.gap = root_gap(refit, f, band, again.depth, rest);
  m = refit;
  return again;
}

// The V model fitted (steps 1-6), `ok` or why not.
VProfile fit_v(const std::vector<Eigen::Vector2d>& all, double half_window, VFit mode,
               const Eigen::Vector2d& view) {
  VProfile out;
  ProfileFit f;
  f.W = half_window;
  f.stepped = mode.stepped;
  f.seam_step = mode.step;
  f.view = view.normalized();
  f.pts.reserve(all.size());
  for (const auto& p : all) {
    if (std::abs(p.x()) <= f.W && p.allFinite()) f.pts.push_back(p);
  }
  if (f.pts.size() < 16) {
    out.why = "too few points";
    return out;
  }
  Eigen::Vector3d q;
  if (!fit_top(f, q)) {
    out.why = "no top surface";
    return out;
  }
  out.top = q;
  out.noise = f.sigma;
  const std::vector<Eigen::Vector2d> groove = groove_run(f, q, out.why);
  if (groove.empty()) return out;
  // 4. Joint robust fit of the whole V (root, both edges, the top's offset and slope) to the
  //    orthogonal distances, by Gauss-Newton with Tukey weights. Points near the three
  //    vertices do not count: rounded rims and the root gap are not the V's planes.
  f.scale = std::max(f.sigma, 0.005 * f.W);
  f.vertex_zone = std::max(2 * f.sigma, 0.06 * f.W);
  const Tie tie = mode.stepped      ? Tie::free
                  : mode.symmetric  ? Tie::symmetric
                  : mode.square < 0 ? Tie::square_left
                  : mode.square > 0 ? Tie::square_right
                                    : Tie::free;
  VModel m;
  if (!refine_from(groove, q, f, tie, m)) {
    out.why = "V fit did not converge";
    return out;
  }
  VProfile two_wall = judge_v(m, false, f);
  if (!two_wall.ok) two_wall = past_the_slot(groove, q, f, tie, m, two_wall);
  if (two_wall.ok) {
    const VProfile out_v = with_root_gap(m, f, tie, two_wall, mode.root_gap);  // may refit m
    return with_top_sides(out_v, f, m);
  }
  return one_wall_v(m, two_wall, f, groove, mode);
}

}  // namespace

VProfile fit_v_profile(const std::vector<Eigen::Vector2d>& all, double half_window, VFit mode,
                       const Eigen::Vector2d& view) {
  if (mode.kind == VFit::Kind::corner)
    return fit_corner_profile(all, half_window, mode.corner_leg, view);
  VProfile v = fit_v(all, half_window, mode, view);
  if (v.ok || mode.kind == VFit::Kind::groove) return v;
  // No V: a corner between two faces (fillet, lap) has no top surface for it to stand on.
  VProfile corner = fit_corner_profile(all, half_window, mode.corner_leg, view);
  return corner.ok ? corner : v;
}

}  // namespace groovetrace
