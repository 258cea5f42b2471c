// Stage 3 of the robust method, second half: an ordered node path (node_order.cpp) into a
// smooth seam curve, by local fits over arc length, piecewise between sharp corners so that
// an L keeps its corner.

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "core/stats.hpp"
#include "robust/stages.hpp"

namespace groovetrace {
namespace {

// The curve's positions are smoothed over this many half-windows (quadratic fits).
constexpr double kCurveWindow = 3.0;
// A turn sharper than this between chords of 3 half-windows is a corner: an L turns 90 deg,
// a 60 mm bend 17 deg, and root noise on a far scan some 10-20 deg.
constexpr double kCornerDeg = 45.0;

// Local line fit of positions against arc length around s0 (tricube weights over h).
// Returns position and unit direction; false with too little support.
bool local_line(const std::vector<Eigen::Vector3d>& p, const std::vector<double>& s, double s0,
                double h, Eigen::Vector3d& pos, Eigen::Vector3d& dir) {
  double sw = 0, ss = 0, sss = 0;
  Eigen::Vector3d sp = Eigen::Vector3d::Zero(), ssp = Eigen::Vector3d::Zero();
  int used = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double d = s[k] - s0;
    if (std::abs(d) >= h) continue;
    const double w = tricube_weight(d, h);
    sw += w;
    ss += w * d;
    sss += w * d * d;
    sp += w * p[k];
    ssp += w * d * p[k];
    ++used;
  }
  if (used < 2 || sw <= 0) return false;
  const double det = sw * sss - ss * ss;
  if (det <= 1e-12 * sw * sw * h * h) {
    // All support on one side at one spot: constant fit, no direction.
    pos = sp / sw;
    return false;
  }
  const Eigen::Vector3d slope = (sw * ssp - ss * sp) / det;
  pos = (sp - slope * ss) / sw;
  if (!(slope.norm() > 1e-9)) return false;
  dir = slope.normalized();
  return true;
}

// Local quadratic fit of positions against arc length around s0 (tricube weights over h):
// a seam bending round a pipe (radius ~40 mm) turns 25 degrees within a window, which a line
// would cut short, tilting the sections. Falls back to the line fit with too little support.
bool local_quad(const std::vector<Eigen::Vector3d>& p, const std::vector<double>& s, double s0,
                double h, Eigen::Vector3d& pos, Eigen::Vector3d& dir) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();  // rows: basis, columns: x y z
  int used = 0;
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double d = s[k] - s0;
    if (std::abs(d) >= h) continue;
    const double w = tricube_weight(d, h);
    const Eigen::Vector3d b(1, d / h, (d / h) * (d / h));
    A += w * b * b.transpose();
    B += w * b * p[k].transpose();
    ++used;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  // A quadratic needs support on a good part of the window (one-sided ends included).
  if (used >= 6 && hi - lo > 0.5 * h) {
    Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
    if (ldlt.info() == Eigen::Success && std::abs(A.determinant()) > 1e-9 * std::pow(A(0, 0), 3)) {
      const Eigen::Matrix3d C = ldlt.solve(B);
      if (C.allFinite()) {
        pos = C.row(0).transpose();
        const Eigen::Vector3d slope = C.row(1).transpose();
        if (slope.norm() > 1e-12) {
          dir = slope.normalized();
          return true;
        }
      }
    }
  }
  return local_line(p, s, s0, std::min(h, h), pos, dir);
}

}  // namespace

