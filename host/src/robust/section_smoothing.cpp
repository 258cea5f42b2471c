// The fitted sections of a seam smoothed along it: roots over the smoothing window, the
// groove's shape over a longer one (see smooth_sections).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/stats.hpp"
#include "robust/context.hpp"

namespace groovetrace::robust_detail {
namespace {

// The shape window against the root's (see smooth_sections).
constexpr double kShapeWindow = 5.0;
// The weight of the curve's own point in the root's mean (see smooth_sections): that of one fit
// at the station itself, against about 4.6 for a full window of fits. At 0.2 a 640x480 scan
// still moved by up to 1.3 mm where few fits passed (a one-wall fit flipping to two walls);
// at 1.0 the sweep's lateral and depth errors came out as good or better.
constexpr double kPriorWeight = 1.0;

int piece_of(double s, const std::vector<double>& corners) {
  int p = 0;
  for (double c : corners) p += s > c ? 1 : 0;
  return p;
}

// Local linear fit of values against arc-length offsets `ds` with weights `w`, evaluated at
// offset 0; falls back to the weighted mean when the offsets do not span a line.
template <int N>
Eigen::Matrix<double, N, 1> local_linear(const std::vector<Eigen::Matrix<double, N, 1>>& v,
                                         const std::vector<double>& ds,
                                         const std::vector<double>& w) {
  double sw = 0, ss = 0, sss = 0;
  Eigen::Matrix<double, N, 1> sp = Eigen::Matrix<double, N, 1>::Zero();
  Eigen::Matrix<double, N, 1> ssp = Eigen::Matrix<double, N, 1>::Zero();
  for (std::size_t q = 0; q < v.size(); ++q) {
    sw += w[q];
    ss += w[q] * ds[q];
    sss += w[q] * ds[q] * ds[q];
    sp += w[q] * v[q];
    ssp += w[q] * ds[q] * v[q];
  }
  if (!(sw > 0)) return Eigen::Matrix<double, N, 1>::Constant(NAN);
  const double det = sw * sss - ss * ss;
  if (det <= 1e-6 * sw * sss) return sp / sw;
  const Eigen::Matrix<double, N, 1> slope = (sw * ssp - ss * sp) / det;
  return (sp - slope * ss) / sw;
}

// local_linear with two Tukey reweightings on the residual norm: one bad section (a fit that
// caught a dropout or the other leg of a corner) must not drag its neighbours.
template <int N>
Eigen::Matrix<double, N, 1> robust_local_linear(const std::vector<Eigen::Matrix<double, N, 1>>& v,
                                                const std::vector<double>& ds,
                                                std::vector<double> w) {
  Eigen::Matrix<double, N, 1> fit = local_linear<N>(v, ds, w);
  const std::vector<double> w0 = w;
  for (int iter = 0; iter < 2 && fit.allFinite(); ++iter) {
    std::vector<double> res(v.size());
    for (std::size_t q = 0; q < v.size(); ++q) res[q] = (v[q] - fit).norm();
    const double c = kTukeyC * kMadToSigma * upper_median(res);
    if (!(c > 0)) break;
    for (std::size_t q = 0; q < v.size(); ++q) w[q] = w0[q] * tukey_weight(res[q], c);
    fit = local_linear<N>(v, ds, w);
  }
  return fit;
}

// The ok sections near a station: their indices, signed arc-length offsets (m) and tricube
// weights.
struct Near {
  std::vector<std::size_t> index;
  std::vector<double> ds, w;
};

// The ok sections within `win` of arc length of station k (rings wrap; `by_piece`: only
// those between the same corners).
Near neighbours(const std::vector<GrooveSection>& raw, std::size_t k, const SeamCurve& curve,
                double win, bool by_piece) {
  Near near;
  const double L = curve.length;
  const bool ring = curve.closed && curve.corners.empty();
  const int pieces = static_cast<int>(curve.corners.size()) + 1;
  const int pk = piece_of(raw[k].s, curve.corners);
  for (std::size_t j = 0; j < raw.size(); ++j) {
    if (!raw[j].ok) continue;
    double d = raw[j].s - raw[k].s;
    const int pj = piece_of(raw[j].s, curve.corners);
    if (curve.closed && (ring || !by_piece)) {
      if (d > 0.5 * L) d -= L;
      if (d < -0.5 * L) d += L;
    } else if (by_piece && pj != pk) {
      // On a closed seam with corners the first and the last piece are one.
      const bool joined =
          curve.closed && ((pk == 0 && pj == pieces - 1) || (pk == pieces - 1 && pj == 0));
      if (!joined) continue;
      d = d > 0 ? d - L : d + L;
    }
    if (std::abs(d) >= win) continue;
    near.index.push_back(j);
    near.ds.push_back(d);
    near.w.push_back(tricube_weight(d, win));
  }
  return near;
}

using V1 = Eigen::Matrix<double, 1, 1>;
using V3 = Eigen::Vector3d;
using V4 = Eigen::Matrix<double, 4, 1>;

// Each section's edges as offsets from its root: (across, up) of the left edge, then of the
// right, in the frame of the bisector, which smooths well; the normal tilts with the root
// line's depth wobble along the seam.
std::vector<V4> edge_offsets(const std::vector<GrooveSection>& raw) {
  std::vector<V4> shape(raw.size());
  for (std::size_t j = 0; j < raw.size(); ++j) {
    const GrooveSection& s = raw[j];
    const V3 up = s.bisector;
    const V3 a = up.cross(s.tangent).normalized();
    shape[j] << (s.edge_left - s.root).dot(a), (s.edge_left - s.root).dot(up),
        (s.edge_right - s.root).dot(a), (s.edge_right - s.root).dot(up);
  }
  return shape;
}

// The mean of `off` with weights `w`, the curve's own point (offset zero) weighing kPriorWeight.
Eigen::Vector2d mean_offset(const std::vector<Eigen::Vector2d>& off, const std::vector<double>& w) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double sw = kPriorWeight;
  for (std::size_t q = 0; q < off.size(); ++q) {
    sum += w[q] * off[q];
    sw += w[q];
  }
  return Eigen::Vector2d(sum / sw);
}

// The smoothed root at station k. Each ok fit within h gives its offset from its own station,
// across the seam and in depth (a root lies in its station's plane); the root is the station
// plus their weighted mean. The curve carries the seam's course, so the offsets change slowly,
// and a mean does not extrapolate: a line fitted to the roots beside a run of failed fits had
// all of its support on one side, and one fit more or less there (a micrometre of input)
// tipped it by up to 3 mm. The curve itself - the previous pass's smoothed roots, meeting at
// corners where the legs' lines do - enters as one more offset (zero) with kPriorWeight: where
// fits fail the root slides to the curve as their weight fades, instead of jumping to it when
// fewer than three remain, and one fit more or less moves it less.
V3 smoothed_root(const std::vector<GrooveSection>& raw, std::size_t k, const SeamCurve& curve,
                 double h) {
  Near near = neighbours(raw, k, curve, h, true);
  const std::size_t n = near.index.size();
  std::vector<Eigen::Vector2d> off(n);
  for (std::size_t q = 0; q < n; ++q) {
    const GrooveSection& r = raw[near.index[q]];
    const V3 d = r.root - curve.points[near.index[q]];
    off[q] = Eigen::Vector2d(d.dot(r.across()), d.dot(r.normal));
  }
  if (n >= 3) {
    // One Tukey reweighting: a fit that caught something else must not drag its neighbours.
    const Eigen::Vector2d o0 = mean_offset(off, near.w);
    std::vector<double> res(n);
    for (std::size_t q = 0; q < n; ++q) res[q] = (off[q] - o0).norm();
    const double c = std::max(kTukeyC * kMadToSigma * upper_median(res), 1e-4);
    for (std::size_t q = 0; q < n; ++q) near.w[q] *= tukey_weight(res[q], c);
  }
  const Eigen::Vector2d o = mean_offset(off, near.w);
  return curve.points[k] + o[0] * raw[k].across() + o[1] * raw[k].normal;
}

// The groove's shape at station k (`s`, its root already smoothed) from the ok sections within
// `win` (m): surface normal, wall bisector and edges, noise, and where its own fit failed its
// depth and width. False, `s` untouched, with fewer than three or a degenerate fit.
bool smooth_shape(const std::vector<GrooveSection>& raw, const std::vector<V4>& shape,
                  std::size_t k, const SeamCurve& curve, double win, GrooveSection& s) {
  const Near near = neighbours(raw, k, curve, win, false);
  if (near.index.size() < 3) return false;
  std::vector<V3> normals, bisectors;
  std::vector<V4> shapes;
  std::vector<V1> noise, depth;
  for (std::size_t j : near.index) {
    normals.push_back(raw[j].normal);
    bisectors.push_back(raw[j].bisector);
    shapes.push_back(shape[j]);
    noise.push_back(V1(raw[j].noise));
    depth.push_back(V1(raw[j].depth));
  }
  const auto &ds = near.ds, &w = near.w;
  V3 n = local_linear<3>(normals, ds, w);
  n -= n.dot(s.tangent) * s.tangent;
  const V3 b = robust_local_linear<3>(bisectors, ds, w);
  const V4 e = robust_local_linear<4>(shapes, ds, w);
  if (!(n.norm() > 1e-9) || !(b.norm() > 1e-9) || !e.allFinite()) return false;
  s.normal = n.normalized();
  s.bisector = b.normalized();
  const V3 a = s.bisector.cross(s.tangent).normalized();
  s.edge_left = s.root + e[0] * a + e[1] * s.bisector;
  s.edge_right = s.root + e[2] * a + e[3] * s.bisector;
  s.noise = local_linear<1>(noise, ds, w)[0];
  if (!s.ok) {
    s.depth = local_linear<1>(depth, ds, w)[0];
    s.width = (s.edge_right - s.edge_left).norm();
  }
  return true;
}

}  // namespace

// Smooths the fitted sections along the seam. The root follows the seam closely (window h):
// it carries the lateral accuracy. The groove's shape - edge offsets from the root, surface
// normal and wall bisector - is smoothed over 5h: a groove's width and opening change slowly,
// while a D415's correlated undulation tilts the surface by up to ~10 degrees over 10-40 mm,
// which only a long window averages out. Windows widen where fits failed (corners,
// dropouts); stations with no ok fit within 4 windows are dropped. Robust: one Tukey
// reweighting on the root's residual across the seam.
std::vector<GrooveSection> smooth_sections(const std::vector<GrooveSection>& raw,
                                           const SeamCurve& curve, double h) {
  const std::vector<V4> shape = edge_offsets(raw);
  std::vector<GrooveSection> out;
  for (std::size_t k = 0; k < raw.size(); ++k) {
    GrooveSection s = raw[k];
    s.root = smoothed_root(raw, k, curve, h);
    for (double win = kShapeWindow * h; win <= 4 * kShapeWindow * h + 1e-12; win *= 2) {
      if (smooth_shape(raw, shape, k, curve, win, s)) {
        out.push_back(s);
        break;
      }
    }
  }
  return out;
}

}  // namespace groovetrace::robust_detail
