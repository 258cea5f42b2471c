// Torch poses along a traced seam: on the fitted root line, spaced by arc length, the torch
// along the walls' bisector. The sections are already smoothed along the seam, so this only
// interpolates between them.

#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <groovetrace/robust.hpp>

#include "core/stats.hpp"

namespace groovetrace {
namespace {

// A ring starts at its smallest x (ties: y) and runs counter-clockwise about its mean surface
// normal.
// Where a ring's path starts - its section of smallest x (ties: y) - and whether it runs
// against the sections' order: counter-clockwise about the mean top normal.
struct RingStart {
  std::size_t first = 0;
  bool reversed = false;
};

RingStart ring_start(const std::vector<GrooveSection>& secs) {
  RingStart start;
  for (std::size_t k = 1; k < secs.size(); ++k) {
    const Eigen::Vector3d& a = secs[k].root;
    const Eigen::Vector3d& b = secs[start.first].root;
    if (a.x() < b.x() || (a.x() == b.x() && a.y() < b.y())) start.first = k;
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), up = Eigen::Vector3d::Zero();
  for (const auto& s : secs) {
    centre += s.root;
    up += s.normal;
  }
  centre /= static_cast<double>(secs.size());
  Eigen::Vector3d turn = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < secs.size(); ++k) {
    turn += (secs[k].root - centre).cross(secs[(k + 1) % secs.size()].root - centre);
  }
  start.reversed = turn.dot(up) < 0;
  return start;
}

void orient_ring(std::vector<GrooveSection>& secs) {
  const RingStart start = ring_start(secs);
  std::rotate(secs.begin(), secs.begin() + static_cast<std::ptrdiff_t>(start.first), secs.end());
  if (start.reversed) std::reverse(secs.begin() + 1, secs.end());
}

// Whether an open seam from `first` to `last` (roots, m) runs towards smaller x (ties: y, then z).
bool backwards(const Eigen::Vector3d& first, const Eigen::Vector3d& last) {
  const Eigen::Vector3d d = last - first;
  const double eps = 1e-9;
  return d.x() < -eps ||
         (std::abs(d.x()) <= eps && (d.y() < -eps || (std::abs(d.y()) <= eps && d.z() < 0)));
}

// An open seam ends at larger x than it starts (ties: y, then z).
void orient_open(std::vector<GrooveSection>& secs) {
  if (backwards(secs.front().root, secs.back().root)) std::reverse(secs.begin(), secs.end());
}

// Drops the roots where the path folds back on itself (the chords before and after turn by
// more than 120 deg), until none does. At an L's corner the legs meet where their lines do,
// and that point can lie half a millimetre beyond the first roots of the next leg: the path
// went out to it and back, and the torch turned by its blended 8 deg within 0.75 mm there.
void drop_folds(std::vector<GrooveSection>& secs, bool closed) {
  const double cos_fold = std::cos(120.0 * M_PI / 180.0);
  for (std::size_t k = closed ? 0 : 1; secs.size() > 3 && k < secs.size();) {
    const std::size_t n = secs.size();
    if (!closed && k + 1 >= n) break;
    const Eigen::Vector3d a = secs[k].root - secs[(k + n - 1) % n].root;
    const Eigen::Vector3d b = secs[(k + 1) % n].root - secs[k].root;
    if (a.dot(b) < cos_fold * a.norm() * b.norm()) {
      secs.erase(secs.begin() + static_cast<std::ptrdiff_t>(k));
      k = k > (closed ? 0u : 1u) ? k - 1 : k;
    } else {
      ++k;
    }
  }
}

// The torch's path: the polyline through the roots (m; closed: back to the start) with its arc
// length S (m), and at each root the wall bisector B and the travel tangent T. Tangents are
// the sections' own, from the seam curve smoothed over 18 mm, turned along the travel: the
// chord between neighbouring roots 1.5 mm apart would turn with their jitter (0.4 mm across
// tilts it 13 deg at 640x480).
struct TorchPath {
  std::vector<Eigen::Vector3d> P, B, T, N;  ///< N: the top surface normal
  std::vector<double> S;
  std::vector<double> D;  ///< the groove's depth, root below the top along N (m)
  /// 0 on a tack weld, else 1: the weight of the root's top and depth in smooth_depth.
  std::vector<double> W;
};

// The root `reach` (m) or more before (dir = -1) or after (+1) root k along the path (rings
// wrap), else the path's end.
std::size_t root_at_reach(const std::vector<GrooveSection>& secs, std::size_t k, int dir,
                          bool closed, double reach) {
  const std::size_t n = secs.size();
  std::size_t j = k;
  for (std::size_t steps = 0; steps + 1 < n; ++steps) {
    if (!closed && (dir < 0 ? j == 0 : j + 1 == n)) break;
    j = dir < 0 ? (j + n - 1) % n : (j + 1) % n;
    if ((secs[j].root - secs[k].root).norm() >= reach) break;
  }
  return j;
}

// Whether station `sec` lies on one of `tacks` (arc lengths along the seam, m).
bool on_tack(const GrooveSection& sec, const std::vector<SeamCandidate::Tack>& tacks) {
  return std::any_of(tacks.begin(), tacks.end(), [&](const SeamCandidate::Tack& t) {
    return std::abs(sec.s - t.position) <= 0.5 * t.length;
  });
}

TorchPath torch_path(const std::vector<GrooveSection>& secs, bool closed,
                     const std::vector<SeamCandidate::Tack>& tacks) {
  // The tangent's sign from the chord between the roots kSignReach before and after: the
  // neighbouring roots, 1.5 mm apart, can lie crosswise at a corner, where the two legs meet
  // where their lines do, and turned a section's tangent against the travel.
  constexpr double kSignReach = 0.005;
  TorchPath path;
  const std::size_t n = secs.size();
  for (std::size_t k = 0; k < n; ++k) {
    path.P.push_back(secs[k].root);
    path.B.push_back(secs[k].bisector);
    path.N.push_back(secs[k].normal);
    path.D.push_back(secs[k].depth);
    path.W.push_back(on_tack(secs[k], tacks) ? 0.0 : 1.0);
    const std::size_t next = root_at_reach(secs, k, +1, closed, kSignReach);
    const std::size_t prev = root_at_reach(secs, k, -1, closed, kSignReach);
    Eigen::Vector3d t = secs[k].tangent;
    if (t.dot(secs[next].root - secs[prev].root) < 0) t = -t;
    path.T.push_back(t);
  }
  if (closed) {
    path.P.push_back(path.P.front());
    path.B.push_back(path.B.front());
    path.T.push_back(path.T.front());
    path.N.push_back(path.N.front());
    path.D.push_back(path.D.front());
    path.W.push_back(path.W.front());
  }
  path.S.assign(path.P.size(), 0.0);
  for (std::size_t k = 1; k < path.P.size(); ++k) {
    path.S[k] = path.S[k - 1] + (path.P[k] - path.P[k - 1]).norm();
  }
  return path;
}

// Blends the torch's orientation along the path over `blend` (m) of arc length: the bisector
// and the travel tangent at each root become their weighted means over the roots within
// `blend` either side, each weighing the arc length it stands for times a triangle (1 at the
// root, 0 at `blend`; a boxcar of the same rate would let each root's noise in and out as a
// step). Through a corner the tool x then turns from `blend` before it to `blend` after it,
// fastest at the corner: at about turn / blend, for a 90 deg turn 1.27 times that (the mean of
// two unit vectors turns fastest half-way). A straight, even path keeps its orientation. Within
// `blend` of an open path's end the window is one-sided, and a line in arc length fitted to it
// is taken at the root instead of the mean, so that a curved seam's end is not pulled towards
// the inside (a girth seam's bisector turns with the pipe, 2 deg/mm at 60 mm). A window
// shrunk to stay centred instead kept the end root's own noisy bisector: the torch turned by
// up to 18 deg within a seam's first millimetre (640x480, 0.45 m, tilt -20 deg). Positions do
// not change.
void blend_orientation(TorchPath& path, double blend, bool closed) {
  const std::size_t n = closed ? path.P.size() - 1 : path.P.size();
  const double L = path.S.back();
  if (!(blend > 0) || n < 3) return;
  std::vector<double> cell(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double before = j > 0 ? path.S[j] - path.S[j - 1] : (closed ? L - path.S[n - 1] : 0.0);
    cell[j] = 0.5 * (before + (j + 1 < path.S.size() ? path.S[j + 1] - path.S[j] : 0.0));
  }
  std::vector<Eigen::Vector3d> B(n, Eigen::Vector3d::Zero()), T(n, Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k < n; ++k) {
    const bool one_sided = !closed && std::min(path.S[k], L - path.S[k]) < blend;
    double sw = 0, swd = 0, swdd = 0;  // weighted sums for the line
    Eigen::Vector3d dB = Eigen::Vector3d::Zero(), dT = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < n; ++j) {
      double d = path.S[j] - path.S[k];
      if (closed) d -= L * std::round(d / L);
      if (std::abs(d) > blend + 1e-12) continue;
      const double w = cell[j] * (1.0 - std::abs(d) / (blend + 1e-12));
      B[k] += w * path.B[j];
      T[k] += w * path.T[j];
      sw += w;
      swd += w * d;
      swdd += w * d * d;
      dB += w * d * path.B[j];
      dT += w * d * path.T[j];
    }
    const double det = sw * swdd - swd * swd;
    if (one_sided && det > 1e-6 * sw * swdd) {
      B[k] = (swdd * B[k] - swd * dB) / det;
      T[k] = (swdd * T[k] - swd * dT) / det;
    }
    if (!(B[k].norm() > 1e-9)) B[k] = path.B[k];
    if (!(T[k].norm() > 1e-9)) T[k] = path.T[k];
  }
  for (std::size_t k = 0; k < n; ++k) {
    path.B[k] = B[k].normalized();
    path.T[k] = T[k].normalized();
  }
  if (closed) {
    path.B[n] = path.B[0];
    path.T[n] = path.T[0];
  }
}

