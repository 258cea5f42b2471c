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
                         std::vector<std::uint32_t>& scratch, VFit mode, bool curved) {
  const Eigen::Vector3d t = surface_tangent(ctx, origin, tangent, normal, curved);
  mode.corner_leg = ctx.params.fillet_leg;
  // The ball holds the window across, the slab along and the groove's depth below.
  const double radius = 1.3 * ctx.half_window + slab;
  ctx.bins.within_slab(ctx.cloud, origin, radius, t.normalized(), slab, scratch);
  return fit_section(ctx.cloud, scratch, origin, t, normal, slab, ctx.half_window, mode);
}

namespace {

// Arc-length distance between stations a and b (wrapping on rings).
double arc_distance(double a, double b, double length, bool closed) {
  double d = std::abs(a - b);
  if (closed) d = std::min(d, length - d);
  return d;
}

// The median width and depth (m) of the sections whose own V fit passed, and how many passed.
struct OkMedians {
  std::size_t count = 0;
  double width = NAN, depth = NAN;
};

OkMedians ok_medians(const std::vector<GrooveSection>& secs) {
  std::vector<double> widths, depths;
  for (const auto& s : secs) {
    if (!s.ok) continue;
    widths.push_back(s.width);
    depths.push_back(s.depth);
  }
  OkMedians med;
  med.count = widths.size();
  med.width = upper_median(std::move(widths));
  med.depth = upper_median(std::move(depths));
  return med;
}

// Where the V is not seen its opening may still show as a gap of the seam's width in the top
// surface (walls at a grazing angle): the gap section at `origin` across `tangent` laid into
// the surface, its root the seam's median depth below the gap.
GrooveSection gap_section_at(const Context& ctx, const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal,
                             const OkMedians& med, std::vector<std::uint32_t>& scratch) {
  const Eigen::Vector3d t = surface_tangent(ctx, origin, tangent, normal);
  ctx.bins.within_slab(ctx.cloud, origin, 1.3 * ctx.half_window + ctx.params.slab, t.normalized(),
                       ctx.params.slab, scratch);
  return fit_gap_section(ctx.cloud, scratch, origin, t, normal, ctx.params.slab, ctx.half_window,
                         med.width, med.depth);
}

// The index of the point of `points` nearest to p (the first of equals).
std::size_t nearest(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& p) {
  std::size_t best = 0;
  double best_d = INFINITY;
  for (std::size_t j = 0; j < points.size(); ++j) {
    const double d = (points[j] - p).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = j;
    }
  }
  return best;
}

// A seam whose median turn out of its surface exceeds this (1/m: a radius of 100 mm) lies on
// a curved part, a pipe. On plates a D415's roots make the curve's turn, measured over
// +-18 mm, scatter to 20-50 /m at single stations, and its median reached 5-7 /m on a box
// seen at 0.55 m (640x480). A girth seam's root turns at 11 /m on a 200 mm pipe, 38 /m on a
// 60 mm one.
constexpr double kMinBend = 10.0;

// Whether `curve` bends out of its surface: the median over its points of its tangent's turn
// between `half` (m) of arc length before and after (one-sided at an open curve's ends;
// rings wrap), per metre, along the surface normal there (that of the nearest of
// `hint_points`). Never with corners (an L's turn is no bend of the surface) nor on a curve
// shorter than two windows, which holds no median worth the name (a 12-29 mm stretch of a
// lap's edge read as a V came out bent).
bool bends_out_of_surface(const SeamCurve& curve, const std::vector<Eigen::Vector3d>& hint_points,
                          const std::vector<Eigen::Vector3d>& hint_normals, double half) {
  const std::size_t m = curve.points.size();
  if (!curve.corners.empty() || m < 3 || curve.length < 2 * half) return false;
  // The index `half` of arc length (or less) from k in direction `dir` (+1 or -1).
  auto reach = [&](std::size_t k, int dir, double& arc) {
    std::size_t j = k;
    arc = 0;
    for (std::size_t step = 0; step + 1 < m; ++step) {
      if (!curve.closed && (dir < 0 ? j == 0 : j + 1 == m)) break;
      const std::size_t next = dir < 0 ? (j + m - 1) % m : (j + 1) % m;
      const double d = arc_distance(curve.s[next], curve.s[j], curve.length, curve.closed);
      if (arc + d > half) break;
      arc += d;
      j = next;
    }
    return j;
  };
  std::vector<double> out_of_surface;
  for (std::size_t k = 0; k < m; ++k) {
    double before = 0, after = 0;
    const std::size_t lo = reach(k, -1, before), hi = reach(k, +1, after);
    if (!(before + after > 0)) continue;
    const Eigen::Vector3d turn = (curve.tangents[hi] - curve.tangents[lo]) / (before + after);
    const Eigen::Vector3d& n = hint_normals[nearest(hint_points, curve.points[k])];
    out_of_surface.push_back(turn.dot(n.normalized()));
  }
  return !out_of_surface.empty() && std::abs(upper_median(out_of_surface)) > kMinBend;
}

