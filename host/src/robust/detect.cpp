// The robust method end to end: candidates -> nodes confirmed by a V fit -> ordered seams ->
// sections every `station` along each seam, fitted twice (the second time across the
// smoothed first result) and smoothed along the seam -> score -> region.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/eigen3.hpp"
#include "core/neighbor_grid.hpp"
#include "core/stats.hpp"
#include "robust/bins.hpp"
#include "robust/stages.hpp"
#include "robust/stations.hpp"

namespace groovetrace {
namespace {

// The shape window against the root's (see smooth_sections).
constexpr double kShapeWindow = 5.0;
// The weight of the curve's own point in the root's mean (see smooth_sections): that of one fit
// at the station itself, against about 4.6 for a full window of fits. At 0.2 a 640x480 scan
// still moved by up to 1.3 mm where few fits passed (a one-wall fit flipping to two walls);
// at 1.0 the sweep's lateral and depth errors came out as good or better.
constexpr double kPriorWeight = 1.0;

struct Context {
  const Cloud& cloud;
  const RobustParams& params;
  const CreaseMap& map;
  Cloud voxels;  // the map's voxel centroids, for nearest-voxel look-ups
  NeighborGrid voxel_grid;
  BoxBins bins;
  double half_window;
};

// The surface normal at p: the plane of the voxels within `scale` of p that are not in a
// groove (concavity below half the candidate threshold), PCA reweighted twice (Tukey on the
// distance to the plane, scale from the residuals' MAD). Only the top surface counts, so a
// wall the sensor did not see cannot tilt it; the reweighting drops what lies off that plane
// - near a part's end its end face and the table beyond, which tilted the tool by up to 7 deg
// over a seam's last 10 mm. It is local, so it follows a seam round a pipe. `fallback` when
// too few voxels qualify.
Eigen::Vector3d surface_normal(const Context& ctx, const Eigen::Vector3d& p,
                               const Eigen::Vector3d& fallback) {
  const float r = static_cast<float>(ctx.params.scale);
  const double limit = 0.5 * ctx.map.threshold;
  // Centred half a scale above p (p is near the root): the top surface around the opening.
  const Eigen::Vector3d c = p + 0.5 * ctx.params.scale * fallback.normalized();
  std::vector<Eigen::Vector3d> pts;
  ctx.voxel_grid.for_each_within(c.cast<float>(), r, [&](std::uint32_t j, float) {
    if (ctx.map.concavity[j] < limit) pts.push_back(ctx.map.points[j].cast<double>() - c);
  });
  if (pts.size() < 20) return fallback;
  std::vector<double> w(pts.size(), 1.0), dist(pts.size());
  Eigen::Vector3d n = fallback;
  for (int iter = 0; iter < 3; ++iter) {
    double sw = 0;
    Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
    for (std::size_t k = 0; k < pts.size(); ++k) {
      sw += w[k];
      s1 += w[k] * pts[k];
      s2 += w[k] * pts[k] * pts[k].transpose();
    }
    if (!(sw > 10)) break;
    const Eigen::Vector3d mean = s1 / sw;
    n = smallest_eigenvector(s2 / sw - mean * mean.transpose());
    if (iter == 2) break;
    for (std::size_t k = 0; k < pts.size(); ++k) dist[k] = std::abs(n.dot(pts[k] - mean));
    // Floor: a tenth of a voxel, so that a noise-free plane does not reject its own rounding.
    const double cut = kTukeyC * std::max(kMadToSigma * upper_median(dist), 0.1 * ctx.params.cell);
    for (std::size_t k = 0; k < pts.size(); ++k) w[k] = tukey_weight(dist[k], cut);
  }
  if (n.dot(fallback) < 0) n = -n;
  return n;
}

// The tangent taken in the surface at p: the roots' depth wobble (undulation, one-wall fits)
// must not tip a section. Only the top-surface normal's component along the seam matters here,
// so its tilt across the seam (a wall the sensor did not see) does no harm.
Eigen::Vector3d surface_tangent(const Context& ctx, const Eigen::Vector3d& p,
                                const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d n = surface_normal(ctx, p, normal).normalized();
  const Eigen::Vector3d t = tangent - tangent.dot(n) * n;
  return t.norm() > 1e-6 ? Eigen::Vector3d(t.normalized()) : tangent;
}

// A gap in the top surface stands for a groove only where the walls can hide: where the
// surface is seen at a slant (over kGrazingDeg incidence; a pipe's flanks). Square on, a gap is a
// hole or the part's end.
constexpr double kGrazingDeg = 55.0;
bool grazing(const Context& ctx, const Eigen::Vector3d& p, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d ray = (ctx.cloud.viewpoint.cast<double>() - p).normalized();
  return std::abs(ray.dot(normal.normalized())) < std::cos(deg_to_rad(kGrazingDeg));
}

// Fits the section at `origin` across the surface tangent; `normal` orients the profile.
GrooveSection section_at(const Context& ctx, const Eigen::Vector3d& origin,
                         const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal, double slab,
                         std::vector<std::uint32_t>& scratch, bool symmetric = false) {
  const Eigen::Vector3d t = surface_tangent(ctx, origin, tangent, normal);
  // The ball holds the window across, the slab along and the groove's depth below.
  const double radius = 1.3 * ctx.half_window + slab;
  ctx.bins.within(ctx.cloud, origin, radius, scratch);
  return fit_section(ctx.cloud, scratch, origin, t, normal, slab, ctx.half_window, symmetric);
}

// Arc-length distance between stations a and b (wrapping on rings).
double arc_distance(double a, double b, double length, bool closed) {
  double d = std::abs(a - b);
  if (closed) d = std::min(d, length - d);
  return d;
}

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

// The ok sections within `win` of arc length of station k (rings wrap; `by_piece`: only
// those between the same corners), with their signed offsets and tricube weights.
void neighbours(const std::vector<GrooveSection>& raw, std::size_t k, const SeamCurve& curve,
                double win, bool by_piece, std::vector<std::size_t>& near, std::vector<double>& ds,
                std::vector<double>& w) {
  near.clear();
  ds.clear();
  w.clear();
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
    near.push_back(j);
    ds.push_back(d);
    w.push_back(tricube_weight(d, win));
  }
}

// Smooths the fitted sections along the seam. The root follows the seam closely (window h):
// it carries the lateral accuracy. The groove's shape - edge offsets from the root, surface
// normal and wall bisector - is smoothed over 5h: a groove's width and opening change slowly,
// while a D415's correlated undulation tilts the surface by up to ~10 degrees over 10-40 mm,
// which only a long window averages out. Windows widen where fits failed (corners,
// dropouts); stations with no ok fit within 4 windows are dropped. Robust: one Tukey
// reweighting on the root's residual across the seam.
std::vector<GrooveSection> smooth_sections(const std::vector<GrooveSection>& raw,
                                           const SeamCurve& curve, double h) {
  using V3 = Eigen::Vector3d;
  using V4 = Eigen::Matrix<double, 4, 1>;
  using V1 = Eigen::Matrix<double, 1, 1>;
  std::vector<V4> shape(raw.size());
  for (std::size_t j = 0; j < raw.size(); ++j) {
    const GrooveSection& s = raw[j];
    // In the frame of the bisector, which smooths well; the normal tilts with the root
    // line's depth wobble along the seam.
    const V3 up = s.bisector;
    const V3 a = up.cross(s.tangent).normalized();
    shape[j] << (s.edge_left - s.root).dot(a), (s.edge_left - s.root).dot(up),
        (s.edge_right - s.root).dot(a), (s.edge_right - s.root).dot(up);
  }
  std::vector<GrooveSection> out;
  std::vector<std::size_t> near;
  std::vector<double> ds, w;
  for (std::size_t k = 0; k < raw.size(); ++k) {
    GrooveSection s = raw[k];
    // Root: each ok fit within h gives its offset from its own station, across the seam and in
    // depth (a root lies in its station's plane); the root is the station plus their weighted
    // mean. The curve carries the seam's course, so the offsets change slowly, and a mean does
    // not extrapolate: a line fitted to the roots beside a run of failed fits had all of its
    // support on one side, and one fit more or less there (a micrometre of input) tipped it by
    // up to 3 mm. The curve itself - the previous pass's smoothed roots, meeting at corners
    // where the legs' lines do - enters as one more offset (zero) with kPriorWeight: where
    // fits fail the root slides to the curve as their weight fades, instead of jumping to it
    // when fewer than three remain, and one fit more or less moves it less.
    neighbours(raw, k, curve, h, true, near, ds, w);
    std::vector<Eigen::Vector2d> off(near.size());
    for (std::size_t q = 0; q < near.size(); ++q) {
      const GrooveSection& r = raw[near[q]];
      const V3 d = r.root - curve.points[near[q]];
      off[q] = Eigen::Vector2d(d.dot(r.across()), d.dot(r.normal));
    }
    auto mean_offset = [&] {
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      double sw = kPriorWeight;
      for (std::size_t q = 0; q < near.size(); ++q) {
        sum += w[q] * off[q];
        sw += w[q];
      }
      return Eigen::Vector2d(sum / sw);
    };
    const Eigen::Vector2d o0 = mean_offset();
    if (near.size() >= 3) {
      // One Tukey reweighting: a fit that caught something else must not drag its neighbours.
      std::vector<double> res(near.size());
      for (std::size_t q = 0; q < near.size(); ++q) res[q] = (off[q] - o0).norm();
      const double c = std::max(kTukeyC * kMadToSigma * upper_median(res), 1e-4);
      for (std::size_t q = 0; q < near.size(); ++q) w[q] *= tukey_weight(res[q], c);
    }
    const Eigen::Vector2d o = mean_offset();
    s.root = curve.points[k] + o[0] * raw[k].across() + o[1] * raw[k].normal;
    // Shape.
    bool have_shape = false;
    for (double win = kShapeWindow * h; win <= 4 * kShapeWindow * h + 1e-12 && !have_shape;
         win *= 2) {
      neighbours(raw, k, curve, win, false, near, ds, w);
      if (near.size() < 3) continue;
      std::vector<V3> normals, bisectors;
      std::vector<V4> shapes;
      std::vector<V1> noise, depth;
      for (std::size_t j : near) {
        normals.push_back(raw[j].normal);
        bisectors.push_back(raw[j].bisector);
        shapes.push_back(shape[j]);
        noise.push_back(V1(raw[j].noise));
        depth.push_back(V1(raw[j].depth));
      }
      V3 n = local_linear<3>(normals, ds, w);
      n -= n.dot(s.tangent) * s.tangent;
      const V3 b = robust_local_linear<3>(bisectors, ds, w);
      const V4 e = robust_local_linear<4>(shapes, ds, w);
      if (!(n.norm() > 1e-9) || !(b.norm() > 1e-9) || !e.allFinite()) continue;
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
      have_shape = true;
    }
    if (have_shape) out.push_back(s);
  }
  return out;
}

// Stations along `curve`, each fitted; normals from the nearest of `hint_points`. `symmetric`:
// fit symmetric V's (see fit_v_profile).
std::vector<GrooveSection> fit_stations(const Context& ctx, const SeamCurve& curve,
                                        const std::vector<Eigen::Vector3d>& hint_points,
                                        const std::vector<Eigen::Vector3d>& hint_normals,
                                        bool symmetric) {
  const std::size_t m = curve.points.size();
  std::vector<GrooveSection> secs(m);
  const std::int64_t count = static_cast<std::int64_t>(m);
#pragma omp parallel
  {
    std::vector<std::uint32_t> scratch;
#pragma omp for schedule(dynamic, 4)
    for (std::int64_t k = 0; k < count; ++k) {
      std::size_t best = 0;
      double best_d = INFINITY;
      for (std::size_t j = 0; j < hint_points.size(); ++j) {
        const double d = (hint_points[j] - curve.points[k]).squaredNorm();
        if (d < best_d) {
          best_d = d;
          best = j;
        }
      }
      secs[k] = section_at(ctx, curve.points[k], curve.tangents[k], hint_normals[best],
                           ctx.params.slab, scratch, symmetric);
      secs[k].s = curve.s[k];
    }
  }
  // Where the V failed, its opening may still show as a gap of the seam's width (walls at a
  // grazing angle): the same test the tracking uses, with this pass's median width and depth.
  std::vector<double> widths, depths;
  for (const auto& s : secs) {
    if (!s.ok) continue;
    widths.push_back(s.width);
    depths.push_back(s.depth);
  }
  if (widths.size() >= 3) {
    const double width = upper_median(widths), depth = upper_median(depths);
    std::vector<std::uint32_t> scratch;
    for (std::size_t k = 0; k < m; ++k) {
      if (secs[k].ok) continue;
      const Eigen::Vector3d n = secs[k].normal.allFinite() ? secs[k].normal : hint_normals[0];
      ctx.bins.within(ctx.cloud, curve.points[k], 1.3 * ctx.half_window + ctx.params.slab, scratch);
      GrooveSection g = fit_gap_section(ctx.cloud, scratch, curve.points[k],
                                        surface_tangent(ctx, curve.points[k], curve.tangents[k], n),
                                        n, ctx.params.slab, ctx.half_window, width, depth);
      if (!g.inferred || !grazing(ctx, g.root, n) ||
          (g.root - curve.points[k]).norm() > 0.3 * ctx.params.scale) {
        continue;
      }
      g.s = secs[k].s;
      secs[k] = g;
    }
  }
  // Near a corner the window holds the other leg too: those fits are not trusted.
  for (auto& s : secs) {
    for (double c : curve.corners) {
      if (arc_distance(s.s, c, curve.length, curve.closed) < ctx.half_window * 0.6) {
        s.ok = s.inferred = false;
        s.why = "near a corner";
      }
    }
  }
  return secs;
}

// Extends an open seam past its ends by tracking: from the last ok sections, step one
// station along the seam as a quadratic through the last 15 mm of roots continues, fit a
// section there, repeat while fits pass (two misses in a row end it). The crease nodes stop
// short where the groove is seen at a grazing angle (a pipe's flanks) yet a section across
// the expected place still finds the V.
void extend_ends(const Context& ctx, std::vector<GrooveSection>& secs) {
  const double step = ctx.params.station;
  const double reach = 10 * ctx.params.scale;  // at most 100 mm more per end
  std::vector<std::uint32_t> scratch;
  std::vector<double> widths, depths;
  for (const auto& s : secs) {
    if (!s.ok) continue;
    widths.push_back(s.width);
    depths.push_back(s.depth);
  }
  if (widths.empty()) return;
  const double width = upper_median(widths), depth = upper_median(depths);
  for (int end = 0; end < 2; ++end) {
    if (end == 1) std::reverse(secs.begin(), secs.end());
    // Work at the back: drop trailing stations whose own fit failed.
    while (!secs.empty() && !secs.back().ok && !secs.back().inferred) secs.pop_back();
    int misses = 0;
    double grown = 0;
    std::vector<GrooveSection> pending;  // misses, kept only if a later fit passes
    while (grown < reach) {
      // The last ok roots within 15 mm of arc, back from the end, for the extrapolation.
      std::vector<Eigen::Vector3d> pts;
      std::vector<double> s;
      double arc = 0;
      for (std::size_t k = secs.size(); k-- > 0;) {
        if (k + 1 < secs.size()) arc += (secs[k + 1].root - secs[k].root).norm();
        if (arc > 1.5 * ctx.params.scale) break;
        if (!secs[k].ok && !secs[k].inferred) continue;
        pts.push_back(secs[k].root);
        s.push_back(-arc);
      }
      if (pts.size() < 4) break;
      // A line in arc length through those roots, continued by (misses + 1) steps; over a few
      // millimetres a seam's bend is far below the tolerance below.
      Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
      Eigen::Matrix<double, 2, 3> B = Eigen::Matrix<double, 2, 3>::Zero();
      for (std::size_t q = 0; q < pts.size(); ++q) {
        const Eigen::Vector2d b(1, s[q] / ctx.params.scale);
        A += b * b.transpose();
        B += b * pts[q].transpose();
      }
      const Eigen::Matrix<double, 2, 3> C = A.ldlt().solve(B);
      const double d = (misses + 1) * step / ctx.params.scale;
      const Eigen::Vector3d at = (C.row(0) + d * C.row(1)).transpose();
      const Eigen::Vector3d tangent = C.row(1).transpose().normalized();
      if (!at.allFinite() || !tangent.allFinite()) break;
      GrooveSection sec =
          section_at(ctx, at, tangent, secs.back().normal, ctx.params.slab, scratch);
      if (!sec.ok) {
        // The V may be invisible while its opening still shows as a gap in the surface.
        sec = fit_gap_section(ctx.cloud, scratch, at,
                              surface_tangent(ctx, at, tangent, secs.back().normal),
                              secs.back().normal, ctx.params.slab, ctx.half_window, width, depth);
        if (sec.inferred && !grazing(ctx, sec.root, secs.back().normal)) {
          sec.inferred = false;
          sec.why = "a gap seen square on";
        }
      }
      // A pass far off the predicted place is another feature, not this seam.
      // Across the seam the track must hold (3 mm). In depth a one-wall fit is looser (6 mm:
      // its root is where the seen wall meets the axis of a V taken symmetric); a two-wall V
      // must hold 3 mm too: past a part's end, a slab half on the groove and half on the end
      // face still fits a V, its root millimetres down the end face (2 mm also cut off true
      // fits on a far, tilted 640x480 S-curve). A gap carries no depth of its own (its root
      // is placed): it must continue the surface (2 mm, a normal within 20 deg) or it may walk
      // off along a shadow.
      const Eigen::Vector3d off = sec.root - at;
      const double across_tol = (sec.inferred ? 0.2 : 0.3) * ctx.params.scale;
      const double depth_tol = (sec.ok && sec.one_wall ? 0.6
                                : sec.ok               ? 0.3
                                                       : 0.2) *
                               ctx.params.scale;
      const bool turned =
          sec.inferred && sec.normal.dot(secs.back().normal) < std::cos(deg_to_rad(20.0));
      if ((sec.ok || sec.inferred) && (std::abs(off.dot(sec.across())) > across_tol ||
                                       std::abs(off.dot(sec.normal)) > depth_tol || turned)) {
        sec.ok = sec.inferred = false;
        sec.why = "off the tracked seam";
      }
      grown += step;
      if (sec.ok || sec.inferred) {
        for (auto& m : pending) secs.push_back(m);
        pending.clear();
        secs.push_back(sec);
        misses = 0;
      } else {
        sec.root = at;
        sec.tangent = tangent;
        sec.normal = secs.back().normal;
        pending.push_back(sec);
        if (++misses >= 2) break;
      }
    }
    if (end == 1) std::reverse(secs.begin(), secs.end());
  }
}

// A groove keeps its width and depth along a seam; a V fit far off the seam's medians over
// all its fits (narrower than 0.6 or wider than 1.6 times, shallower than 0.6 or deeper than
// 1.5 times) caught something else - a shadow's edge, the table through a dropout - and is
// not trusted.
void reject_inconsistent(std::vector<GrooveSection>& secs) {
  std::vector<double> widths, depths;
  for (const auto& s : secs) {
    if (!s.ok) continue;
    widths.push_back(s.width);
    depths.push_back(s.depth);
  }
  if (widths.size() < 5) return;
  const double width = upper_median(widths), depth = upper_median(depths);
  for (auto& s : secs) {
    if (!s.ok) continue;
    if (s.width < 0.6 * width || s.width > 1.6 * width || s.depth < 0.6 * depth ||
        s.depth > 1.5 * depth) {
      s.ok = false;
      s.why = "inconsistent with the seam";
    }
  }
}

// A one-wall section's root (where the unseen wall would meet the seen one) is sensitive to
// where the unseen rim is guessed; its depth is not. Where the seam has two-wall sections,
// one-wall roots are put the seam's median depth below their opening's centre, along the
// section's top normal.
void anchor_one_wall_roots(std::vector<GrooveSection>& secs) {
  std::vector<double> depths;
  for (const auto& s : secs) {
    if (s.ok && !s.one_wall) depths.push_back(s.depth);
  }
  if (depths.size() < 3) return;
  const double depth = upper_median(depths);
  for (auto& s : secs) {
    if (!s.ok || !s.one_wall) continue;
    const Eigen::Vector3d centre = 0.5 * (s.edge_left + s.edge_right);
    s.root = centre - depth * s.normal;
    s.depth = depth;
  }
}

// The wall bisector, per section, is the top normal turned about the tangent by the groove's
// asymmetry; the top normal comes from the wide top surfaces and is 2-3 times less noisy
// than the steep, often half-hidden walls. The asymmetry is a property of the seam: its
// median over the two-wall sections. Below kSymmetricDeg the groove is taken as symmetric
// (what a D415 at a slant reads as asymmetry stays below that on symmetric V-grooves); above,
// each section's bisector is the top normal turned by the median.
constexpr double kSymmetricDeg = 8.0;

// The seam's asymmetry (rad, about the tangent, from top normal to bisector): the median over
// its two-wall sections; NaN with fewer than three.
double seam_asymmetry(const std::vector<GrooveSection>& secs) {
  std::vector<double> asym;
  for (const auto& s : secs) {
    if (!s.ok || s.one_wall) continue;
    asym.push_back(std::atan2(s.normal.cross(s.bisector).dot(s.tangent), s.normal.dot(s.bisector)));
  }
  if (asym.size() < 3) return NAN;
  return upper_median(asym);
}

bool symmetric_seam(const std::vector<GrooveSection>& secs) {
  return std::abs(seam_asymmetry(secs)) < deg_to_rad(kSymmetricDeg);  // false for NaN
}

void align_bisectors(std::vector<GrooveSection>& secs) {
  double turn = seam_asymmetry(secs);
  if (std::isnan(turn)) return;
  if (std::abs(turn) < deg_to_rad(kSymmetricDeg)) turn = 0.0;
  for (auto& s : secs) {
    if (!s.ok && !s.inferred) continue;
    s.bisector = Eigen::AngleAxisd(turn, s.tangent.normalized()) * s.normal;
  }
}

// An open seam ends where its groove leaves the part or the view; the last sections there
// straddle the part's end face or the table. From each end, sections are dropped while their
// own fit failed (gap-inferred ones stay: a pipe's flanks) or gave a width far from the seam's
// median. Before that, the seam is cut at holes longer than `link` (m).
void trim_ends(SeamCandidate& seam, double link) {
  auto& secs = seam.sections;
  // Where smoothing dropped a long stretch (nothing fitted within reach), the curve across it
  // is a guess: keep the run between such holes that holds the most ok sections.
  {
    std::size_t best_lo = 0, best_hi = 0, best_ok = 0, lo = 0;
    for (std::size_t k = 1; k <= secs.size(); ++k) {
      if (k < secs.size() && (secs[k].root - secs[k - 1].root).norm() <= link) continue;
      std::size_t ok = 0;
      for (std::size_t q = lo; q < k; ++q) ok += secs[q].ok ? 1 : 0;
      if (ok > best_ok || (ok == best_ok && k - lo > best_hi - best_lo)) {
        best_ok = ok;
        best_lo = lo;
        best_hi = k;
      }
      lo = k;
    }
    if (best_hi - best_lo < secs.size()) {
      secs = std::vector<GrooveSection>(secs.begin() + static_cast<std::ptrdiff_t>(best_lo),
                                        secs.begin() + static_cast<std::ptrdiff_t>(best_hi));
    }
  }
  std::vector<double> widths;
  for (const auto& s : secs) {
    if (s.ok) widths.push_back(s.width);
  }
  if (widths.size() < 3) return;
  const double width = upper_median(widths);
  auto bad = [&](const GrooveSection& s) {
    if (s.inferred) return false;
    return !s.ok || s.width > 1.4 * width || s.width < 0.6 * width;
  };
  std::size_t lo = 0, hi = secs.size();
  while (lo < hi && bad(secs[lo])) ++lo;
  while (hi > lo && bad(secs[hi - 1])) --hi;
  if (hi - lo < 2) return;
  secs = std::vector<GrooveSection>(secs.begin() + static_cast<std::ptrdiff_t>(lo),
                                    secs.begin() + static_cast<std::ptrdiff_t>(hi));
}

SeamCandidate trace_seam(const Context& ctx, std::vector<Eigen::Vector3d> ordered,
                         std::vector<Eigen::Vector3d> normals, bool closed) {
  SeamCandidate seam;
  const RobustParams& p = ctx.params;
  // A symmetric seam (the first pass's walls dip alike, within kSymmetricDeg) is fitted with
  // symmetric V's the second time: at a slant one wall is seen at a grazing angle, a pixel's
  // footprint on it stretches to 2-4 mm, and its slope from the two or three image rows it
  // gets (one of them blurred into the root by stereo matching) comes out several degrees too
  // flat, which moves its rim out and the root towards the other wall by up to a millimetre.
  bool symmetric = false;
  for (int pass = 0; pass < 2; ++pass) {
    // Sampled finely, then at stations anchored to the frame (robust_stations.hpp).
    const SeamCurve curve = anchored_stations(
        smooth_curve(ordered, closed, p.smooth, 0.25 * p.station, normals), p.station);
    if (curve.points.size() < 2) break;
    std::vector<GrooveSection> raw = fit_stations(ctx, curve, ordered, normals, symmetric);
    reject_inconsistent(raw);
    if (pass == 0) symmetric = symmetric_seam(raw);
    anchor_one_wall_roots(raw);
    align_bisectors(raw);
    std::vector<GrooveSection> smooth = smooth_sections(raw, curve, p.smooth);
    if (pass == 0 && !closed) {
      extend_ends(ctx, smooth);
      if (smooth.size() < 2) break;
    }
    seam.curve = curve;
    seam.sections = smooth;
    seam.raw = raw;
    if (smooth.size() < 2) break;
    // The next pass follows this one's roots; where fits failed those are the curve's own
    // points (a corner's legs meet where their lines do), so no gap cuts a corner short.
    ordered.clear();
    normals.clear();
    for (const auto& s : smooth) {
      ordered.push_back(s.root);
      normals.push_back(s.normal);
    }
  }
  if (!closed) trim_ends(seam, 1.5 * p.scale);
  // Length, arc lengths and corners along the smoothed roots (for the score and the region).
  if (seam.sections.size() >= 2) {
    std::vector<double> old_s, new_s;
    double s = 0;
    for (std::size_t k = 0; k < seam.sections.size(); ++k) {
      if (k > 0) s += (seam.sections[k].root - seam.sections[k - 1].root).norm();
      old_s.push_back(seam.sections[k].s);
      new_s.push_back(s);
      seam.sections[k].s = s;
    }
    if (closed) s += (seam.sections.front().root - seam.sections.back().root).norm();
    std::vector<double> corners;
    for (double c : seam.curve.corners) {
      std::size_t best = 0;
      for (std::size_t k = 0; k < old_s.size(); ++k) {
        if (std::abs(old_s[k] - c) < std::abs(old_s[best] - c)) best = k;
      }
      corners.push_back(new_s[best]);
    }
    seam.curve.corners = corners;
    seam.curve.length = s;
    seam.curve.closed = closed;
  }
  seam.closed = closed;
  return seam;
}

// Outward unit direction of an open seam at its end `which` (0 first, 1 last), from the roots
// within 10 mm of it.
Eigen::Vector3d end_direction(const SeamCandidate& s, int which) {
  const auto& secs = s.sections;
  const Eigen::Vector3d end = which == 0 ? secs.front().root : secs.back().root;
  Eigen::Vector3d inner = end;
  for (std::size_t q = 0; q < secs.size(); ++q) {
    const auto& r = secs[which == 0 ? q : secs.size() - 1 - q].root;
    if ((r - end).norm() > 0.01) break;
    inner = r;
  }
  const Eigen::Vector3d d = end - inner;
  return d.norm() > 1e-6 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::Zero();
}

// The gap (m) between two open seams that continue each other across it (each end points at
// the other within 30 deg), or infinity.
double collinear_gap(const SeamCandidate& a, const SeamCandidate& b) {
  if (a.closed || b.closed || a.sections.size() < 2 || b.sections.size() < 2) return INFINITY;
  double best = INFINITY;
  for (int ea = 0; ea < 2; ++ea) {
    for (int eb = 0; eb < 2; ++eb) {
      const Eigen::Vector3d pa = ea == 0 ? a.sections.front().root : a.sections.back().root;
      const Eigen::Vector3d pb = eb == 0 ? b.sections.front().root : b.sections.back().root;
      const Eigen::Vector3d gap = pb - pa;
      const double len = gap.norm();
      if (!(len > 0)) return 0.0;
      const double cos30 = 0.866;
      if (end_direction(a, ea).dot(gap / len) > cos30 &&
          end_direction(b, eb).dot(-gap / len) > cos30) {
        best = std::min(best, len);
      }
    }
  }
  return best;
}

// Whether two seams look like stretches of one groove: each made of V fits (40 %), their
// median widths within 30 % of each other. A bridge across a gap needs that; a chain of
// shadow-edge fits beside a pipe does not have it.
bool same_groove(const SeamCandidate& a, const SeamCandidate& b) {
  auto stats = [](const SeamCandidate& s, double& ok, double& width) {
    std::vector<double> w;
    for (const auto& g : s.sections) {
      if (g.ok) w.push_back(g.width);
    }
    ok = s.sections.empty() ? 0.0 : static_cast<double>(w.size()) / s.sections.size();
    if (w.empty()) {
      width = 0;
      return;
    }
    width = upper_median(w);
  };
  double oka, wa, okb, wb;
  stats(a, oka, wa);
  stats(b, okb, wb);
  return oka >= 0.4 && okb >= 0.4 && wa > 0 && wb > 0 &&
         std::abs(wa - wb) <= 0.3 * std::max(wa, wb);
}

// Seams traced from separate node paths can be one: the tracking of one runs into the other,
// or both stop short of a corner or of a noisy stretch. The second seam's sections that
// overlap the first are dropped; when the rest is one run whose end faces an end of the
// first (touching, or continuing it across a gap of up to 3 links), the two are joined end
// to end and traced again. Joining end to end, rather than re-ordering both sets of roots,
// cannot fold the path back over itself.
void merge_seams(const Context& ctx, std::vector<SeamCandidate>& seams, double link) {
  for (int round = 0; round < 8; ++round) {
    bool merged = false;
    for (std::size_t i = 0; i < seams.size() && !merged; ++i) {
      for (std::size_t j = 0; j < seams.size() && !merged; ++j) {
        if (i == j || seams[i].closed || seams[j].closed) continue;
        const SeamCandidate& a = seams[i];
        const SeamCandidate& b = seams[j];
        if (a.sections.size() < 2 || b.sections.size() < 2) continue;
        // b's sections away from a, as one run.
        std::vector<std::size_t> rest;
        for (std::size_t k = 0; k < b.sections.size(); ++k) {
          bool overlaps = false;
          for (const auto& s : a.sections) {
            if ((s.root - b.sections[k].root).norm() < 0.5 * link) {
              overlaps = true;
              break;
            }
          }
          if (!overlaps) rest.push_back(k);
        }
        if (rest.size() < 2 || rest.back() - rest.front() + 1 != rest.size()) continue;
        const bool trimmed = rest.size() < b.sections.size();
        // The facing pair of ends, and the join's reach.
        double best = INFINITY;
        int best_ea = 0, best_eb = 0;
        for (int ea = 0; ea < 2; ++ea) {
          for (int eb = 0; eb < 2; ++eb) {
            const Eigen::Vector3d pa = ea == 0 ? a.sections.front().root : a.sections.back().root;
            const Eigen::Vector3d pb =
                (eb == 0 ? b.sections[rest.front()] : b.sections[rest.back()]).root;
            const double d = (pa - pb).norm();
            if (d < best) {
              best = d;
              best_ea = ea;
              best_eb = eb;
            }
          }
        }
        bool join = best <= link;
        if (!join && !trimmed) join = collinear_gap(a, b) <= 3 * link && same_groove(a, b);
        if (!join) continue;
        std::vector<Eigen::Vector3d> ordered, normals;
        for (std::size_t q = 0; q < a.sections.size(); ++q) {
          const auto& s = a.sections[best_ea == 1 ? q : a.sections.size() - 1 - q];
          ordered.push_back(s.root);
          normals.push_back(s.normal);
        }
        for (std::size_t q = 0; q < rest.size(); ++q) {
          const auto& s = b.sections[best_eb == 0 ? rest[q] : rest[rest.size() - 1 - q]];
          ordered.push_back(s.root);
          normals.push_back(s.normal);
        }
        SeamCandidate joined = trace_seam(ctx, ordered, normals, false);
        if (joined.sections.size() < 2) continue;
        const std::size_t hi = std::max(i, j), lo = std::min(i, j);
        seams.erase(seams.begin() + static_cast<std::ptrdiff_t>(hi));
        seams.erase(seams.begin() + static_cast<std::ptrdiff_t>(lo));
        seams.push_back(std::move(joined));
        merged = true;
      }
    }
    if (!merged) break;
  }
}

}  // namespace

RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                              const std::function<void(const std::string&)>& lap) {
  const auto cpu = make_cpu_backend();
  return detect_robust(cloud, params, *cpu, lap);
}

RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                              FeatureBackend& backend,
                              const std::function<void(const std::string&)>& lap) {
  RobustDetection det;
  det.groove.assign(cloud.size(), 0);
  det.concavity.assign(cloud.size(), NAN);
  det.normals.resize(cloud.size());
  const CreaseMap map = crease_map(cloud, params, backend);
  det.threshold = map.threshold;
  det.noise_sigma = map.sigma;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::int32_t v = map.voxel[i];
    if (v < 0) continue;
    det.concavity[i] = map.concavity[v];
    det.normals.x[i] = map.normals[v].x();
    det.normals.y[i] = map.normals[v].y();
    det.normals.z[i] = map.normals[v].z();
  }
  for (float c : map.concavity) det.candidates += (std::isfinite(c) && c > map.threshold) ? 1 : 0;
  const CreaseNodes nodes = crease_nodes(map, params);
  det.nodes = nodes.voxel.size();
  if (lap) lap("candidates");
  if (nodes.voxel.empty()) return det;

  Cloud voxels = voxel_cloud(map);
  const NeighborGrid voxel_grid(voxels, static_cast<float>(params.scale));
  Context ctx{cloud,
              params,
              map,
              std::move(voxels),
              voxel_grid,
              BoxBins(cloud, 0.25 * params.scale),
              2 * params.scale};

  // Confirm each node with a V fit across its own direction (a thicker slab: one fit only).
  const std::size_t nn = nodes.voxel.size();
  std::vector<GrooveSection> checks(nn);
  const std::int64_t count = static_cast<std::int64_t>(nn);