// The arc-length offset (m) from root k to root j (rings wrap).
double arc_offset(const TorchPath& path, std::size_t k, std::size_t j, bool closed) {
  const double L = path.S.back();
  double d = path.S[j] - path.S[k];
  if (closed) d -= L * std::round(d / L);
  return d;
}

// The half-window (m) about root k: `half`, shrunk near an open path's ends to stay centred.
double centred_half(const TorchPath& path, std::size_t k, double half, bool closed) {
  const double L = path.S.back();
  return closed ? half : std::min(half, std::min(path.S[k], L - path.S[k]));
}

// The groove's depth at root k: the tricube-weighted mean of the roots' depths over `half`
// (m) of arc length either side, centred.
double mean_depth(const TorchPath& path, std::size_t k, double half, bool closed, std::size_t n) {
  const double h = centred_half(path, k, half, closed);
  double sw = 0, sd = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const double w = path.W[j] * tricube_weight(arc_offset(path, k, j, closed), h);
    sw += w;
    sd += w * path.D[j];
  }
  return sw > 0 ? sd / sw : path.D[k];
}

// The roots' height along the top normal, smoothed. The top above each root (root + depth
// along the normal) is smoothed over `half` (m) of arc length either side: at each root a
// tricube-weighted quadratic in arc length through the neighbours' tops, taken at the root (a
// quadratic follows a pipe's curvature; the window shrinks to stay centred near an open
// path's ends, so they are not smoothed). The groove's depth is taken off that, smoothed over
// kDepthWindow times as much: a groove's depth changes slowly along its seam, and its root,
// where two steep walls fitted to a few image rows each meet, scatters in depth by 1-3 mm at
// 640x480 where the top beside it, fitted to the wide top surfaces, moves by about 1 mm (the
// sweep's v16-90 s319: the path's depth error 1.34 mm rms with the roots smoothed alone, in
// 40-60 mm waves; 0.89 mm now). A corner joint (fillet, lap) is taken alike: its depth is
// the weld's throat, from the root to the line through its leg ends on the two faces, and
// those faces are fitted as widely as a groove's top (the sweep's lap s310: 0.65 -> 0.53 mm
// depth error). Stations on a tack weld weigh nothing (TorchPath::W): their roots and depths
// are their neighbours' interpolated, from the tack's flanks, and their tops stood up to
// 1.8 mm high (the sweep's tacks s352). Only the path moves: the sections (and with them the
// region and the reported stations) keep their roots.
constexpr double kDepthWindow = 3.0;

