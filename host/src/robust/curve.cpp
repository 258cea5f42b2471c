// Stage 3 of the robust method, second half: an ordered node path (node_order.cpp) into a
// smooth seam curve, by local fits over arc length, piecewise between sharp corners so that
// an L keeps its corner.

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

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
  return local_line(p, s, s0, h, pos, dir);
}

// The ordered nodes by arc length. A closed curve is unrolled three times (one length before
// and one after) so that windows wrap.
struct ArcNodes {
  std::vector<Eigen::Vector3d> P;  // positions (m)
  std::vector<double> S;           // their arc lengths (m)

  // The nodes with lo <= S <= hi (m), into pp and ps.
  void within(double lo, double hi, std::vector<Eigen::Vector3d>& pp,
              std::vector<double>& ps) const {
    pp.clear();
    ps.clear();
    for (std::size_t k = 0; k < P.size(); ++k) {
      if (S[k] >= lo && S[k] <= hi) {
        pp.push_back(P[k]);
        ps.push_back(S[k]);
      }
    }
  }

  // The curve at arc length s0 (m): a local line over h (m), else the nearest node.
  Eigen::Vector3d at(double s0, double h) const {
    Eigen::Vector3d pos = Eigen::Vector3d::Constant(NAN), dir;
    local_line(P, S, s0, h, pos, dir);
    if (!pos.allFinite()) {
      std::size_t best = 0;
      for (std::size_t k = 1; k < S.size(); ++k) {
        if (std::abs(S[k] - s0) < std::abs(S[best] - s0)) best = k;
      }
      pos = P[best];
    }
    return pos;
  }
};

// What smooth_curve works on: the ordered nodes (m) with their surface normals (one per node,
// or none), their arc lengths and the curve's length.
struct NodeCurve {
  const std::vector<Eigen::Vector3d>& ordered;
  const std::vector<Eigen::Vector3d>& normals;
  bool closed;
  double half_window;     // m
  std::vector<double> s;  // arc length of each node (m)
  double L = 0;           // length (m); closed: back to the start
  ArcNodes arc;
};

// The turn (deg) from direction d1 to d2 at node k, measured in the surface (the plane normal
// to the node's normal, when it has one): depth noise of the roots must not look like a corner.
double turn_deg(const NodeCurve& c, std::size_t k, Eigen::Vector3d d1, Eigen::Vector3d d2) {
  if (c.normals.size() == c.s.size() && c.normals[k].allFinite()) {
    const Eigen::Vector3d nk = c.normals[k].normalized();
    d1 -= d1.dot(nk) * nk;
    d2 -= d2.dot(nk) * nk;
  }
  return rad_to_deg(std::acos(std::clamp(d1.normalized().dot(d2.normalized()), -1.0, 1.0)));
}

// The turn (deg) at node k between the chords over `a` (m) before and after it.
double chord_turn(const NodeCurve& c, std::size_t k, double a) {
  const double h = 0.5 * c.half_window;
  const Eigen::Vector3d c0 = c.arc.at(c.s[k], h);
  return turn_deg(c, k, c0 - c.arc.at(c.s[k] - a, h), c.arc.at(c.s[k] + a, h) - c0);
}

// The turn (deg) at node k between lines fitted over 2a (m) on either side: a zigzag of the
// node path (a stray node at 0.5 m and 640x480) turns the short chords, not the legs. 180 when
// one side has too little to tell: the chords are trusted.
double legs_turn(const NodeCurve& c, std::size_t k, double a) {
  Eigen::Vector3d p1, d1, p2, d2;
  if (!local_line(c.arc.P, c.arc.S, c.s[k] - a, a, p1, d1) ||
      !local_line(c.arc.P, c.arc.S, c.s[k] + a, a, p2, d2)) {
    return 180.0;
  }
  return turn_deg(c, k, d1, d2);
}

// Sharp corners, as the arc lengths (m) of their nodes: the turn between the chords over `a`
// before and after a node, kept at its maximum within 2a (a gap at a corner turns the chords
// twice, once at each end). A 60 mm radius bends ~12 deg over a = 12 mm, an L-corner 90 deg.
// A corner must hold at the legs' scale too (legs_turn), or cutting there would join two
// straight pieces in a spike.
std::vector<double> corner_cuts(const NodeCurve& c) {
  const std::size_t n = c.s.size();
  const double a = 3 * c.half_window;
  std::vector<double> turn(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    if (!c.closed && (c.s[k] < a || c.s[k] > c.s.back() - a)) continue;
    turn[k] = chord_turn(c, k, a);
  }
  std::vector<double> cuts;
  for (std::size_t k = 0; k < n; ++k) {
    if (turn[k] < kCornerDeg) continue;
    bool is_max = true;
    for (std::size_t j = 0; j < n && is_max; ++j) {
      double ds = std::abs(c.s[j] - c.s[k]);
      if (c.closed) ds = std::min(ds, c.L - ds);
      if (j != k && ds < 2 * a && (turn[j] > turn[k] || (turn[j] == turn[k] && j < k))) {
        is_max = false;
      }
    }
    if (is_max && legs_turn(c, k, a) >= kCornerDeg) cuts.push_back(c.s[k]);
  }
  return cuts;
}

