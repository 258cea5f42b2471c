// A seam traced from its ordered nodes: sections fitted at stations along its curve, checked
// against each other, smoothed, extended past the ends by tracking, fitted a second time along
// the first pass's roots, and trimmed where the groove ends.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/stats.hpp"
#include "robust/context.hpp"
#include "robust/stations.hpp"

namespace groovetrace::robust_detail {

GrooveSection section_at(const Context& ctx, const Eigen::Vector3d& origin,
                         const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal, double slab,
                         std::vector<std::uint32_t>& scratch, bool symmetric) {
  const Eigen::Vector3d t = surface_tangent(ctx, origin, tangent, normal);
  // The ball holds the window across, the slab along and the groove's depth below.
  const double radius = 1.3 * ctx.half_window + slab;
  ctx.bins.within(ctx.cloud, origin, radius, scratch);
  return fit_section(ctx.cloud, scratch, origin, t, normal, slab, ctx.half_window, symmetric);
}

namespace {

// Arc-length distance between stations a and b (wrapping on rings).
double arc_distance(double a, double b, double length, bool closed) {
  double d = std::abs(a - b);
  if (closed) d = std::min(d, length - d);
  return d;
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

}  // namespace

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

}  // namespace groovetrace::robust_detail