// Stations along `curve`, each fitted; normals from the nearest of `hint_points`. `mode` as in
// fit_v_profile; `curved`: the seam lies on a curved part (bends_out_of_surface).
// Where the V failed, a gap of the seam's width seen at a slant stands in (the same test the
// tracking uses, with this pass's median width and depth).
std::vector<GrooveSection> fit_stations(const Context& ctx, const SeamCurve& curve,
                                        const std::vector<Eigen::Vector3d>& hint_points,
                                        const std::vector<Eigen::Vector3d>& hint_normals, VFit mode,
                                        bool curved) {
  const std::size_t m = curve.points.size();
  std::vector<GrooveSection> secs(m);
  const std::int64_t count = static_cast<std::int64_t>(m);
#pragma omp parallel
  {
    std::vector<std::uint32_t> scratch;
#pragma omp for schedule(dynamic, 4)
    for (std::int64_t k = 0; k < count; ++k) {
      const std::size_t best = nearest(hint_points, curve.points[k]);
      secs[k] = section_at(ctx, curve.points[k], curve.tangents[k], hint_normals[best],
                           ctx.params.slab, scratch, mode, curved);
      secs[k].s = curve.s[k];
    }
  }
  const OkMedians med = ok_medians(secs);
  std::vector<std::uint32_t> scratch;
  const bool gaps = mode.kind != VFit::Kind::corner;  // a corner has no top to hold a gap
  for (std::size_t k = 0; k < m && gaps && med.count >= 3; ++k) {
    if (secs[k].ok) continue;
    const Eigen::Vector3d n = secs[k].normal.allFinite() ? secs[k].normal : hint_normals[0];
    GrooveSection g = gap_section_at(ctx, curve.points[k], curve.tangents[k], n, med, scratch);
    if (!g.inferred || !grazing(ctx, g.root, n) ||
        (g.root - curve.points[k]).norm() > 0.3 * ctx.params.scale) {
      continue;
    }
    g.s = secs[k].s;
    secs[k] = g;
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

}  // namespace

// Where an open seam continues `steps` stations past the last of `secs`: a line in arc length
// through the ok roots within 1.5 scale (15 mm) of arc back from the end, continued (over a few
// millimetres a seam's bend is far below the tolerances of off_track), and its direction.
// False with fewer than four such roots or a degenerate line.
bool continue_seam(const Context& ctx, const std::vector<GrooveSection>& secs, int steps,
                   Eigen::Vector3d& at, Eigen::Vector3d& tangent) {
  const double scale = ctx.params.scale;
  std::vector<Eigen::Vector3d> pts;
  std::vector<double> s;
  double arc = 0;
  for (std::size_t k = secs.size(); k-- > 0;) {
    if (k + 1 < secs.size()) arc += (secs[k + 1].root - secs[k].root).norm();
    if (arc > 1.5 * scale) break;
    if (!secs[k].ok && !secs[k].inferred) continue;
    pts.push_back(secs[k].root);
    s.push_back(-arc);
  }
  if (pts.size() < 4) return false;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Matrix<double, 2, 3> B = Eigen::Matrix<double, 2, 3>::Zero();
  for (std::size_t q = 0; q < pts.size(); ++q) {
    const Eigen::Vector2d b(1, s[q] / scale);
    A += b * b.transpose();
    B += b * pts[q].transpose();
  }
  const Eigen::Matrix<double, 2, 3> C = A.ldlt().solve(B);
  const double d = steps * ctx.params.station / scale;
  at = (C.row(0) + d * C.row(1)).transpose();
  tangent = C.row(1).transpose().normalized();
  return at.allFinite() && tangent.allFinite();
}

namespace {

// Whether a section tracked at `at` lies off the seam (another feature). Across the seam the
// track must hold (3 mm). In depth a one-wall fit is looser (6 mm: its root is where the seen
// wall meets the axis of a V taken symmetric); a two-wall V must hold 3 mm too: past a part's
// end, a slab half on the groove and half on the end face still fits a V, its root millimetres
// down the end face (2 mm also cut off true fits on a far, tilted 640x480 S-curve). A gap
// carries no depth of its own (its root is placed): it must continue the surface (2 mm, a
// normal within 20 deg of the seam's last, `normal`) or it may walk off along a shadow.
bool off_track(const Context& ctx, const GrooveSection& sec, const Eigen::Vector3d& at,
               const Eigen::Vector3d& normal) {
  const Eigen::Vector3d off = sec.root - at;
  const double across_tol = (sec.inferred ? 0.2 : 0.3) * ctx.params.scale;
  const double depth_tol = (sec.ok && sec.one_wall ? 0.6 : sec.ok ? 0.3 : 0.2) * ctx.params.scale;
  const bool turned = sec.inferred && sec.normal.dot(normal) < std::cos(deg_to_rad(20.0));
  return std::abs(off.dot(sec.across())) > across_tol ||
         std::abs(off.dot(sec.normal)) > depth_tol || turned;
}

// The section tracked at `at` across `tangent` (`normal`: the seam's last section's): a V, or
// where none fits a gap of the seam's width seen at a slant; neither when off the track.
GrooveSection section_ahead(const Context& ctx, const OkMedians& med, const Eigen::Vector3d& at,
                            const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal,
                            VFit mode) {
  std::vector<std::uint32_t> scratch;
  GrooveSection sec = section_at(ctx, at, tangent, normal, ctx.params.slab, scratch, mode);
  if (!sec.ok && mode.kind != VFit::Kind::corner) {
    sec = gap_section_at(ctx, at, tangent, normal, med, scratch);
    if (sec.inferred && !grazing(ctx, sec.root, normal)) {
      sec.inferred = false;
      sec.why = "a gap seen square on";
    }
  }
  if ((sec.ok || sec.inferred) && off_track(ctx, sec, at, normal)) {
    sec.ok = sec.inferred = false;
    sec.why = "off the tracked seam";
  }
  return sec;
}

// Tracking crosses up to kBridge (m) of stations that do not fit - a clamp hiding the
// groove, a shallow groove's stretch lost in the noise - when the groove resumes beyond in
// kResume V fits in a row on the tracked line; fewer, and the stations past the gap are
// dropped (one or two fits pass beyond a plate's end, where a slab half on the end face
// still fits a V).
constexpr double kBridge = 0.02;
constexpr int kResume = 3;

// Whether a V fit past a gap continues the seam: on the tracked line within 2 mm across and
// in depth, with the seam's width and depth within 30 %.
bool resumes(const GrooveSection& sec, const Eigen::Vector3d& at, const OkMedians& med) {
  const Eigen::Vector3d off = sec.root - at;
  const auto near = [](double x, double ref) { return std::abs(x - ref) <= 0.3 * ref; };
  return std::abs(off.dot(sec.across())) <= 0.002 && std::abs(off.dot(sec.normal)) <= 0.002 &&
         near(sec.width, med.width) && near(sec.depth, med.depth);
}

// Extends `secs` past its last section by tracking (see extend_ends): trailing stations whose
// own fit failed are dropped first; misses are kept only if a later fit passes (after a gap
// of more than one miss, kResume fits).
void extend_back(const Context& ctx, const OkMedians& med, std::vector<GrooveSection>& secs,
                 VFit mode) {
  const double reach = 10 * ctx.params.scale;  // at most 100 mm more per end
  const int max_misses = std::max(2, static_cast<int>(kBridge / ctx.params.station));
  while (!secs.empty() && !secs.back().ok && !secs.back().inferred) secs.pop_back();
  std::vector<GrooveSection> pending;
  int misses = 0, probation = 0;  // probation: fits still needed past a gap
  std::size_t kept = secs.size();
  for (double grown = 0; grown < reach; grown += ctx.params.station) {
    Eigen::Vector3d at, tangent;
    if (!continue_seam(ctx, secs, misses + 1, at, tangent)) break;
    const Eigen::Vector3d normal = secs.back().normal;
    GrooveSection sec = section_ahead(ctx, med, at, tangent, normal, mode);
    if (sec.ok && (misses >= 2 || probation > 0) && !resumes(sec, at, med)) sec.ok = false;
    if (sec.ok || (sec.inferred && probation == 0 && misses < 2)) {
      if (misses >= 2) probation = kResume;
      secs.insert(secs.end(), pending.begin(), pending.end());
      pending.clear();
      secs.push_back(sec);
      misses = 0;
      if (probation > 0) --probation;
      if (probation == 0) kept = secs.size();
    } else {
      if (probation > 0) break;
      sec.root = at;
      sec.tangent = tangent;
      sec.normal = normal;
      pending.push_back(sec);
      if (++misses >= max_misses) break;
    }
  }
  secs.erase(secs.begin() + static_cast<std::ptrdiff_t>(kept), secs.end());
}

// Extends an open seam past its ends by tracking: from the last ok sections, step one station
// along the seam as the line through its last roots continues, fit a section there, repeat
// while fits pass (two misses in a row end it). The crease nodes stop short where the groove
// is seen at a grazing angle (a pipe's flanks) yet a section across the expected place still
// finds the V.
void extend_ends(const Context& ctx, std::vector<GrooveSection>& secs, VFit mode) {
  const OkMedians med = ok_medians(secs);
  if (med.count == 0) return;
  extend_back(ctx, med, secs, mode);
  std::reverse(secs.begin(), secs.end());
  extend_back(ctx, med, secs, mode);
  std::reverse(secs.begin(), secs.end());
}

// A groove keeps its width and depth along a seam; a V fit far off the seam's medians over
// all its fits (narrower than 0.6 or wider than 1.6 times, shallower than 0.6 or deeper than
// 1.5 times) caught something else - a shadow's edge, the table through a dropout - and is
// not trusted.
//
// One kind of failure is a finding: shallower than 0.6 times the median depth with the seam's
// width (its rims are where the seam's are), something fills the groove - a tack weld
// (`filled`; reported, see find_tacks).
void reject_inconsistent(std::vector<GrooveSection>& secs) {
  const OkMedians med = ok_medians(secs);
  if (med.count < 5) return;
  for (auto& s : secs) {
    if (!s.ok) continue;
    const bool wide_as_seam = s.width >= 0.6 * med.width && s.width <= 1.6 * med.width;
    if (wide_as_seam && s.depth < 0.6 * med.depth && !s.corner) {
      s.ok = false;
      s.filled = true;
      s.why = "filled: shallower than the seam (a tack weld)";
    } else if (!wide_as_seam || s.depth < 0.6 * med.depth || s.depth > 1.5 * med.depth) {
      s.ok = false;
      s.why = "inconsistent with the seam";
    }
  }
}

// The seam's root gap (m): the median over its two-wall sections; 0 with fewer than three.
double seam_gap(const std::vector<GrooveSection>& secs) {
  std::vector<double> gaps;
  for (const auto& s : secs) {
    if (s.ok && !s.one_wall && !s.corner) gaps.push_back(s.gap);
  }
  return gaps.size() < 3 ? 0.0 : upper_median(gaps);
}

// The root of a joint with a root gap is the middle of the opening at the root faces, not where
// the walls, extended, meet below it (a 0.5 mm gap puts that 0.43 mm deeper in a 60 deg V, a
// bevel's 0.5 mm off to its square side as well). One station's gap is a handful of points, so
// the seam's is the median over its two-wall sections; every section whose root is the walls'
// meeting point (a one-wall one's is anchored after) moves up the line from it to the
// opening's centre by the share gap / width, where the walls are the gap apart. Returns the
// seam's gap (m; 0 with fewer than three two-wall sections).
double open_root_gap(std::vector<GrooveSection>& secs) {
  const double gap = seam_gap(secs);
  if (!(gap > 0)) return 0.0;
  for (auto& s : secs) {
    if (!s.ok || s.corner || (s.one_wall && !s.square_side) || !(s.width > gap)) continue;
    const double t = gap / s.width;
    s.root += t * (0.5 * (s.edge_left + s.edge_right) - s.root);
    s.depth *= 1.0 - t;
  }
  return gap;
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
    if (!s.ok || !s.one_wall || s.square_side) continue;
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
// each section's bisector is the top normal turned by the median - on a single bevel only
// (align_bisectors).
constexpr double kSymmetricDeg = 8.0;

// The seam's asymmetry (rad, about the tangent, from top normal to bisector): the median over
// its two-wall sections and those one-wall sections whose hidden side is square (their
// bisector is measured, not assumed); NaN with fewer than three.
double seam_asymmetry(const std::vector<GrooveSection>& secs) {
  std::vector<double> asym;
  for (const auto& s : secs) {
    if (!s.ok || (s.one_wall && !s.square_side)) continue;
    asym.push_back(std::atan2(s.normal.cross(s.bisector).dot(s.tangent), s.normal.dot(s.bisector)));
  }
  if (asym.size() < 3) return NAN;
  return upper_median(asym);
}

bool symmetric_seam(const std::vector<GrooveSection>& secs) {
  return std::abs(seam_asymmetry(secs)) < deg_to_rad(kSymmetricDeg);  // false for NaN
}

// A high-low below this share of the groove's depth is not modelled, nor one that is not the
// same all along the seam: a D415's noise and undulation alone make the two top sides of a
// level joint differ by up to a millimetre at 640x480, this way and that, and fitting a step
// to that would take the top's slope from each side's short run alone.
constexpr double kStepShare = 0.1;

// The two top sides of plates set high-low are parallel: the median of their slopes' difference
// beyond the edges (GrooveSection::top_bend) is within 0.026 on nine high-low scans' seams at
// 640x480 and 1280x720 (0.036 on a short piece at a 30 deg tilt) and 0.005 on a level girth
// seam. Round a cylinder seen at a slant it reads 0.05-0.08, one side bending away, and lines
// through the sides then differ in height by 1-2 mm at the centre.
constexpr double kParallelBend = 0.04;

// The two-wall sections' signed steps between the top sides (right minus left, the same sides
// all along a seam), their depths and their sides' bends.
struct SeamSteps {
  std::vector<double> step, depth, bend;
  // `outer`: the steps of the outer half's lines, else from the edges out (misalignment).
  SeamSteps(const std::vector<GrooveSection>& secs, bool outer) {
    for (const auto& s : secs) {
      if (!s.ok || s.one_wall) continue;
      step.push_back(outer ? s.outer_step : s.misalignment);
      depth.push_back(s.depth);
      if (std::isfinite(s.top_bend)) bend.push_back(s.top_bend);
    }
  }
  // The median step when it clears the groove's size and `spread` times its own spread along
  // the seam, else 0 (m).
  double clear_step(double spread) const {
    if (step.size() < 3) return 0.0;
    const double median = upper_median(step);
    const double clear =
        std::max(kStepShare * upper_median(depth), spread * mad_sigma(step, median));
    return std::abs(median) > clear ? median : 0.0;
  }
};

// Plates set high-low along the whole seam, as one pass reads them: parallel sides and a median
// step clear of two thirds of its spread (the median of many stations is surer than one).
// The step (m), 0 when not. Found so, nine high-low scans' passes read 0.76-3.3 times their
// spread; level joints read up to 1.5 mm at 640x480 (box at 0.55 m: 0.52 times; girth round
// a 79 mm pipe: 0.88 in the first pass, 0.62 in the second).
double seam_step(const std::vector<GrooveSection>& secs) {
  const SeamSteps s(secs, false);
  if (s.bend.size() < 3 || std::abs(upper_median(s.bend)) > kParallelBend) return 0.0;
  return s.clear_step(2.0 / 3.0);
}

// The step `first` as the second pass's sections (fitted without it, framed by the first pass's
// roots and normals rather than the crease's) read it again, else 0 (m).
double step_read_again(double first, const std::vector<GrooveSection>& secs) {
  const double again = seam_step(secs);
  return again * first > 0 ? again : 0.0;
}

// The tops differ in height at each station by more than the steps' spread (a clamp beside the
// groove, a short piece's plates): each station is fitted with the step it reads itself.
bool stepped_seam(const std::vector<GrooveSection>& secs) {
  return SeamSteps(secs, true).clear_step(1.0) != 0.0;
}

VFit seam_fit_mode(const std::vector<GrooveSection>& secs) {
  VFit mode;
  mode.root_gap = seam_gap(secs) > 0;
  mode.stepped = stepped_seam(secs);
  mode.symmetric = !mode.stepped && symmetric_seam(secs);
  mode.square = mode.stepped || mode.symmetric ? 0 : bevel_square_side(secs);
  return mode;
}

// A groove seam that is no single bevel (`mode`: the first pass's finding) has walls that dip
// alike: the joints welded are symmetric V's and bevels. What it reads as asymmetry is the
// view's: a narrow V seen at a slant gets one or two image rows on its far wall, which read
// flatter, and a 4 mm V at 30 deg tilt read 15 deg asymmetric - the torch 15 deg off.
void align_bisectors(std::vector<GrooveSection>& secs, const VFit& mode) {
  double turn = seam_asymmetry(secs);
  if (std::isnan(turn)) return;
  const bool v_groove = mode.kind == VFit::Kind::groove && mode.square == 0;
  if (v_groove || std::abs(turn) < deg_to_rad(kSymmetricDeg)) turn = 0.0;
  for (auto& s : secs) {
    if (!s.ok && !s.inferred) continue;
    s.bisector = Eigen::AngleAxisd(turn, s.tangent.normalized()) * s.normal;
  }
}

// Where smoothing dropped a long stretch (nothing fitted within reach), the curve across it is
// a guess: keeps the run between holes longer than `link` (m) that holds the most ok sections
// (the longer of equals).
void keep_best_run(std::vector<GrooveSection>& secs, double link) {
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

// An open seam ends where its groove leaves the part or the view; the last sections there
// straddle the part's end face or the table. From each end, sections are dropped while their
// own fit failed (gap-inferred ones stay: a pipe's flanks) or gave a width far from the seam's
// median. Before that, the seam is cut at holes longer than `link` (m).
void trim_ends(SeamCandidate& seam, double link) {
  auto& secs = seam.sections;
  keep_best_run(secs, link);
  const OkMedians med = ok_medians(secs);
  if (med.count < 3) return;
  auto bad = [&](const GrooveSection& s) {
    if (s.inferred) return false;
    return !s.ok || s.width > 1.4 * med.width || s.width < 0.6 * med.width;
  };
  std::size_t lo = 0, hi = secs.size();
  while (lo < hi && bad(secs[lo])) ++lo;
  while (hi > lo && bad(secs[hi - 1])) --hi;
  if (hi - lo < 2) return;
  secs = std::vector<GrooveSection>(secs.begin() + static_cast<std::ptrdiff_t>(lo),
                                    secs.begin() + static_cast<std::ptrdiff_t>(hi));
}

}  // namespace

// The seam's length, arc lengths and corners measured along its smoothed roots (for the score
// and the region): each corner and tack moves to the station nearest its old arc length.
void measure_along_roots(SeamCandidate& seam, bool closed) {
  std::vector<double> old_s, new_s;
  double s = 0;
  for (std::size_t k = 0; k < seam.sections.size(); ++k) {
    if (k > 0) s += (seam.sections[k].root - seam.sections[k - 1].root).norm();
    old_s.push_back(seam.sections[k].s);
    new_s.push_back(s);
    seam.sections[k].s = s;
  }
  if (closed) s += (seam.sections.front().root - seam.sections.back().root).norm();
  auto moved = [&](double c) {
    std::size_t best = 0;
    for (std::size_t k = 0; k < old_s.size(); ++k) {
      if (std::abs(old_s[k] - c) < std::abs(old_s[best] - c)) best = k;
    }
    return new_s[best];
  };
  for (double& c : seam.curve.corners) c = moved(c);
  for (SeamCandidate::Tack& t : seam.tacks) t.position = moved(t.position);
  seam.curve.length = s;
  seam.curve.closed = closed;
}

namespace {

// A tack's hump tapers to its ends, and only its middle reads `filled` (shallower than 0.6
// times the seam's depth): the runs came out 3-5 mm short of the renderer's 8-15 mm tacks
// (60-75 %). Each run is widened over the neighbouring stations that read shallower than
// kFlankShare of the seam's median depth, halfway between `filled` and the open groove (a
// straight seam's stations scatter by 1-6 % of its depth): one to three per end. On the
// sweep's tack scans and a 1280x720 one the mean length error went from -3.1..-4.0 mm to
// -1.0..-0.1 mm (0.75: -1.9..-0.1; 0.85: -1.0..+1.6).
constexpr double kFlankShare = 0.8;

// Whether station `s` reads as a tack's flank: shallower than kFlankShare of `depth` (m),
// its own fit passed or not (a flank's V often fails).
bool on_flank(const GrooveSection& s, double depth) {
  return std::isfinite(s.depth) && s.depth > 0 && s.depth < kFlankShare * depth;
}

// The tack welds along a seam: runs of at least three `filled` stations of `raw` (one station
// that is neither filled nor ok may sit inside a run), widened over their flanks, each as its
// centre's arc length and its length (m, one `station` more than its first to last station).
std::vector<SeamCandidate::Tack> find_tacks(const std::vector<GrooveSection>& raw, double station) {
  std::vector<double> depths;
  for (const auto& s : raw) {
    if (s.ok && !s.filled) depths.push_back(s.depth);
  }
  const double depth = depths.empty() ? NAN : upper_median(depths);
  std::vector<SeamCandidate::Tack> tacks;
  std::size_t k = 0;
  while (k < raw.size()) {
    if (!raw[k].filled) {
      ++k;
      continue;
    }
    std::size_t first = k, last = k, count = 1;
    for (std::size_t j = k + 1; j < raw.size(); ++j) {
      if (raw[j].filled) {
        last = j;
        ++count;
      } else if (raw[j].ok || j > last + 1) {
        break;
      }
    }
    if (count >= 3) {
      while (first > 0 && !raw[first - 1].filled && on_flank(raw[first - 1], depth)) --first;
      while (last + 1 < raw.size() && !raw[last + 1].filled && on_flank(raw[last + 1], depth))
        ++last;
      const double from = raw[first].s, to = raw[last].s;
      tacks.push_back({0.5 * (from + to), to - from + station});
    }
    k = last + 1;
  }
  return tacks;
}

}  // namespace

SeamCandidate trace_seam(const Context& ctx, std::vector<Eigen::Vector3d> ordered,
                         std::vector<Eigen::Vector3d> normals, bool closed, bool corner) {
  SeamCandidate seam;
  seam.corner = corner;
  const VFit::Kind kind = corner ? VFit::Kind::corner : VFit::Kind::groove;
  const RobustParams& p = ctx.params;
  // A symmetric seam (the first pass's walls dip alike, within kSymmetricDeg) is fitted with
  // symmetric V's the second time: at a slant one wall is seen at a grazing angle, a pixel's
  // footprint on it stretches to 2-4 mm, and its slope from the two or three image rows it
  // gets (one of them blurred into the root by stereo matching) comes out several degrees too
  // flat, which moves its rim out and the root towards the other wall by up to a millimetre.
  // Plates set high-low are fitted with a step between the two tops the second time (VFit).
  VFit mode;
  mode.kind = kind;
  double first_step = 0;  // the step the first pass read along the whole seam (m)
  for (int pass = 0; pass < 2; ++pass) {
    // Sampled finely, then at stations anchored to the frame (robust/stations.hpp).
    const SeamCurve curve = anchored_stations(
        smooth_curve(ordered, closed, p.smooth, 0.25 * p.station, normals), p.station);
    if (curve.points.size() < 2) break;
    // A curved surface is taken in the second pass only: the first pass's sections decide
    // how far tracking follows the seam (extend_ends), and there they stay as they were (a
    // cylinder's seam, its flank's sections tilted otherwise, was tracked 8 mm less).
    // The turn over +-3 smoothing windows: the curve is smoothed over as much (curve.cpp).
    const bool curved = pass == 1 && bends_out_of_surface(curve, ordered, normals, 3 * p.smooth);
    std::vector<GrooveSection> raw = fit_stations(ctx, curve, ordered, normals, mode, curved);
    reject_inconsistent(raw);
    if (pass == 0) {
      mode = seam_fit_mode(raw);
      mode.kind = kind;
      first_step = seam_step(raw);
    }
    // Plates set high-low: a step that both passes' stations read along the whole seam is held
    // at every station, and the second pass fitted again so.
    if (pass == 1 && first_step != 0.0) {
      const double step = step_read_again(first_step, raw);
      first_step = 0;
      if (step != 0.0) {
        mode.stepped = true;
        mode.step = step;
        mode.symmetric = false;
        mode.square = 0;
        --pass;
        continue;
      }
    }
    seam.gap = open_root_gap(raw);
    anchor_one_wall_roots(raw);
    align_bisectors(raw, mode);
    std::vector<GrooveSection> smooth = smooth_sections(raw, curve, p.smooth);
    if (pass == 0 && !closed) {
      VFit ahead;  // the tracking fits as the first pass did: its own kind only
      ahead.kind = kind;
      extend_ends(ctx, smooth, ahead);
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
  seam.tacks = find_tacks(seam.raw, p.station);
  if (seam.sections.size() >= 2) measure_along_roots(seam, closed);
  seam.closed = closed;
  return seam;
}

}  // namespace groovetrace::robust_detail
