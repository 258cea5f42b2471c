// Stage 2 of the robust method: the V model fitted to one cross-section of the seam.
//
// The profile is (u across, v height): top surface, two walls. The top is fitted first, from
// the outer half of the window where no groove lies, as a robust quadratic (a pipe's crown
// bends 2-4 mm over a 20 mm window). Points clearly below it are the groove; each side of the
// deepest point is a wall, fitted as an orthogonal line (walls are steep, so residuals in v
// alone would weigh them wrongly). The rims and the root are left out of the wall fits:
// stereo matching rounds both off, and the root gap is not a wall. Root = the walls'
// intersection, edges = walls meet top.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/stats.hpp"
#include "robust/stages.hpp"
#include "robust/vmodel.hpp"

namespace groovetrace {
namespace {

using robust_detail::fit_poly;
using robust_detail::kLeftU;
using robust_detail::kQ0;
using robust_detail::kQ1;
using robust_detail::kRightU;
using robust_detail::kRootU;
using robust_detail::kRootV;
using robust_detail::nearest_piece;
using robust_detail::top_at;
using robust_detail::Vec6;
using robust_detail::VModel;

// Robust sigma of residuals: the rms of the smallest 80% of |r|, scaled to a Gaussian's sigma
// (0.6616 sigma for a Gaussian). Unlike the MAD it does not collapse to zero on depths
// quantized to 1 mm, where most of a flat's points share one value.
double robust_sigma(const std::vector<double>& r) {
  if (r.empty()) return 0.0;
  std::vector<double> a(r.size());
  for (std::size_t k = 0; k < r.size(); ++k) a[k] = r[k] * r[k];
  const std::size_t keep = std::max<std::size_t>(1, (r.size() * 8) / 10);
  std::nth_element(a.begin(), a.begin() + (keep - 1), a.end());
  double ss = 0;
  for (std::size_t k = 0; k < keep; ++k) ss += a[k];
  return std::sqrt(ss / keep) / 0.6616;
}

}  // namespace

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

// Angle (deg) by which `wall` (unit, from the edge towards the root) dips below the top's
// tangent `inward` (unit, along the top towards the groove). Positive: into the material.
double dip_deg(const Eigen::Vector2d& inward, const Eigen::Vector2d& wall, bool left) {
  const double cross = inward.x() * wall.y() - inward.y() * wall.x();
  return rad_to_deg(std::atan2(left ? -cross : cross, inward.dot(wall)));
}

bool near_vertex(const Eigen::Vector2d& p, const VModel& m, double zone) {
  const double z2 = zone * zone;
  return (p - m.root).squaredNorm() < z2 || (p - m.edge_left()).squaredNorm() < z2 ||
         (p - m.edge_right()).squaredNorm() < z2;
}

// Gauss-Newton on (root u, root v, u_left, u_right, q0, q1) with analytic derivatives and
// Tukey weights from the current residuals; steps halved until the robust cost drops.
bool refine_v(const std::vector<Eigen::Vector2d>& pts, VModel& m, double scale, double zone,
              double coarse, bool symmetric) {
  // Free: x = (root u, root v, u_left, u_right, q0, q1). Symmetric: x[2] is the half width h
  // and x[3] is unused (held at 0); the edges lie at u_c -+ h, u_c the foot of the top normal
  // through the root (on the top's tangent line there), so both walls dip alike.
  auto centre_u = [&](const Vec6& x) {
    const double s = x[5] + 2 * m.q[2] * x[0];
    const double gap = x[4] + x[5] * x[0] + m.q[2] * x[0] * x[0] - x[1];
    return x[0] - s * gap / (1 + s * s);
  };
  auto pack = [&](const VModel& v) {
    Vec6 x;
    x << v.root.x(), v.root.y(), v.u_left, v.u_right, v.q[0], v.q[1];
    if (symmetric) {
      x[2] = 0.5 * (v.u_right - v.u_left);
      x[3] = 0;
    }
    return x;
  };
  auto unpack = [&](const Vec6& x) {
    VModel v = m;
    v.root = {x[0], x[1]};
    v.u_left = x[2];
    v.u_right = x[3];
    v.q[0] = x[4];
    v.q[1] = x[5];
    if (symmetric) {
      const double uc = centre_u(x);
      v.u_left = uc - x[2];
      v.u_right = uc + x[2];
    }
    return v;
  };
  // Symmetric: d(free parameters) / d(x), for the chain rule. With s the top's slope at the
  // root and g its height above the root, u_c = root u - s g / (1 + s^2).
  auto chain = [&](const Vec6& x) {
    Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Identity();
    if (!symmetric) return M;
    const double s = x[5] + 2 * m.q[2] * x[0];
    const double g = x[4] + x[5] * x[0] + m.q[2] * x[0] * x[0] - x[1];
    const double n = 1 + s * s;
    const double df_ds = g * (1 - s * s) / (n * n), df_dg = s / n;
    Vec6 du = Vec6::Zero();  // d u_c / d x
    du[0] = 1 - (df_ds * 2 * m.q[2] + df_dg * s);
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
  };
  double c = kTukeyC * scale;
  auto cost = [&](const VModel& v) {
    double sum = 0;
    for (const auto& p : pts) {
      if (near_vertex(p, v, zone)) continue;
      const double r = nearest_piece(p, v).second / c;
      const double a = 1 - r * r;
      sum += std::abs(r) >= 1 ? 1.0 : 1 - a * a * a;
    }
    return sum;
  };
  Vec6 x = pack(m);
  // Graduated: a wide Tukey window first, so that a start a few millimetres off still sees
  // the walls, then halving down to the noise.
  for (double stage = std::max(coarse, scale);; stage = std::max(scale, 0.5 * stage)) {
    c = kTukeyC * stage;
    double f = cost(unpack(x));
    for (int iter = 0; iter < 30; ++iter) {
      const VModel cur = unpack(x);
      const Eigen::Matrix<double, 6, 6> M = chain(x);
      Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
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
      const Vec6 step = -JtJ.ldlt().solve(Jtr);
      if (!step.allFinite()) return false;
      double t = 1.0;
      bool improved = false;
      for (int half = 0; half < 8; ++half, t *= 0.5) {
        const Vec6 xn = x + t * step;
        const VModel vn = unpack(xn);
        if (!(vn.u_left < vn.root.x() && vn.root.x() < vn.u_right)) continue;
        const double fn = cost(vn);
        if (fn < f) {
          x = xn;
          improved = f - fn > 1e-6 * (1 + f);
          f = fn;
          break;
        }
      }
      if (!improved || (t * step).norm() < 1e-6) break;
    }
    if (stage <= scale) break;
  }
  m = unpack(x);
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

// Orthogonal (total least squares) line through `pts`, Tukey-reweighted on the perpendicular
// residual: returns a point on it and its unit direction.
std::pair<Eigen::Vector2d, Eigen::Vector2d> fit_line(const std::vector<Eigen::Vector2d>& pts,
                                                     double scale) {
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

struct PieceStats {
  int count[4] = {0, 0, 0, 0};  // points fitting each piece (Tukey inliers)
  double wall_rms = 0;          // rms distance of the wall inliers
  double top_sigma = 0;         // robust sigma of the top inliers
  double top_outliers = 0;      // share of the outer points that do not fit the top
};

PieceStats piece_stats(const std::vector<Eigen::Vector2d>& pts, const VModel& m, double scale,
                       double zone) {
  PieceStats st;
  double ss = 0;
  int nw = 0, outer = 0, outer_bad = 0;
  std::vector<double> top_r;
  const double c = kTukeyC * scale;
  for (const auto& p : pts) {
    const auto [piece, r] = nearest_piece(p, m);
    const bool is_top = piece == 0 || piece == 3;
    if (is_top && (p.x() < m.u_left - zone || p.x() > m.u_right + zone)) {
      ++outer;
      if (std::abs(r) >= c) ++outer_bad;
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
  return st;
}

}  // namespace

VProfile fit_v_profile(const std::vector<Eigen::Vector2d>& all, double half_window,
                       bool symmetric) {
  VProfile out;
  const double W = half_window;
  std::vector<Eigen::Vector2d> pts;
  pts.reserve(all.size());
  for (const auto& p : all) {
    if (std::abs(p.x()) <= W && p.allFinite()) pts.push_back(p);
  }
  if (pts.size() < 16) {
    out.why = "too few points";
    return out;
  }

  // 1. Top surface from the outer half of the window.
  std::vector<Eigen::Vector2d> outer;
  int n_left = 0, n_right = 0;
  for (const auto& p : pts) {
    if (std::abs(p.x()) >= 0.5 * W) {
      outer.push_back(p);
      (p.x() < 0 ? n_left : n_right) += 1;
    }
  }
  if (n_left < 3 && n_right < 3) {
    out.why = "no top surface";
    return out;
  }
  // A quadratic needs both sides; its curvature is bounded (radius >= W) so that it cannot
  // bend into the groove.
  auto [q, sigma] = fit_poly(outer, n_left >= 3 && n_right >= 3 ? 2 : 1);
  if (std::abs(q[2]) > 0.5 / W) std::tie(q, sigma) = fit_poly(outer, 1);
  out.top = q;
  out.noise = sigma;
  // Points within tau of the top are top; tau covers the sensor noise with a floor for
  // noise-free scans (2% of the window, 0.4 mm at the default scale).
  const double tau = std::max(3.0 * sigma, 0.02 * W);

  // 2. The groove: the run of points clearly below the top that holds the deepest point near
  //    the centre. Runs split at gaps in u (other dips, the table beyond an edge).
  std::vector<Eigen::Vector2d> below;
  for (const auto& p : pts) {
    if (p.y() - top_at(q, p.x()) < -tau) below.push_back(p);
  }
  if (below.size() < 6) {
    out.why = "nothing below the top surface";
    return out;
  }
  std::sort(below.begin(), below.end(),
            [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); });
  const double gap = 0.15 * W;
  std::size_t best_lo = 0, best_hi = 0;
  double best_mass = -1;
  for (std::size_t lo = 0; lo < below.size();) {
    std::size_t hi = lo + 1;
    while (hi < below.size() && below[hi].x() - below[hi - 1].x() <= gap) ++hi;
    double mass = 0;
    bool central = false;
    for (std::size_t k = lo; k < hi; ++k) {
      mass += top_at(q, below[k].x()) - below[k].y();
      central = central || std::abs(below[k].x()) <= 0.5 * W;
    }
    if (central && mass > best_mass) {
      best_mass = mass;
      best_lo = lo;
      best_hi = hi;
    }
    lo = hi;
  }
  if (best_mass < 0 || best_hi - best_lo < 6) {
    out.why = "no groove near the centre";
    return out;
  }
  const std::vector<Eigen::Vector2d> groove(below.begin() + best_lo, below.begin() + best_hi);
  const double g_lo = groove.front().x(), g_hi = groove.back().x();

  // 3. Initial V from the run: root at its deepest points, edges at its ends.
  std::vector<double> depths, deep_u;
  for (const auto& p : groove) depths.push_back(top_at(q, p.x()) - p.y());
  std::vector<double> sorted_depths = depths;
  std::sort(sorted_depths.begin(), sorted_depths.end());
  const double d90 = sorted_depths[(sorted_depths.size() * 9) / 10];
  for (std::size_t k = 0; k < groove.size(); ++k) {
    if (depths[k] >= 0.8 * d90) deep_u.push_back(groove[k].x());
  }
  const double u0 = upper_median(deep_u);
  VModel m;
  m.q = q;
  m.root = Eigen::Vector2d(u0, top_at(q, u0) - d90);
  m.u_left = std::min(g_lo, u0 - 0.1 * W);
  m.u_right = std::max(g_hi, u0 + 0.1 * W);

  // 4. Joint robust fit of the whole V (root, both edges, the top's offset and slope) to the
  //    orthogonal distances, by Gauss-Newton with Tukey weights. Points near the three
  //    vertices do not count: rounded rims and the root gap are not the V's planes.
  const double scale = std::max(sigma, 0.005 * W);
  const double vertex_zone = std::max(2 * sigma, 0.06 * W);
  if (!refine_v(pts, m, scale, vertex_zone, 0.1 * W, false)) {
    out.why = "V fit did not converge";
    return out;
  }
  if (symmetric) {
    VModel sym = m;
    if (refine_v(pts, sym, scale, vertex_zone, 0.1 * W, true)) m = sym;
  }
  const Eigen::Vector2d el = m.edge_left(), er = m.edge_right();
  out.top = m.q;
  out.root = m.root;
  out.edge_left = el;
  out.edge_right = er;
  // Each side's top on its own, as a line from the outer half: a real groove's two top sides
  // continue each other (curved or not, their lines meet above the centre at one height); a
  // step down to a table fitted by one tilted line does not.
  double top_step = 0;
  {
    std::vector<Eigen::Vector2d> lo, hi;
    for (const auto& p : outer) (p.x() < 0 ? lo : hi).push_back(p);
    if (lo.size() >= 3 && hi.size() >= 3) {
      const Eigen::Vector3d ql = fit_poly(lo, 1).first, qr = fit_poly(hi, 1).first;
      top_step = std::abs(ql[0] - qr[0]);
    }
  }

  // 5. Derived quantities and the test: is it a V? Both walls dip into the material at a
  //    plausible angle (a vertical step to a table is ~90 deg, a convex edge negative), both
  //    top sides and both walls carry points, the groove lies inside the window and is deeper
  //    than the noise.
  const int min_wall = 4;
  auto finish = [&](const VModel& v, bool one_wall) {
    VProfile o;
    o.one_wall = one_wall;
    const Eigen::Vector2d el = v.edge_left(), er = v.edge_right();
    o.top = v.q;
    o.root = v.root;
    o.edge_left = el;
    o.edge_right = er;
    const PieceStats st = piece_stats(pts, v, scale, vertex_zone);
    o.top_left = st.count[0];
    o.wall_left = st.count[1];
    o.wall_right = st.count[2];
    o.top_right = st.count[3];
    o.rms = st.wall_rms;
    o.noise = st.top_sigma > 0 ? st.top_sigma : sigma;
    o.width = (er - el).norm();
    o.depth = top_at(v.q, v.root.x()) - v.root.y();
    const Eigen::Vector2d to_root_l = (v.root - el).normalized();
    const Eigen::Vector2d to_root_r = (v.root - er).normalized();
    const Eigen::Vector2d tl = Eigen::Vector2d(1, v.q[1] + 2 * v.q[2] * el.x()).normalized();
    const Eigen::Vector2d tr = Eigen::Vector2d(1, v.q[1] + 2 * v.q[2] * er.x()).normalized();
    o.wall_left_deg = dip_deg(tl, to_root_l, true);
    o.wall_right_deg = dip_deg(-tr, to_root_r, false);
    o.opening_deg = rad_to_deg(std::acos(std::clamp(to_root_l.dot(to_root_r), -1.0, 1.0)));
    o.bisector = (-to_root_l - to_root_r).normalized();
    const int wall_min = one_wall ? 0 : min_wall;
    if (!o.root.allFinite() || !el.allFinite() || !er.allFinite()) {
      o.why = "V fit did not converge";
    } else if (o.wall_left_deg < 8 || o.wall_right_deg < 8) {
      o.why = "a wall is too flat";
    } else if (o.wall_left_deg > 86 || o.wall_right_deg > 86) {
      o.why = "a wall is vertical or overhangs";
    } else if (o.top_left < 3 || o.top_right < 3) {
      o.why = "a top surface is missing";
    } else if (o.wall_left < wall_min || o.wall_right < wall_min) {
      o.why = "a wall is missing";
    } else if (o.depth < 1.5 * tau) {
      o.why = "too shallow for the noise";
    } else if (el.x() < -0.9 * W || er.x() > 0.9 * W || el.x() >= er.x()) {
      o.why = "groove leaves the window";
    } else if (o.rms > 0.35 * o.depth) {
      o.why = "walls are not straight";
    } else if (st.top_outliers > 0.5) {
      o.why = "top surfaces disagree";
    } else if (top_step > std::max(2 * tau, 0.5 * o.depth)) {
      o.why = "top surfaces at different heights (a step)";
    } else {
      o.ok = true;
    }
    return o;
  };
  out = finish(m, false);
  if (out.ok) return out;

  // 6. One wall seen, the other at a grazing angle (no or a few stray points, which the
  //    two-wall fit then bends into a vertical or flat wall): the unseen wall's edge is where
  //    the top surface ends, half a sample spacing past the last top point, and the V is
  //    symmetric about the top normal through the opening's centre, so the root lies where
  //    that axis meets the seen wall.
  const PieceStats st = piece_stats(pts, m, scale, vertex_zone);
  const double dip_l = out.wall_left_deg, dip_r = out.wall_right_deg;
  const bool left_seen = st.count[1] >= 2 * min_wall && dip_l >= 8 && dip_l <= 86;
  const bool right_seen = st.count[2] >= 2 * min_wall && dip_r >= 8 && dip_r <= 86;
  if (left_seen == right_seen) return out;
  const bool left_missing = right_seen;
  // The seen wall, refitted alone (the failed fit's root may have been dragged by strays).
  std::vector<Eigen::Vector2d> wall_pts;
  for (const auto& p : pts) {
    if (near_vertex(p, m, vertex_zone)) continue;
    const auto [piece, r] = nearest_piece(p, m);
    if (piece == (left_missing ? 2 : 1) && std::abs(r) < kTukeyC * scale) wall_pts.push_back(p);
  }
  if (wall_pts.size() < static_cast<std::size_t>(2 * min_wall)) return out;
  const auto [wc, wd] = fit_line(wall_pts, scale);
  // Up the wall, towards the top on the seen side.
  const Eigen::Vector2d up = (left_missing ? wd.x() > 0 : wd.x() < 0) ? wd : Eigen::Vector2d(-wd);
  Eigen::Vector2d seen_edge;
  if (!meet_top(wc, up, m.q, seen_edge)) return out;
  // The unseen wall's rim: the top on that side ends there (its innermost point, plus half the
  // spacing of the top points).
  std::vector<double> tops;
  for (const auto& p : pts) {
    if (std::abs(p.y() - top_at(m.q, p.x())) > tau) continue;
    if (left_missing ? p.x() < seen_edge.x() - vertex_zone : p.x() > seen_edge.x() + vertex_zone) {
      tops.push_back(left_missing ? p.x() : -p.x());
    }
  }
  if (tops.size() < 3) return out;
  // From the outside in, the top's run of points ends at the first wide gap (the groove);
  // points beyond it near the top's height are the seen wall's rim.
  std::sort(tops.begin(), tops.end());
  std::vector<double> gaps;
  for (std::size_t k = 1; k < tops.size(); ++k) gaps.push_back(tops[k] - tops[k - 1]);
  const double spacing = upper_median(gaps);
  std::size_t last = 0;
  while (last + 1 < tops.size() && tops[last + 1] - tops[last] <= std::max(3 * spacing, 0.1 * W)) {
    ++last;
  }
  const double edge = (tops[last] + 0.5 * spacing) * (left_missing ? 1 : -1);
  const double uc = 0.5 * (edge + seen_edge.x());
  const Eigen::Vector2d centre(uc, top_at(m.q, uc));
  const Eigen::Vector2d axis = -Eigen::Vector2d(-(m.q[1] + 2 * m.q[2] * uc), 1).normalized();
  Eigen::Matrix2d M;
  M.col(0) = axis;
  M.col(1) = up;
  if (std::abs(M.determinant()) < 1e-6) return out;
  const Eigen::Vector2d ts = M.inverse() * (seen_edge - centre);
  VModel one = m;
  one.root = centre + ts.x() * axis;
  one.u_left = left_missing ? edge : seen_edge.x();
  one.u_right = left_missing ? seen_edge.x() : edge;
  if (!(one.u_left < one.root.x() && one.root.x() < one.u_right)) return out;
  VProfile alt = finish(one, true);
  if (!alt.ok) alt.why = "one wall: " + alt.why;
  return alt;
}

}  // namespace groovetrace