#pragma omp parallel
  {
    std::vector<std::uint32_t> scratch;
#pragma omp for schedule(dynamic, 8)
    for (std::int64_t k = 0; k < count; ++k) {
      const std::int32_t v = nodes.voxel[k];
      checks[k] = section_at(ctx, map.points[v].cast<double>(), nodes.tangent[k],
                             map.normals[v].cast<double>(), 2 * params.slab, scratch);
    }
  }
  std::vector<Eigen::Vector3d> pts, tans, nrms;
  for (std::size_t k = 0; k < nn; ++k) {
    if (!checks[k].ok) continue;
    pts.push_back(checks[k].root);
    tans.push_back(checks[k].tangent);
    nrms.push_back(checks[k].normal);
  }
  det.confirmed_nodes = pts.size();

  const double link = 1.5 * params.scale;
  const auto min_nodes =
      static_cast<std::size_t>(std::max(5.0, params.min_length / params.cell / 3));
  for (const NodePath& path : order_nodes(pts, tans, link, min_nodes)) {
    std::vector<Eigen::Vector3d> ordered, normals;
    for (int v : path.nodes) {
      ordered.push_back(pts[v]);
      normals.push_back(nrms[v]);
    }
    det.seams.push_back(trace_seam(ctx, ordered, normals, path.closed));
  }
  merge_seams(ctx, det.seams, link);
  for (SeamCandidate& seam : det.seams) score_seam(seam, params);
  std::stable_sort(det.seams.begin(), det.seams.end(),
                   [](const SeamCandidate& a, const SeamCandidate& b) {
                     if (a.accepted != b.accepted) return a.accepted;
                     return a.score > b.score;
                   });
  if (lap) lap("seams");
  det.groove = label_grooves(cloud, det.seams);
  if (lap) lap("region");
  return det;
}

}  // namespace groovetrace