using Piece = std::pair<double, double>;  // arc-length interval (m)

// The pieces between the corners `cuts` (m); piece j runs from corner j (closed) or the start.
// Without corners, the whole curve (closed: with half a length more at either end).
std::vector<Piece> pieces_between(const std::vector<double>& cuts, const NodeCurve& c) {
  std::vector<Piece> pieces;
  if (cuts.empty()) {
    pieces.emplace_back(c.closed ? -0.5 * c.L : 0.0, c.closed ? 1.5 * c.L : c.s.back());
  } else if (c.closed) {
    for (std::size_t k = 0; k < cuts.size(); ++k) {
      pieces.emplace_back(cuts[k], k + 1 < cuts.size() ? cuts[k + 1] : cuts[0] + c.L);
    }
  } else {
    double lo = 0;
    for (double cut : cuts) {
      pieces.emplace_back(lo, cut);
      lo = cut;
    }
    pieces.emplace_back(lo, c.s.back());
  }
  return pieces;
}

// Where two pieces meet: the corner point and the directions along the piece before and after.
struct Corner {
  bool ok = false;
  Eigen::Vector3d point, d_in, d_out;
};

// The line through the nodes of `piece` over up to 3 half-windows at its end (`at_end`) or
// start: a point on it and its unit direction. False with too little support.
bool piece_line(const NodeCurve& c, const Piece& piece, bool at_end, Eigen::Vector3d& p,
                Eigen::Vector3d& d) {
  const auto [lo, hi] = piece;
  std::vector<Eigen::Vector3d> pp;
  std::vector<double> sp;
  c.arc.within(lo, hi, pp, sp);
  const double r = std::min(3 * c.half_window, 0.5 * (hi - lo));
  return local_line(pp, sp, at_end ? hi - r : lo + r, 2 * r, p, d);
}

// Corner j joins the end of piece j and the start of piece j + 1 (wrapping when closed) where
// the two pieces' end lines come closest. None without cuts.
std::vector<Corner> corners_between(const NodeCurve& c, const std::vector<Piece>& pieces,
                                    bool cut) {
  const std::size_t np = pieces.size();
  std::vector<Corner> corners(np);
  for (std::size_t j = 0; cut && j < np; ++j) {
    if (!c.closed && j + 1 == np) break;
    Piece next = pieces[(j + 1) % np];
    if (j + 1 == np) next = {next.first + c.L, next.second + c.L};
    Eigen::Vector3d p1, d1, p2, d2;
    if (!piece_line(c, pieces[j], true, p1, d1) || !piece_line(c, next, false, p2, d2)) continue;
    const Eigen::Vector3d w = p1 - p2;
    const double b = d1.dot(d2), d = d1.dot(w), e = d2.dot(w);
    const double den = 1 - b * b;
    if (den < 1e-3) continue;
    const double t1 = (b * e - d) / den, t2 = (e - b * d) / den;
    corners[j] = {true, 0.5 * ((p1 + t1 * d1) + (p2 + t2 * d2)), d1, d2};
  }
  return corners;
}

// A polyline with the vertices that are corners flagged.
struct Polyline {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::uint8_t> corner;
};

// Piece `piece`'s smoothed samples every half `spacing` (m), trimmed where they overshoot its
// corners `start` and `end` (either null), then the corner at its end. `cut`: the curve has
// corners, and only the piece's own nodes count (a window must not reach round a corner).
void sample_piece(const NodeCurve& c, const Piece& piece, const Corner* start, const Corner* end,
                  bool cut, double spacing, Polyline& line) {
  const auto [lo, hi] = piece;
  std::vector<Eigen::Vector3d> pp, own;
  std::vector<double> sp, own_s;
  c.arc.within(lo - c.half_window, hi + c.half_window, pp, sp);
  for (std::size_t k = 0; k < pp.size(); ++k) {
    if (!cut || (sp[k] >= lo && sp[k] <= hi)) {
      own.push_back(pp[k]);
      own_s.push_back(sp[k]);
    }
  }
  const bool ring = !cut && c.closed;
  const double a0 = ring ? 0.0 : lo;
  const double a1 = ring ? c.L : hi;
  const int steps = std::max(1, static_cast<int>(std::ceil((a1 - a0) / (0.5 * spacing))));
  for (int k = 0; k <= steps; ++k) {
    if (ring && k == steps) break;  // the ring's end is its start
    const double s0 = a0 + (a1 - a0) * k / steps;
    Eigen::Vector3d pos = Eigen::Vector3d::Constant(NAN), dir;
    local_quad(own, own_s, s0, kCurveWindow * c.half_window, pos, dir);
    if (!pos.allFinite()) continue;
    if (start && (pos - start->point).dot(start->d_out) <= 0) continue;
    if (end && (pos - end->point).dot(end->d_in) >= 0) continue;
    line.points.push_back(pos);
    line.corner.push_back(0);
  }
  if (end) {
    line.points.push_back(end->point);
    line.corner.push_back(1);
  }
}