SeamCurve smooth_curve(const std::vector<Eigen::Vector3d>& ordered, bool closed, double half_window,
                       double spacing, const std::vector<Eigen::Vector3d>& normals) {
  SeamCurve out;
  out.closed = closed;
  const std::size_t n = ordered.size();
  if (n < 2 || !(spacing > 0)) return out;
  std::vector<double> s(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) s[k] = s[k - 1] + (ordered[k] - ordered[k - 1]).norm();
  const double L = s.back() + (closed ? (ordered.front() - ordered.back()).norm() : 0.0);
  if (!(L > 0)) return out;

  // Positions by arc length; a closed curve is unrolled three times so that windows wrap.
  std::vector<Eigen::Vector3d> P;
  std::vector<double> S;
  for (int rep = closed ? -1 : 0; rep <= (closed ? 1 : 0); ++rep) {
    for (std::size_t k = 0; k < n; ++k) {
      P.push_back(ordered[k]);
      S.push_back(s[k] + rep * L);
    }
  }
  auto nodes_in = [&](double lo, double hi, std::vector<Eigen::Vector3d>& pp,
                      std::vector<double>& ps) {
    pp.clear();
    ps.clear();
    for (std::size_t k = 0; k < P.size(); ++k) {
      if (S[k] >= lo && S[k] <= hi) {
        pp.push_back(P[k]);
        ps.push_back(S[k]);
      }
    }
  };

  // Sharp corners: the turn between the chords over `a` before and after a node, kept at its
  // maximum within 2a (a gap at a corner turns the chords twice, once at each end). A 60 mm radius
  // bends ~12 deg over a = 12 mm, an L-corner 90 deg.
  const double a = 3 * half_window;
  auto at = [&](double s0) {
    Eigen::Vector3d pos = Eigen::Vector3d::Constant(NAN), dir;
    local_line(P, S, s0, 0.5 * half_window, pos, dir);
    if (!pos.allFinite()) {
      std::size_t best = 0;
      for (std::size_t k = 1; k < S.size(); ++k) {
        if (std::abs(S[k] - s0) < std::abs(S[best] - s0)) best = k;
      }
      pos = P[best];
    }
    return pos;
  };
  std::vector<double> turn(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    if (!closed && (s[k] < a || s[k] > s.back() - a)) continue;
    const Eigen::Vector3d c0 = at(s[k]);
    Eigen::Vector3d d1 = c0 - at(s[k] - a);
    Eigen::Vector3d d2 = at(s[k] + a) - c0;
    if (normals.size() == n && normals[k].allFinite()) {
      const Eigen::Vector3d nk = normals[k].normalized();
      d1 -= d1.dot(nk) * nk;
      d2 -= d2.dot(nk) * nk;
    }
    d1.normalize();
    d2.normalize();
    turn[k] = rad_to_deg(std::acos(std::clamp(d1.dot(d2), -1.0, 1.0)));
  }
  // A corner must hold at the legs' scale too: lines fitted over 2a on either side meet at
  // kCornerDeg or more. A zigzag of the node path (a stray node at 0.5 m and 640x480) turns
  // the short chords, not the legs; cutting there would join two straight pieces in a spike.
  auto legs_turn = [&](std::size_t k) {
    Eigen::Vector3d p1, d1, p2, d2;
    if (!local_line(P, S, s[k] - a, a, p1, d1) || !local_line(P, S, s[k] + a, a, p2, d2)) {
      return 180.0;  // too little on one side to tell: trust the chords
    }
    if (normals.size() == n && normals[k].allFinite()) {
      const Eigen::Vector3d nk = normals[k].normalized();
      d1 -= d1.dot(nk) * nk;
      d2 -= d2.dot(nk) * nk;
    }
    return rad_to_deg(std::acos(std::clamp(d1.normalized().dot(d2.normalized()), -1.0, 1.0)));
  };
  std::vector<double> cuts;
  for (std::size_t k = 0; k < n; ++k) {
    if (turn[k] < kCornerDeg) continue;
    bool is_max = true;
    for (std::size_t j = 0; j < n && is_max; ++j) {
      double ds = std::abs(s[j] - s[k]);
      if (closed) ds = std::min(ds, L - ds);
      if (j != k && ds < 2 * a && (turn[j] > turn[k] || (turn[j] == turn[k] && j < k))) {
        is_max = false;
      }
    }
    if (is_max && legs_turn(k) >= kCornerDeg) cuts.push_back(s[k]);
  }

  // Pieces between corners; piece j runs from corner j (closed) or the start.
  std::vector<std::pair<double, double>> pieces;
  if (cuts.empty()) {
    pieces.emplace_back(closed ? -0.5 * L : 0.0, closed ? 1.5 * L : s.back());
  } else if (closed) {
    for (std::size_t k = 0; k < cuts.size(); ++k) {
      pieces.emplace_back(cuts[k], k + 1 < cuts.size() ? cuts[k + 1] : cuts[0] + L);
    }
  } else {
    double lo = 0;
    for (double c : cuts) {
      pieces.emplace_back(lo, c);
      lo = c;
    }
    pieces.emplace_back(lo, s.back());
  }
  const std::size_t np = pieces.size();
  // Corner j joins the end of piece j and the start of piece j + 1 (wrapping when closed):
  // where the two pieces' end lines come closest.
  struct Corner {
    bool ok = false;
    Eigen::Vector3d point, d_in, d_out;  // d_in along the piece before, d_out after
  };
  std::vector<Corner> corners(np);
  std::vector<Eigen::Vector3d> pp, pn;
  std::vector<double> sp, sn;
  for (std::size_t j = 0; j < np; ++j) {
    if (!closed && j + 1 == np) break;
    if (cuts.empty()) break;
    const auto [lo1, hi1] = pieces[j];
    auto [lo2, hi2] = pieces[(j + 1) % np];
    if (j + 1 == np) {
      lo2 += L;
      hi2 += L;
    }
    nodes_in(lo1, hi1, pp, sp);
    nodes_in(lo2, hi2, pn, sn);
    const double r1 = std::min(3 * half_window, 0.5 * (hi1 - lo1));
    const double r2 = std::min(3 * half_window, 0.5 * (hi2 - lo2));
    Eigen::Vector3d p1, d1, p2, d2;
    if (!local_line(pp, sp, hi1 - r1, 2 * r1, p1, d1) ||
        !local_line(pn, sn, lo2 + r2, 2 * r2, p2, d2)) {
      continue;
    }
    const Eigen::Vector3d w = p1 - p2;
    const double b = d1.dot(d2), d = d1.dot(w), e = d2.dot(w);
    const double den = 1 - b * b;
    if (den < 1e-3) continue;
    const double t1 = (b * e - d) / den, t2 = (e - b * d) / den;
    corners[j] = {true, 0.5 * ((p1 + t1 * d1) + (p2 + t2 * d2)), d1, d2};
  }

  // The polyline: each piece's smoothed samples, trimmed where they overshoot its corners,
  // then the corner at its end.
  std::vector<Eigen::Vector3d> line;
  std::vector<std::uint8_t> corner_flag;
  for (std::size_t j = 0; j < np; ++j) {
    const auto [lo, hi] = pieces[j];
    nodes_in(lo - half_window, hi + half_window, pp, sp);
    // Only the piece's own nodes: a window must not reach round a corner.
    std::vector<Eigen::Vector3d> own;
    std::vector<double> own_s;
    for (std::size_t k = 0; k < pp.size(); ++k) {
      if (cuts.empty() || (sp[k] >= lo && sp[k] <= hi)) {
        own.push_back(pp[k]);
        own_s.push_back(sp[k]);
      }
    }
    const Corner* start = nullptr;
    if (!cuts.empty() && (j > 0 || closed)) {
      const Corner& c = corners[(j + np - 1) % np];
      if (c.ok) start = &c;
    }
    const Corner* end = corners[j].ok ? &corners[j] : nullptr;
    const double a0 = cuts.empty() && closed ? 0.0 : lo;
    const double a1 = cuts.empty() && closed ? L : hi;
    const int steps = std::max(1, static_cast<int>(std::ceil((a1 - a0) / (0.5 * spacing))));
    for (int k = 0; k <= steps; ++k) {
      if (cuts.empty() && closed && k == steps) break;  // the ring's end is its start
      const double s0 = a0 + (a1 - a0) * k / steps;
      Eigen::Vector3d pos = Eigen::Vector3d::Constant(NAN), dir;
      local_quad(own, own_s, s0, kCurveWindow * half_window, pos, dir);
      if (!pos.allFinite()) continue;
      if (start && (pos - start->point).dot(start->d_out) <= 0) continue;
      if (end && (pos - end->point).dot(end->d_in) >= 0) continue;
      line.push_back(pos);
      corner_flag.push_back(0);
    }
    if (end) {
      line.push_back(end->point);
      corner_flag.push_back(1);
    }
  }
  if (closed && !line.empty()) {
    line.push_back(line.front());
    corner_flag.push_back(corner_flag.front());
  }
  std::vector<double> ls(line.size(), 0.0);
  for (std::size_t k = 1; k < line.size(); ++k) ls[k] = ls[k - 1] + (line[k] - line[k - 1]).norm();
  if (line.size() < 2 || !(ls.back() > 0)) return out;
  out.length = ls.back();
  for (std::size_t k = 0; k + (closed ? 1 : 0) < line.size(); ++k) {
    if (corner_flag[k]) out.corners.push_back(ls[k]);
  }

  // Uniform resampling at `spacing`.
  const int m = std::max(1, static_cast<int>(std::round(out.length / spacing)));
  std::size_t seg = 0;
  for (int k = 0; k <= m; ++k) {
    if (closed && k == m) break;
    const double s0 = out.length * k / m;
    while (seg + 2 < line.size() && ls[seg + 1] < s0) ++seg;
    const double span = ls[seg + 1] - ls[seg];
    const double f = span > 0 ? std::clamp((s0 - ls[seg]) / span, 0.0, 1.0) : 0.0;
    out.points.push_back(line[seg] + f * (line[seg + 1] - line[seg]));
    out.s.push_back(s0);
  }
  // Tangents by central differences, one-sided where a corner lies between the neighbours.
  const std::size_t q = out.points.size();
  out.tangents.resize(q);
  auto corner_between = [&](double s1, double s2) {
    for (double c : out.corners) {
      if ((c > s1 && c < s2) || (c > s2 && c < s1)) return true;
    }
    return false;
  };
  for (std::size_t k = 0; k < q; ++k) {
    std::size_t prev = k, next = k;
    if (k > 0 || closed) prev = (k + q - 1) % q;
    if (k + 1 < q || closed) next = (k + 1) % q;
    const double sp0 = prev < k ? out.s[prev] : out.s[prev] - out.length;
    const double sn0 = next > k ? out.s[next] : out.s[next] + out.length;
    if (prev != k && corner_between(sp0, out.s[k])) prev = k;
    if (next != k && corner_between(out.s[k], sn0)) next = k;
    const Eigen::Vector3d d = out.points[next] - out.points[prev];
    out.tangents[k] = d.norm() > 0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
  }
  return out;
}

}  // namespace groovetrace