void smooth_depth(TorchPath& path, double half, bool closed) {
  const std::size_t n = closed ? path.P.size() - 1 : path.P.size();
  if (n < 5) return;
  std::vector<double> lift(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double h = centred_half(path, k, half, closed);
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < n; ++j) {
      const double d = arc_offset(path, k, j, closed);
      const double w = path.W[j] * tricube_weight(d, h);
      if (w <= 0) continue;
      const Eigen::Vector3d x(1, d, d * d);
      A += w * x * x.transpose();
      b += w * x * ((path.P[j] - path.P[k]).dot(path.N[k]) + path.D[j]);
    }
    const Eigen::Vector3d c = A.ldlt().solve(b);
    // Where the window holds too few roots for a quadratic (an open path's ends), the root's
    // own top.
    const double top = A(2, 2) > 1e-12 * A(0, 0) && c.allFinite() ? c[0] : path.D[k];
    lift[k] = top - mean_depth(path, k, kDepthWindow * half, closed, n);
  }
  for (std::size_t k = 0; k < n; ++k) path.P[k] += lift[k] * path.N[k];
  if (closed) path.P[n] = path.P[0];
  for (std::size_t k = 1; k < path.P.size(); ++k) {
    path.S[k] = path.S[k - 1] + (path.P[k] - path.P[k - 1]).norm();
  }
}

