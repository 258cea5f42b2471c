// Seams traced from separate node paths joined where they are one seam.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/stats.hpp"
#include "robust/context.hpp"

namespace groovetrace::robust_detail {
namespace {

// Outward unit direction of an open seam at its end `which` (0 first, 1 last): the main axis
// of the roots within `run` (m) of it, pointing from their centroid to the end. Not the chord to
// the root 10 mm in: at 640x480 and 0.55 m single roots scatter by 1-2 mm, which turned that
// chord 33 deg off a straight seam and kept two stretches of one groove apart at a clamp.
Eigen::Vector3d end_direction(const SeamCandidate& s, int which, double run = 0.02) {
  const auto& secs = s.sections;
  const Eigen::Vector3d end = which == 0 ? secs.front().root : secs.back().root;
  std::vector<Eigen::Vector3d> near;
  for (std::size_t q = 0; q < secs.size(); ++q) {
    const auto& r = secs[which == 0 ? q : secs.size() - 1 - q].root;
    if ((r - end).norm() > run) break;
    near.push_back(r);
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& r : near) mean += r / static_cast<double>(near.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& r : near) cov += (r - mean) * (r - mean).transpose();
  const Eigen::Vector3d out = end - mean;
  if (near.size() < 2 || !(out.norm() > 1e-6)) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d axis =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(2);
  return axis.dot(out) >= 0 ? axis : Eigen::Vector3d(-axis);
}

}  // namespace

// A groove stretch too short to stand alone (under min_length) continues an accepted groove
// seam beyond something standing on the groove: a clamp across it hides 30-50 mm, and the
// 12-19 mm beyond it, up to the plate's edge, were dropped (the sweep's clamps-bar s360). It
// is taken where it lies beyond one of the seam's open ends, within kReachPerScale search
// scales, every root within kOffLine of the seam's line there (across and in depth), its width and
// depth within kLike of the seam's. It stays a seam of its own: the path does not run through the
// clamp.
constexpr double kReachPerScale = 10.0;
constexpr double kOffLine = 0.002;
constexpr double kLike = 0.3;
// The seam's line at an end: its main axis over this much of it (m), longer than a join's
// (end_direction): extrapolated 50-60 mm past a clamp, the axis over 20 mm was 2-4 mm off.
constexpr double kEndRun = 0.05;

namespace {

// Whether every root of `c` lies beyond end `which` of `seam` (0 first, 1 last), in its line
// and within `reach` (m).
bool lies_beyond(const SeamCandidate& c, const SeamCandidate& seam, int which, double reach) {
  const Eigen::Vector3d out = end_direction(seam, which, kEndRun);
  if (out.isZero()) return false;
  const Eigen::Vector3d end = which == 0 ? seam.sections.front().root : seam.sections.back().root;
  for (const GrooveSection& s : c.sections) {
    const Eigen::Vector3d d = s.root - end;
    const double along = d.dot(out);
    if (!(along > 0 && along <= reach) || (d - along * out).norm() > kOffLine) return false;
  }
  return true;
}

bool alike(double a, double b) { return std::abs(a - b) <= kLike * b; }

}  // namespace

void accept_continuations(std::vector<SeamCandidate>& seams, double scale) {
  // Only seams accepted on their own carry a continuation on: no chains of short stretches.
  std::vector<bool> parent;
  for (const SeamCandidate& s : seams) parent.push_back(s.accepted);
  for (SeamCandidate& c : seams) {
    if (c.reason != kTooShort || c.corner || c.sections.empty()) continue;
    for (std::size_t k = 0; k < seams.size(); ++k) {
      const SeamCandidate& seam = seams[k];
      if (!parent[k] || seam.corner || seam.closed || seam.sections.size() < 2 ||
          !alike(c.width, seam.width) || !alike(c.depth, seam.depth))
        continue;
      if (lies_beyond(c, seam, 0, kReachPerScale * scale) ||
          lies_beyond(c, seam, 1, kReachPerScale * scale)) {
        c.accepted = true;
        c.reason.clear();
        c.continues = static_cast<int>(k);  // its index here; detect.cpp numbers them all
        break;
      }
    }
  }
}

double collinear_gap(const SeamCandidate& a, const SeamCandidate& b) {
  if (a.closed || b.closed || a.sections.size() < 2 || b.sections.size() < 2) return INFINITY;
  // Each end's direction once (a fit over its last 20 mm), not once per pair of ends.
  const Eigen::Vector3d dir_a[2] = {end_direction(a, 0), end_direction(a, 1)};
  const Eigen::Vector3d dir_b[2] = {end_direction(b, 0), end_direction(b, 1)};
  double best = INFINITY;
  for (int ea = 0; ea < 2; ++ea) {
    for (int eb = 0; eb < 2; ++eb) {
      const Eigen::Vector3d pa = ea == 0 ? a.sections.front().root : a.sections.back().root;
      const Eigen::Vector3d pb = eb == 0 ? b.sections.front().root : b.sections.back().root;
      const Eigen::Vector3d gap = pb - pa;
      const double len = gap.norm();
      if (!(len > 0)) return 0.0;
      const double cos30 = 0.866;
      if (dir_a[ea].dot(gap / len) > cos30 && dir_b[eb].dot(-gap / len) > cos30) {
        best = std::min(best, len);
      }
    }
  }
  return best;
}

namespace {

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

// The indices of b's sections away from a (none of a's roots within half a `link`, m), when
// they are one run of at least two; empty otherwise.
std::vector<std::size_t> rest_of(const SeamCandidate& a, const SeamCandidate& b, double link) {
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
  if (rest.size() < 2 || rest.back() - rest.front() + 1 != rest.size()) return {};
  return rest;
}

// The facing pair of ends, a's `end_a` and the run's `end_b` (0 first, 1 last), and the
// distance between them (m).
double facing_ends(const SeamCandidate& a, const SeamCandidate& b,
                   const std::vector<std::size_t>& rest, int& end_a, int& end_b) {
  double best = INFINITY;
  for (int ea = 0; ea < 2; ++ea) {
    for (int eb = 0; eb < 2; ++eb) {
      const Eigen::Vector3d pa = ea == 0 ? a.sections.front().root : a.sections.back().root;
      const Eigen::Vector3d pb =
          (eb == 0 ? b.sections[rest.front()] : b.sections[rest.back()]).root;
      const double d = (pa - pb).norm();
      if (d < best) {
        best = d;
        end_a = ea;
        end_b = eb;
      }
    }
  }
  return best;
}

// a and b's run joined end to end at the facing ends, as roots (m) and top normals.
void joined_nodes(const SeamCandidate& a, const SeamCandidate& b,
                  const std::vector<std::size_t>& rest, int end_a, int end_b,
                  std::vector<Eigen::Vector3d>& ordered, std::vector<Eigen::Vector3d>& normals) {
  for (std::size_t q = 0; q < a.sections.size(); ++q) {
    const auto& s = a.sections[end_a == 1 ? q : a.sections.size() - 1 - q];
    ordered.push_back(s.root);
    normals.push_back(s.normal);
  }
  for (std::size_t q = 0; q < rest.size(); ++q) {
    const auto& s = b.sections[end_b == 0 ? rest[q] : rest[rest.size() - 1 - q]];
    ordered.push_back(s.root);
    normals.push_back(s.normal);
  }
}

// The longest gap (m) one seam may continue another across: 3 links (m), never less than at
// the 10 mm scale. What breaks a seam - a D415's noise and undulation, a stretch seen at a
// grazing angle - is no shorter along a small groove: a 4 mm V at 0.55 m (1280x720, tilted
// 30 deg) was read at 5 mm in two stretches 32 mm apart, the longer 65 % of the seam.
double bridge(double link) { return std::max(3 * link, 0.045); }

// a and b traced again as one seam (`joined`) when they are stretches of one: b's run away
// from a touches an end of a (within `link`, m) or, untrimmed, continues it across a gap of up
// to bridge(link) as the same groove. False otherwise or when the joined trace fails.
bool join_seams(const Context& ctx, const SeamCandidate& a, const SeamCandidate& b, double link,
                SeamCandidate& joined) {
  if (a.sections.size() < 2 || b.sections.size() < 2) return false;
  const std::vector<std::size_t> rest = rest_of(a, b, link);
  if (rest.empty()) return false;
  const bool trimmed = rest.size() < b.sections.size();
  int end_a = 0, end_b = 0;
  bool join = facing_ends(a, b, rest, end_a, end_b) <= link;
  if (!join && !trimmed) join = collinear_gap(a, b) <= bridge(link) && same_groove(a, b);
  if (!join) return false;
  std::vector<Eigen::Vector3d> ordered, normals;
  joined_nodes(a, b, rest, end_a, end_b, ordered, normals);
  joined = trace_seam(ctx, ordered, normals, false, a.corner);
  return joined.sections.size() >= 2;
}

}  // namespace

// Seams traced from separate node paths can be one: the tracking of one runs into the other,
// or both stop short of a corner or of a noisy stretch. The second seam's sections that
// overlap the first are dropped; when the rest is one run whose end faces an end of the
// first (touching, or continuing it across a gap of up to bridge(link)), the two are joined end
// to end and traced again. Joining end to end, rather than re-ordering both sets of roots,
// cannot fold the path back over itself.
void merge_seams(const Context& ctx, std::vector<SeamCandidate>& seams, double link) {
  for (int round = 0; round < 8; ++round) {
    bool merged = false;
    for (std::size_t i = 0; i < seams.size() && !merged; ++i) {
      for (std::size_t j = 0; j < seams.size() && !merged; ++j) {
        if (i == j || seams[i].closed || seams[j].closed) continue;
        SeamCandidate joined;
        if (!join_seams(ctx, seams[i], seams[j], link, joined)) continue;
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

namespace {

// Share of `seam`'s root line within `reach` (m) of `kept`'s (brute force: a few hundred points
// each).
double share_near(const SeamCandidate& seam, const SeamCandidate& kept, double reach) {
  const auto& pts = seam.curve.points;
  if (pts.empty()) return 0.0;
  std::size_t near = 0;
  for (const Eigen::Vector3d& p : pts) {
    for (const Eigen::Vector3d& q : kept.curve.points) {
      if ((p - q).squaredNorm() <= reach * reach) {
        ++near;
        break;
      }
    }
  }
  return static_cast<double>(near) / pts.size();
}

// Whether `fine` reads only the bottom of the groove `coarse` reads: found at a finer scale,
// at most half as wide, lower scored, and running mostly along the middle of its opening. Its
// top was fitted on the wider groove's walls (a 100 mm 150 deg panel joint read at 20 mm as a
// 31 mm V, longer there than the 40 mm reading's half, pushed that reading out as a repeat).
bool bottom_of(const SeamCandidate& fine, const SeamCandidate& coarse) {
  return coarse.accepted && coarse.scale > fine.scale && 2 * fine.width <= coarse.width &&
         fine.score < coarse.score && share_near(fine, coarse, 0.25 * coarse.width) >= 0.5;
}

// Within this of a seam (m, at least; else half its width) another runs in its groove.
constexpr double kMinReach = 0.003;

// Whether `longer`, a repeat of the kept seam `kept` read at another scale, reads the same
// groove further: accepted, fitting its scale, half as long again and running along all of
// `kept` (80 %). A 6 mm V at 640x480 and 0.45 m was read whole (300 mm) at 10 mm but only
// over 150 mm at 5 mm, and the finer reading, ranked first, pushed the whole one out.
bool reads_further(const SeamCandidate& longer, const SeamCandidate& kept,
                   bool (*fits_scale)(const SeamCandidate&)) {
  return longer.accepted && kept.accepted && fits_scale(longer) &&
         longer.length >= 1.5 * kept.length &&
         share_near(kept, longer, std::max(kMinReach, 0.5 * longer.width)) >= 0.8;
}

}  // namespace

std::vector<SeamCandidate> drop_duplicate_scales(std::vector<SeamCandidate> ranked,
                                                 bool (*fits_scale)(const SeamCandidate&)) {
  std::vector<bool> part(ranked.size(), false);
  for (std::size_t i = 0; i < ranked.size(); ++i) {
    for (const SeamCandidate& other : ranked) part[i] = part[i] || bottom_of(ranked[i], other);
  }
  std::vector<SeamCandidate> kept;
  for (std::size_t i = 0; i < ranked.size(); ++i) {
    bool repeats = part[i];
    for (SeamCandidate& k : kept) {
      const double reach = std::max(kMinReach, 0.5 * k.width);
      if (repeats || share_near(ranked[i], k, reach) < 0.5) continue;
      repeats = true;
      if (reads_further(ranked[i], k, fits_scale)) k = ranked[i];
    }
    if (!repeats) kept.push_back(std::move(ranked[i]));
  }
  return kept;
}

}  // namespace groovetrace::robust_detail
