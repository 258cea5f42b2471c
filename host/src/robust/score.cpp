// Stage 4a of the robust method: is a traced seam a V-groove, and how good a one?
//
// Concave candidates also arise where a part meets the table, at a stereo shadow's rim or on
// a dent; node validation already demands a V in each section, and the seam as a whole must
// then be long, mostly made of good V fits, and the same groove all along (a real groove's
// width and opening hardly change; a chance chain of V-ish noise varies a lot).

#include <algorithm>
#include <cmath>

#include "robust/stages.hpp"

namespace groovetrace {
namespace {

double median_of(std::vector<double> v) {
  if (v.empty()) return NAN;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

// 1.4826 MAD / median: a robust coefficient of variation.
double relative_spread(const std::vector<double>& v) {
  const double med = median_of(v);
  if (!(med > 0)) return 1.0;
  std::vector<double> dev(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) dev[k] = std::abs(v[k] - med);
  return 1.4826 * median_of(dev) / med;
}

}  // namespace

void score_seam(SeamCandidate& seam, const RobustParams& params) {
  std::vector<double> width, depth, opening, quality;
  for (const GrooveSection& s : seam.sections) {
    if (!s.ok) continue;
    width.push_back(s.width);
    depth.push_back(s.depth);
    opening.push_back(s.opening_deg);
    quality.push_back(s.depth / (s.depth + 3 * s.rms));
  }
  const std::size_t total = seam.sections.size();
  seam.length = seam.curve.length;
  seam.closed = seam.curve.closed;
  seam.ok_fraction = total > 0 ? static_cast<double>(width.size()) / total : 0.0;
  seam.width = median_of(width);
  seam.depth = median_of(depth);
  seam.opening_deg = median_of(opening);
  seam.fit_quality = quality.empty() ? 0.0 : median_of(quality);
  seam.consistency =
      width.empty() ? 0.0 : std::max(0.0, 1.0 - relative_spread(width) - relative_spread(opening));
  seam.score = seam.length * 1000.0 * seam.ok_fraction * seam.fit_quality * seam.consistency;

  seam.accepted = false;
  if (width.size() < 3) {
    seam.reason = "fewer than 3 V-shaped sections";
  } else if (seam.length < params.min_length) {
    seam.reason = "shorter than min_length";
  } else if (seam.ok_fraction < 0.4) {
    seam.reason = "fewer than 40 % of the sections are V-shaped";
  } else if (seam.consistency < 0.35) {
    seam.reason = "width or opening varies along the seam";
  } else if (seam.opening_deg < 15 || seam.opening_deg > 160) {
    seam.reason = "implausible opening angle";
  } else {
    seam.accepted = true;
    seam.reason.clear();
  }
}

}  // namespace groovetrace
