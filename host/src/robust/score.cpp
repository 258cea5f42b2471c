// Stage 4a of the robust method: is a traced seam a V-groove, and how good a one?
//
// Concave candidates also arise where a part meets the table, at a stereo shadow's rim or on
// a dent; node validation already demands a V in each section, and the seam as a whole must
// then be long, mostly made of good V fits, and the same groove all along (a real groove's
// width and opening hardly change; a chance chain of V-ish noise varies a lot).

#include <algorithm>
#include <cmath>

#include "core/stats.hpp"
#include "robust/stages.hpp"

namespace groovetrace {
namespace {

// 1.4826 MAD / median: a robust coefficient of variation.
double relative_spread(const std::vector<double>& v) {
  const double med = upper_median(v);
  if (!(med > 0)) return 1.0;
  return mad_sigma(v, med) / med;
}

// A corner seam (no top across it) is a fillet, or a lap where one face, the upper plate's
// edge, ends inside the window and the upper plate's top follows: when a third of its passing
// sections see that top (it holds only a few points of a narrow window). A groove seam is a
// bevel or a V (bevel_square_side).
std::string joint_kind(const SeamCandidate& seam) {
  if (seam.corner) {
    std::size_t passing = 0, short_faces = 0;
    for (const GrooveSection& s : seam.sections) {
      passing += s.ok;
      short_faces += s.ok && s.short_face;
    }
    return 3 * short_faces >= passing && short_faces > 0 ? "lap" : "fillet";
  }
  return bevel_square_side(seam.sections) != 0 ? "bevel" : "V";
}

// Clamps and blocks standing on a part make corners along their feet that no cross-section
// tells from a fillet: a clamp's 30 x 20 mm foot seen on two sides gives 50 mm. A corner joint
// must be longer than that (a limit: shorter fillets are not reported).
constexpr double kMinCornerLength = 0.06;

// |Median high-low| of the two-wall sections (m; signed steps, right minus left: a level
// joint's steps scatter by 1-3 mm this way and that, and the median of their sizes reported
// 1.5-2 mm for it); 0 with none.
double median_misalignment(const std::vector<GrooveSection>& secs) {
  std::vector<double> m;
  for (const GrooveSection& s : secs) {
    if (s.ok && !s.one_wall) m.push_back(s.misalignment);
  }
  return m.empty() ? 0.0 : std::abs(upper_median(m));
}

}  // namespace

// A single bevel has one side square to the top (its dip over 75 deg: a wall measured steep
// or a hidden side whose mirror image would have been seen) and the other at least 20 deg
// flatter; a V's walls dip alike (a D415 at a slant reads up to ~8 deg of difference).
int bevel_square_side(const std::vector<GrooveSection>& sections) {
  std::vector<double> steep, flat;
  int right_steeper = 0;
  for (const GrooveSection& s : sections) {
    if (!s.ok || s.corner) continue;
    steep.push_back(std::max(s.wall_left_deg, s.wall_right_deg));
    flat.push_back(std::min(s.wall_left_deg, s.wall_right_deg));
    right_steeper += s.wall_right_deg > s.wall_left_deg ? 1 : -1;
  }
  if (steep.size() < 3) return 0;
  const double hi = upper_median(steep), lo = upper_median(flat);
  if (!(hi >= 75 && hi - lo >= 20) || right_steeper == 0) return 0;
  return right_steeper > 0 ? 1 : -1;
}

// A V's section may hold a tenth of its opening's points inside its walls away from the root
// (GrooveSection::inside) ...
constexpr double kMaxInside = 0.1;
// ... and a seam this share of such sections; more is a channel with a floor, not a joint. The
// table between a plate's edge and a loose bar beside it, read as a bevel 20 mm deep at the
// 40 mm scale, showed its floor in three of four V sections; no scale of a sweep scan with a
// joint had more than one in seven (the V's own root gap, an L's other leg at its corner).
constexpr double kMaxFloored = 0.5;

void score_seam(SeamCandidate& seam, const RobustParams& params) {
  std::vector<double> width, depth, opening, quality;
  std::size_t floored = 0;
  for (const GrooveSection& s : seam.sections) {
    if (!s.ok) continue;
    floored += s.inside > kMaxInside;
    width.push_back(s.width);
    depth.push_back(s.depth);
    opening.push_back(s.opening_deg);
    quality.push_back(s.depth / (s.depth + 3 * s.rms));
  }
  const std::size_t total = seam.sections.size();
  seam.length = seam.curve.length;
  seam.closed = seam.curve.closed;
  seam.ok_fraction = total > 0 ? static_cast<double>(width.size()) / total : 0.0;
  seam.width = upper_median(width);
  seam.depth = upper_median(depth);
  seam.opening_deg = upper_median(opening);
  seam.fit_quality = quality.empty() ? 0.0 : upper_median(quality);
  seam.consistency =
      width.empty() ? 0.0 : std::max(0.0, 1.0 - relative_spread(width) - relative_spread(opening));
  seam.score = seam.length * 1000.0 * seam.ok_fraction * seam.fit_quality * seam.consistency;
  seam.joint = joint_kind(seam);
  seam.misalignment = median_misalignment(seam.sections);

  // The length is judged last: "shorter than min_length" is a groove in every other respect
  // (accept_continuations).
  seam.accepted = false;
  if (width.size() < 3) {
    seam.reason = "fewer than 3 V-shaped sections";
  } else if (seam.ok_fraction < 0.4) {
    seam.reason = "fewer than 40 % of the sections are V-shaped";
  } else if (seam.consistency < 0.35) {
    seam.reason = "width or opening varies along the seam";
  } else if (seam.opening_deg < 15 || seam.opening_deg > 175) {
    seam.reason = "implausible opening angle";
  } else if (floored > kMaxFloored * width.size()) {
    seam.reason = "a channel with a floor between its walls, not a joint";
  } else if (seam.length < params.min_length) {
    seam.reason = kTooShort;
  } else if (seam.corner && seam.length < kMinCornerLength) {
    seam.reason = "a corner shorter than a fixture's (clamp, block)";
  } else {
    seam.accepted = true;
    seam.reason.clear();
  }
}

}  // namespace groovetrace
