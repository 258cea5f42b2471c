// Stations along a seam anchored to the cloud's frame (see stations.hpp).

#include "robust/stations.hpp"

#include <algorithm>
#include <cmath>

namespace groovetrace {
namespace {

// The anchor planes: normal to each axis of the frame, this many spacings apart.
constexpr double kAnchorLattice = 20.0;
// A crossing anchors only where the seam meets its plane at over 30 degrees: at a glancing
// crossing, a wobble of the curve across the seam moves it far along.
constexpr double kMinCrossingCos = 0.5;

// Arc lengths at which `dense` crosses a plane of the lattice, sorted.
std::vector<double> anchors(const SeamCurve& dense, double lattice) {
  const auto& P = dense.points;
  const std::size_t n = P.size();
  const std::size_t segs = dense.closed ? n : n - 1;
  std::vector<double> out;
  for (std::size_t k = 0; k < segs; ++k) {
    const Eigen::Vector3d& a = P[k];
    const Eigen::Vector3d& b = P[(k + 1) % n];
    const double s0 = dense.s[k];
    const double s1 = k + 1 < n ? dense.s[k + 1] : dense.length;
    const Eigen::Vector3d d = b - a;
    if (!(d.norm() > 0)) continue;
    for (int axis = 0; axis < 3; ++axis) {
      if (std::abs(d[axis]) < kMinCrossingCos * d.norm()) continue;
      // Levels in [min, max) of the segment, so a level through a vertex counts once.
      const double lo = std::min(a[axis], b[axis]), hi = std::max(a[axis], b[axis]);
      for (double level = lattice * std::ceil(lo / lattice); level < hi; level += lattice) {
        const double f = (level - a[axis]) / d[axis];
        out.push_back(s0 + f * (s1 - s0));
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Station arc lengths (m), sorted. From every anchor, stations `spacing` (m) apart both ways
// up to half-way to the next anchor. Arc length drifts between two runs where the curve wobbles
// differently (60 um over 100 mm of a 640x480 scan); anchored every lattice spacing, no station
// lies more than half a lattice from its anchor. Where two series meet, the gap between them
// is whatever is left (0 to `spacing`): a threshold there (one station more or less) would be
// a new place for a micrometre to flip a decision. An open curve keeps its ends as stations
// where they lie over half a spacing from the nearest one.
std::vector<double> station_arcs(const SeamCurve& dense, double spacing) {
  const double L = dense.length;
  std::vector<double> A = anchors(dense, kAnchorLattice * spacing);
  std::vector<double> S;
  if (A.empty()) {
    for (double s = 0; s <= L + 1e-12; s += spacing) S.push_back(s);
  } else if (dense.closed) {
    for (std::size_t i = 0; i < A.size(); ++i) {
      const double a = A[i];
      const double b = i + 1 < A.size() ? A[i + 1] : A[0] + L;
      const double mid = 0.5 * (a + b);
      for (double s = a; s <= mid; s += spacing) S.push_back(std::fmod(s, L));
      for (double s = b - spacing; s > mid; s -= spacing) S.push_back(std::fmod(s, L));
    }
  } else {
    for (double s = A.front() - spacing; s >= 0; s -= spacing) S.push_back(s);
    for (std::size_t i = 0; i + 1 < A.size(); ++i) {
      const double mid = 0.5 * (A[i] + A[i + 1]);
      for (double s = A[i]; s <= mid; s += spacing) S.push_back(s);
      for (double s = A[i + 1] - spacing; s > mid; s -= spacing) S.push_back(s);
    }
    for (double s = A.back(); s <= L; s += spacing) S.push_back(s);
  }
  std::sort(S.begin(), S.end());
  if (!dense.closed) {
    if (S.empty() || S.front() > 0.5 * spacing) S.insert(S.begin(), 0.0);
    if (L - S.back() > 0.5 * spacing) S.push_back(L);
  }
  return S;
}

}  // namespace

SeamCurve anchored_stations(const SeamCurve& dense, double spacing) {
  const std::size_t n = dense.points.size();
  if (n < 2 || !(dense.length > 0) || !(spacing > 0)) return dense;
  const double L = dense.length;
  SeamCurve out;
  out.closed = dense.closed;
  out.length = L;
  out.corners = dense.corners;
  // Positions and tangents interpolated on the dense curve.
  std::size_t seg = 0;
  for (double s0 : station_arcs(dense, spacing)) {
    while (seg + 1 < n && dense.s[seg + 1] < s0) ++seg;
    const std::size_t next = seg + 1 < n ? seg + 1 : (dense.closed ? 0 : seg);
    const double s1 = seg + 1 < n ? dense.s[seg + 1] : (dense.closed ? L : dense.s[seg]);
    const double span_s = s1 - dense.s[seg];
    const double f = span_s > 0 ? std::clamp((s0 - dense.s[seg]) / span_s, 0.0, 1.0) : 0.0;
    out.points.push_back(dense.points[seg] + f * (dense.points[next] - dense.points[seg]));
    // Across a corner the tangent is the nearer sample's (one-sided), not a blend of the legs.
    Eigen::Vector3d t = dense.tangents[seg] + f * (dense.tangents[next] - dense.tangents[seg]);
    if (dense.tangents[seg].dot(dense.tangents[next]) < 0.9) {
      t = f < 0.5 ? dense.tangents[seg] : dense.tangents[next];
    }
    out.tangents.push_back(t.norm() > 0 ? Eigen::Vector3d(t.normalized()) : dense.tangents[seg]);
    out.s.push_back(s0);
  }
  return out;
}

}  // namespace groovetrace