// The waypoint at fraction f of segment seg of `path`; `direction` is the travel where the
// path gives none.
Waypoint waypoint_at(const TorchPath& path, std::size_t seg, double f,
                     const Eigen::Vector3d& direction) {
  const auto &P = path.P, &B = path.B, &T = path.T;
  Waypoint w;
  w.rotation_vector.setZero();
  w.euler_zyx_deg.setZero();
  w.position = P[seg] + f * (P[seg + 1] - P[seg]);
  Eigen::Vector3d bis = ((1 - f) * B[seg] + f * B[seg + 1]);
  if (!(bis.norm() > 1e-9)) bis = B[seg];
  Eigen::Vector3d travel = (1 - f) * T[seg] + f * T[seg + 1];
  if (!(travel.norm() > 1e-9)) travel = P[seg + 1] - P[seg];
  if (!(travel.norm() > 1e-12)) travel = direction;
  w.orientation = tool_orientation(bis.normalized(), travel.normalized());
  w.support = 0;
  return w;
}

}  // namespace

double travel_arc(const SeamCandidate& seam, double s) {
  const auto& secs = seam.sections;
  if (secs.empty()) return s;
  if (!seam.closed) {
    return backwards(secs.front().root, secs.back().root) ? secs.front().s + secs.back().s - s : s;
  }
  const RingStart start = ring_start(secs);
  const double ring = seam.curve.length > 0 ? seam.curve.length : seam.length;
  const double d = (start.reversed ? -1.0 : 1.0) * (s - secs[start.first].s);
  return ring > 0 ? d - ring * std::floor(d / ring) : d;
}

Trajectory seam_trajectory(const SeamCandidate& seam, const RobustParams& params) {
  std::vector<GrooveSection> secs = seam.sections;
  if (secs.size() < 2) throw NoGrooveError("seam has fewer than 2 sections: no trajectory");
  const bool closed = seam.closed;
  if (closed) {
    orient_ring(secs);
  } else {
    orient_open(secs);
  }
  drop_folds(secs, closed);
  TorchPath path = torch_path(secs, closed, seam.tacks);
  smooth_depth(path, params.depth_smooth, closed);
  blend_orientation(path, params.orientation_blend, closed);
  const std::vector<Eigen::Vector3d>& P = path.P;
  const std::vector<double>& S = path.S;
  const double length = S.back();
  if (!(length > 0)) throw NoGrooveError("seam has zero length: no trajectory");

  // Waypoints: `slices` of them evenly (a closed seam repeats its first at the end), else one
  // every `step` with both ends included.
  int intervals = 0;
  if (params.slices > 0) {
    intervals = closed ? params.slices : std::max(1, params.slices - 1);
  } else {
    intervals = std::max(1, static_cast<int>(std::ceil(length / params.step - 1e-9)));
  }
  Trajectory traj;
  traj.length = length;
  const Eigen::Vector3d chord = P.back() - P.front();
  traj.direction = chord.norm() > 1e-9 ? Eigen::Vector3d(chord.normalized())
                                       : Eigen::Vector3d((P[1] - P[0]).normalized());
  std::size_t seg = 0;
  for (int k = 0; k <= intervals; ++k) {
    const double s0 = length * k / intervals;
    while (seg + 2 < P.size() && S[seg + 1] < s0) ++seg;
    const double span = S[seg + 1] - S[seg];
    const double f = span > 0 ? std::clamp((s0 - S[seg]) / span, 0.0, 1.0) : 0.0;
    traj.waypoints.push_back(waypoint_at(path, seg, f, traj.direction));
  }
  if (closed && params.slices > 0) {
    // `slices` waypoints around a ring, the last returning to the first.
    traj.waypoints.back() = traj.waypoints.front();
  }
  fill_rotation_representations(traj);
  return traj;
}

}  // namespace groovetrace