// The polyline through all pieces, with the corners between them (closed: back to its start).
Polyline sample_pieces(const NodeCurve& c, const std::vector<Piece>& pieces,
                       const std::vector<Corner>& corners, bool cut, double spacing) {
  Polyline line;
  const std::size_t np = pieces.size();
  for (std::size_t j = 0; j < np; ++j) {
    const Corner* start = nullptr;
    if (cut && (j > 0 || c.closed)) {
      const Corner& before = corners[(j + np - 1) % np];
      if (before.ok) start = &before;
    }
    const Corner* end = corners[j].ok ? &corners[j] : nullptr;
    sample_piece(c, pieces[j], start, end, cut, spacing, line);
  }
  if (c.closed && !line.points.empty()) {
    line.points.push_back(line.points.front());
    line.corner.push_back(line.corner.front());
  }
  return line;
}

// Samples `line` (arc lengths `ls`, m) every `spacing` (m) into out.points and out.s; a closed
// curve's last sample, its start, is left out.
void resample(const std::vector<Eigen::Vector3d>& line, const std::vector<double>& ls,
              double spacing, SeamCurve& out) {
  const int m = std::max(1, static_cast<int>(std::round(out.length / spacing)));
  std::size_t seg = 0;
  for (int k = 0; k <= m; ++k) {
    if (out.closed && k == m) break;
    const double s0 = out.length * k / m;
    while (seg + 2 < line.size() && ls[seg + 1] < s0) ++seg;
    const double span = ls[seg + 1] - ls[seg];
    const double f = span > 0 ? std::clamp((s0 - ls[seg]) / span, 0.0, 1.0) : 0.0;
    out.points.push_back(line[seg] + f * (line[seg + 1] - line[seg]));
    out.s.push_back(s0);
  }
}

// out.tangents by central differences, one-sided where a corner lies between the neighbours.
void set_tangents(SeamCurve& out) {
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
    if (k > 0 || out.closed) prev = (k + q - 1) % q;
    if (k + 1 < q || out.closed) next = (k + 1) % q;
    const double sp0 = prev < k ? out.s[prev] : out.s[prev] - out.length;
    const double sn0 = next > k ? out.s[next] : out.s[next] + out.length;
    if (prev != k && corner_between(sp0, out.s[k])) prev = k;
    if (next != k && corner_between(out.s[k], sn0)) next = k;
    const Eigen::Vector3d d = out.points[next] - out.points[prev];
    out.tangents[k] = d.norm() > 0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
  }
}

}  // namespace

SeamCurve smooth_curve(const std::vector<Eigen::Vector3d>& ordered, bool closed, double half_window,
                       double spacing, const std::vector<Eigen::Vector3d>& normals) {
  SeamCurve out;
  out.closed = closed;
  const std::size_t n = ordered.size();
  if (n < 2 || !(spacing > 0)) return out;
  NodeCurve c{ordered, normals, closed, half_window, std::vector<double>(n, 0.0), 0.0, {}};
  for (std::size_t k = 1; k < n; ++k) c.s[k] = c.s[k - 1] + (ordered[k] - ordered[k - 1]).norm();
  c.L = c.s.back() + (closed ? (ordered.front() - ordered.back()).norm() : 0.0);
  if (!(c.L > 0)) return out;
  for (int rep = closed ? -1 : 0; rep <= (closed ? 1 : 0); ++rep) {
    for (std::size_t k = 0; k < n; ++k) {
      c.arc.P.push_back(ordered[k]);
      c.arc.S.push_back(c.s[k] + rep * c.L);
    }
  }

  const std::vector<double> cuts = corner_cuts(c);
  const std::vector<Piece> pieces = pieces_between(cuts, c);
  const std::vector<Corner> corners = corners_between(c, pieces, !cuts.empty());
  const Polyline line = sample_pieces(c, pieces, corners, !cuts.empty(), spacing);
  std::vector<double> ls(line.points.size(), 0.0);
  for (std::size_t k = 1; k < ls.size(); ++k) {
    ls[k] = ls[k - 1] + (line.points[k] - line.points[k - 1]).norm();
  }
  if (ls.size() < 2 || !(ls.back() > 0)) return out;
  out.length = ls.back();
  for (std::size_t k = 0; k + (closed ? 1 : 0) < ls.size(); ++k) {
    if (line.corner[k]) out.corners.push_back(ls[k]);
  }
  resample(line.points, ls, spacing, out);
  set_tangents(out);
  return out;
}

}  // namespace groovetrace
