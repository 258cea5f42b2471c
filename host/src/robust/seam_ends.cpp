// An open seam's ends, past its last fitted section, out to where its groove ends.
//
// Near a part's end a section's ball reaches over the end face and the table below it, and the
// stereo matcher blurs the face into the groove: the fits fail over the last 3-8 mm of a seam
// that runs to a plate's edge, and a 300 mm seam lost 2-3 % of its groove to its ends. The
// groove is still plain there in a simpler test, as in the last fitted section: a slab across
// the seam's line, continued straight, holds points on the section's walls and on the top
// surface beside both rims.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/segment.hpp"
#include "robust/context.hpp"

namespace groovetrace::robust_detail {
namespace {

// A slab's points across an end section's groove: on its two walls (the profile from each
// rim down to the root), and on the top surface beside each rim (out to one opening width).
struct SlabCounts {
  int groove = 0, left = 0, right = 0;
};

// An end section's profile in the plane across the unit `along`: u across (towards its right
// edge), h along its top normal, both from the middle of its opening (m).
struct EndProfile {
  Eigen::Vector3d centre, across, out;
  Eigen::Vector2d left, right, foot;  // the edges and the root (u, h)
  double tolerance = 0;               // the region's (label.cpp): 3 noise, or a tenth of the depth
  double reach = 0;                   // the ball holding the groove and both top bands
};

EndProfile end_profile(const GrooveSection& end, const Eigen::Vector3d& along) {
  EndProfile e;
  e.centre = 0.5 * (end.edge_left + end.edge_right);
  e.out = (end.normal - end.normal.dot(along) * along).normalized();
  e.across = e.out.cross(along);
  if (e.across.dot(end.edge_right - end.edge_left) < 0) e.across = -e.across;
  auto uh = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d((p - e.centre).dot(e.across), (p - e.centre).dot(e.out));
  };
  e.left = uh(end.edge_left);
  e.right = uh(end.edge_right);
  e.foot = uh(end.root);
  e.tolerance = std::max(3 * end.noise, 0.1 * end.depth);
  const double width = e.right.x() - e.left.x();
  e.reach = std::max({2 * width, e.foot.norm()}) + e.tolerance;
  return e;
}

// The counts in the slab `half` (m) thick either side of profile `e` moved by `shift` (m).
SlabCounts count_slab(const Context& ctx, const EndProfile& e, const Eigen::Vector3d& shift,
                      const Eigen::Vector3d& along, double half,
                      std::vector<std::uint32_t>& scratch) {
  const Eigen::Vector3d centre = e.centre + shift;
  const double width = e.right.x() - e.left.x(), tol = e.tolerance;
  ctx.bins.within_slab(ctx.cloud, centre, e.reach, along, half, scratch);
  SlabCounts c;
  for (std::uint32_t j : scratch) {
    const Eigen::Vector3d r = ctx.cloud.point(j).cast<double>() - centre;
    const Eigen::Vector2d q(r.dot(e.across), r.dot(e.out));
    const double top = q.x() < e.foot.x() ? e.left.y() : e.right.y();  // that side's rim height
    // Below the rim and on a wall; the walls' distances only for points below a rim.
    if (q.y() < top - tol && std::min(segment_distance(q, e.left, e.foot),
                                      segment_distance(q, e.foot, e.right)) <= tol) {
      ++c.groove;
    } else if (q.x() < e.left.x() && q.x() >= e.left.x() - width) {
      c.left += std::abs(q.y() - e.left.y()) <= tol;
    } else if (q.x() > e.right.x() && q.x() <= e.right.x() + width) {
      c.right += std::abs(q.y() - e.right.y()) <= tol;
    }
  }
  return c;
}

// Whether `c` holds at least kShare of each of `ref`'s counts: where a plate ends mid-slab,
// half the slab is still on it. The end section's own counts must hold kMinRef points in each
// place, or the test tells nothing (a sparse far scan, a wall seen at a grazing angle).
constexpr double kShare = 0.4;
constexpr int kMinRef = 3;

bool holds(const SlabCounts& c, const SlabCounts& ref) {
  auto enough = [](int n, int r) { return n >= 2 && n >= kShare * r; };
  return enough(c.groove, ref.groove) && enough(c.left, ref.left) && enough(c.right, ref.right);
}

// The mean top normal (unit) of the ok sections within `reach` (m) of arc from the end of
// `secs`; zero without one.
Eigen::Vector3d end_normal(const std::vector<GrooveSection>& secs, double reach) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  double arc = 0;
  for (std::size_t k = secs.size(); k-- > 0 && arc <= reach;) {
    if (secs[k].ok) n += secs[k].normal;
    if (k > 0) arc += (secs[k].root - secs[k - 1].root).norm();
  }
  return n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : n;
}

// Appends to `secs` copies of its last section moved one station at a time along the line
// through its last 15 mm of roots (continue_seam), while the slab test holds, up to one scale.
// The line is laid into the top surface of those same 15 mm (their mean normal): the roots'
// depth noise tilts it, and carried 18 mm on at 640x480 and 0.55 m it ran 3.9 mm deep (2.5
// laid in). Not into the end section's own: one noisy normal turned it off the part (a 60 mm
// joint's coverage 96 -> 92 %). `sign`: +1 where arc length grows towards this end, -1 at the
// seam's first end. An end whose V was not measured (`inferred`) is not carried on.
void extend_back_to_end(const Context& ctx, std::vector<GrooveSection>& secs, double sign) {
  const double station = ctx.params.station, half = ctx.params.slab;
  Eigen::Vector3d at, tangent;  // `at`: where the line passes the end (unused)
  if (secs.empty() || secs.back().inferred || !continue_seam(ctx, secs, 0, at, tangent)) return;
  const GrooveSection end = secs.back();
  const Eigen::Vector3d n = end_normal(secs, 1.5 * ctx.params.scale);
  tangent = (tangent - tangent.dot(n) * n).normalized();
  const EndProfile e = end_profile(end, tangent);
  if (!(e.right.x() > e.left.x()) || !e.out.allFinite()) return;
  std::vector<std::uint32_t> scratch;
  const SlabCounts ref = count_slab(ctx, e, Eigen::Vector3d::Zero(), tangent, half, scratch);
  if (std::min({ref.groove, ref.left, ref.right}) < kMinRef) return;
  const int steps = static_cast<int>(ctx.params.scale / station);
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Vector3d shift = k * station * tangent;
    if (!holds(count_slab(ctx, e, shift, tangent, half, scratch), ref)) break;
    GrooveSection s = end;
    s.ok = s.inferred = s.filled = false;
    s.extended = true;
    s.why = "past the last fit: the groove continues in a slab across the seam";
    s.s += sign * k * station;
    s.root += shift;
    s.edge_left += shift;
    s.edge_right += shift;
    secs.push_back(s);
  }
}

}  // namespace

void extend_to_groove_ends(const Context& ctx, SeamCandidate& seam) {
  if (seam.closed || seam.corner) return;
  auto& secs = seam.sections;
  const std::size_t before = secs.size();
  extend_back_to_end(ctx, secs, +1);
  std::reverse(secs.begin(), secs.end());
  extend_back_to_end(ctx, secs, -1);
  std::reverse(secs.begin(), secs.end());
  // The sections' arc lengths; the seam's scored length (seam.length) stays what it was.
  if (secs.size() > before) measure_along_roots(seam, false);
}

}  // namespace groovetrace::robust_detail
