// An open seam's ends, past its last fitted section, out to where its groove ends.
//
// Near a part's end a section's ball reaches over the end face and the table below it, and the
// stereo matcher blurs the face into the groove: the fits fail over the last 3-8 mm of a seam
// that runs to a plate's edge, and a 300 mm seam lost 2-3 % of its groove to its ends. The
// groove is still plain there in a simpler test, as in the last fitted section: a thin slab
// across the seam's line, continued straight, holds points below the opening (the groove) and
// the top surface at the opening's height on both sides of it.

#include <algorithm>
#include <cmath>
#include <vector>

#include "robust/context.hpp"

namespace groovetrace::robust_detail {
namespace {

// A thin slab's points across an opening: on the section's two walls (the profile from each
// rim down to the root), and on the top surface beside each rim (out to one width).
struct SlabCounts {
  int groove = 0, left = 0, right = 0;
};

// Distance (m) from p to the segment from a to b, in the plane of a cross-section.
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-18), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

// The counts in the slab `half` (m) thick either side of `end`'s cross-section moved by
// `shift` (m), the slab across the unit `along`.
SlabCounts count_slab(const Context& ctx, const GrooveSection& end, const Eigen::Vector3d& shift,
                      const Eigen::Vector3d& along, double half,
                      std::vector<std::uint32_t>& scratch) {
  const Eigen::Vector3d centre = 0.5 * (end.edge_left + end.edge_right) + shift;
  const Eigen::Vector3d chord = end.edge_right - end.edge_left;
  const double half_width = 0.5 * chord.norm();
  const Eigen::Vector3d across = chord.normalized();
  Eigen::Vector3d out = across.cross(along).normalized();
  if (out.dot(end.normal) < 0) out = -out;
  // In the section's plane: u across from the opening's centre, h out of the part.
  const Eigen::Vector3d root = end.root + shift - centre;
  const Eigen::Vector2d left(-half_width, 0), right(half_width, 0);
  const Eigen::Vector2d foot(root.dot(across), root.dot(out));
  // The label's tolerance (label.cpp): the top surface's noise, or a tenth of the depth.
  const double tolerance = std::max(3 * end.noise, 0.1 * end.depth);
  ctx.bins.within_slab(ctx.cloud, centre, 2.2 * half_width, along, half, scratch);
  SlabCounts c;
  for (std::uint32_t j : scratch) {
    const Eigen::Vector3d r = ctx.cloud.point(j).cast<double>() - centre;
    const Eigen::Vector2d q(r.dot(across), r.dot(out));
    if (std::abs(q.x()) < half_width) {
      const double off =
          std::min(segment_distance(q, left, foot), segment_distance(q, foot, right));
      c.groove += q.y() < -tolerance && off <= tolerance;
    } else if (std::abs(q.y()) <= tolerance && std::abs(q.x()) <= 2 * half_width) {
      (q.x() < 0 ? c.left : c.right) += 1;
    }
  }
  return c;
}

// Whether `c` holds at least kShare of each of `ref`'s counts (and two points each): where a
// plate ends mid-slab half the slab is still on it.
constexpr double kShare = 0.4;

bool holds(const SlabCounts& c, const SlabCounts& ref) {
  auto enough = [](int n, int r) { return n >= 2 && n >= kShare * r; };
  return enough(c.groove, ref.groove) && enough(c.left, ref.left) && enough(c.right, ref.right);
}

// Appends to `secs` copies of its last section moved one station at a time along the line
// through its last roots (continue_seam), while the thin-slab test holds, up to one scale.
// `ds`: +1 where arc length grows towards the end (the seam's last end), -1 at its first.
void extend_back_to_end(const Context& ctx, std::vector<GrooveSection>& secs, double ds) {
  const double station = ctx.params.station;
  Eigen::Vector3d at0, tangent;
  if (secs.empty() || !continue_seam(ctx, secs, 0, at0, tangent)) return;
  const GrooveSection end = secs.back();
  std::vector<std::uint32_t> scratch;
  const SlabCounts ref = count_slab(ctx, end, Eigen::Vector3d::Zero(), tangent, station, scratch);
  const int steps = static_cast<int>(ctx.params.scale / station);
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Vector3d shift = k * station * tangent;
    if (!holds(count_slab(ctx, end, shift, tangent, station, scratch), ref)) break;
    GrooveSection s = end;
    s.ok = s.inferred = s.filled = false;
    s.extended = true;
    s.why = "past the last fit: the groove continues in a thin slab";
    s.s += ds * k * station;
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
  if (secs.size() > before) measure_along_roots(seam, false);
  seam.length = seam.curve.length;
}

}  // namespace groovetrace::robust_detail
