// Stage 4b of the robust method: the groove region from the fitted openings.
//
// A pixel sees the groove exactly when its viewing ray enters the V between the two top
// edges; that is also how synthetic truth is labelled, and it holds for points the sensor
// misplaced along their ray (noise, flying pixels, blur), which a test on the measured
// position would get wrong at the rims. So each point's ray from the viewpoint is intersected
// with the opening (the plane through the two fitted top edges of the nearest section) and
// the point is groove when the crossing lies between the edges and the point is not in front
// of the opening.

#include <algorithm>
#include <cmath>

#include "core/neighbor_grid.hpp"
#include "robust/stages.hpp"

namespace groovetrace {
namespace {

constexpr double kMaxFan = 3 * M_PI / 180;  // rad: see opening_of

struct Opening {
  Eigen::Vector3d centre, across, along, out;  // out: opening plane normal, towards the sensor
  double half_width, tolerance, reach;         // m
  double end_reach;  // m: how far past an open end's centre a point itself may lie
  bool disc;         // at a corner: a disc of half_width, not a slice
  int end;           // +1 / -1: the seam's open end lies along +along / -along; 0: inside
};

// The larger spacing (m) from section k to its neighbours along the seam (wrapping on rings),
// between their roots or between their openings' centres, whichever is wider. Where the seam
// bends out of its surface (a girth seam) the openings lie further out than the roots: on a
// 60 mm pipe a 10 mm V's rims are 1.4 times as far apart along the seam as its roots, and
// slices as thick as the roots' spacing left whole image rows of the groove unlabelled.
double station_spacing(const SeamCandidate& seam, std::size_t k) {
  const auto& secs = seam.sections;
  const std::size_t n = secs.size();
  const auto apart = [&](std::size_t i, std::size_t j) {
    const Eigen::Vector3d ci = 0.5 * (secs[i].edge_left + secs[i].edge_right);
    const Eigen::Vector3d cj = 0.5 * (secs[j].edge_left + secs[j].edge_right);
    return std::max((secs[i].root - secs[j].root).norm(), (ci - cj).norm());
  };
  double prev = k > 0 ? apart(k, k - 1) : 0;
  double next = k + 1 < n ? apart(k, k + 1) : 0;
  if (seam.closed) {
    if (k == 0) prev = apart(k, n - 1);
    if (k + 1 == n) next = apart(k, 0);
  }
  return std::max(prev, next);
}

// The largest angle (rad) between section k's chord `across` (unit) and its neighbours'
// (wrapping on rings).
double fan_angle(const SeamCandidate& seam, std::size_t k, const Eigen::Vector3d& across) {
  const auto& secs = seam.sections;
  const std::size_t n = secs.size();
  double fan = 0;
  const auto turn = [&](std::size_t j) {
    const Eigen::Vector3d chord = secs[j].edge_right - secs[j].edge_left;
    if (!(chord.norm() > 0)) return;
    fan = std::max(fan, std::acos(std::clamp(chord.normalized().dot(across), -1.0, 1.0)));
  };
  if (k > 0 || seam.closed) turn((k + n - 1) % n);
  if (k + 1 < n || seam.closed) turn((k + 1) % n);
  return fan;
}

// The opening of section k of `seam`; false when its edges coincide.
bool opening_of(const SeamCandidate& seam, std::size_t k, Opening& o) {
  const std::size_t n = seam.sections.size();
  const GrooveSection& s = seam.sections[k];
  o.centre = 0.5 * (s.edge_left + s.edge_right);
  const Eigen::Vector3d chord = s.edge_right - s.edge_left;
  o.half_width = 0.5 * chord.norm();
  if (!(o.half_width > 0)) return false;
  o.across = chord / (2 * o.half_width);
  o.along = (s.tangent - s.tangent.dot(o.across) * o.across).normalized();
  o.out = o.across.cross(o.along);
  if (o.out.dot(s.normal) < 0) o.out = -o.out;
  // Half the spacing to the neighbours, with overlap so that the fan of sections around a
  // bend leaves no gaps; the open ends reach one spacing further (the seam runs to the
  // part's edge).
  // Neighbouring chords that turn by an angle leave a wedge between their slices that
  // grows across the opening: a 100 mm wide joint's rims, read to a millimetre, turn its
  // chords by a degree or two, and 1 deg opens a 0.9 mm gap 50 mm out, wider than the slice.
  // Each slice reaches over its half of that wedge. Chords turned by more than kMaxFan
  // are an outlier's (a fit that caught a rim or a shadow), not a wedge to fill.
  const double spacing = station_spacing(seam, k);
  o.end_reach = 0.6 * spacing;
  const double fan = fan_angle(seam, k, o.across);
  o.reach = o.end_reach + (fan <= kMaxFan ? 0.5 * o.half_width * std::sin(fan) : 0.0);
  o.end = 0;
  if (!seam.closed && n > 1 && (k == 0 || k + 1 == n)) {
    // Does `along` point out of the seam here?
    const Eigen::Vector3d inward =
        k == 0 ? seam.sections[1].root - s.root : seam.sections[n - 2].root - s.root;
    o.end = inward.dot(o.along) < 0 ? 1 : -1;
  }
  o.tolerance = std::max(3 * s.noise, 0.1 * s.depth);
  o.disc = false;
  for (double c : seam.curve.corners) {
    if (std::abs(s.s - c) <= spacing) o.disc = true;
  }
  return true;
}

// The openings of the accepted seams' sections. `radius`: how far (m) from its opening's
// centre a groove point can lie - half a width across, a depth below and a reach along.
std::vector<Opening> openings_of(const std::vector<SeamCandidate>& seams, double& radius) {
  std::vector<Opening> openings;
  radius = 0;
  for (const SeamCandidate& seam : seams) {
    if (!seam.accepted) continue;
    for (std::size_t k = 0; k < seam.sections.size(); ++k) {
      Opening o;
      if (!opening_of(seam, k, o)) continue;
      const GrooveSection& s = seam.sections[k];
      radius = std::max(radius, o.half_width + s.depth + o.reach + o.tolerance);
      openings.push_back(o);
    }
  }
  return openings;
}

// Whether point p, seen along the unit `ray` from the viewpoint, lies in the groove behind
// opening o: its ray crosses the opening and it is not in front of it.
bool behind(const Opening& o, const Eigen::Vector3d& p, const Eigen::Vector3d& ray) {
  const double height = (p - o.centre).dot(o.out);
  if (height > o.tolerance) return false;  // in front of the opening: a top surface or beyond
  const double dn = ray.dot(o.out);
  if (std::abs(dn) < 1e-6) return false;
  const Eigen::Vector3d q = p + ((o.centre - p).dot(o.out) / dn) * ray;
  const Eigen::Vector3d r = q - o.centre;
  if (o.disc) return (r - r.dot(o.out) * o.out).norm() <= o.half_width;
  if (std::abs(r.dot(o.along)) > o.reach) return false;
  // Past an open end (a plate's edge) the ray may pass the opening's plane and meet the
  // table beyond the part: the point itself must lie within the seam's end too.
  if (o.end != 0 && o.end * (p - o.centre).dot(o.along) > o.end_reach) return false;
  return std::abs(r.dot(o.across)) <= o.half_width;
}

}  // namespace

std::vector<std::uint8_t> label_grooves(const Cloud& cloud,
                                        const std::vector<SeamCandidate>& seams) {
  std::vector<std::uint8_t> label(cloud.size(), 0);
  double radius = 0;
  const std::vector<Opening> openings = openings_of(seams, radius);
  if (openings.empty()) return label;
  Cloud centres;
  centres.resize(openings.size());
  centres.width = static_cast<std::uint32_t>(openings.size());
  for (std::size_t k = 0; k < openings.size(); ++k) {
    centres.x[k] = static_cast<float>(openings[k].centre.x());
    centres.y[k] = static_cast<float>(openings[k].centre.y());
    centres.z[k] = static_cast<float>(openings[k].centre.z());
  }
  radius *= 1.05;
  const NeighborGrid grid(centres, static_cast<float>(radius));
  const Eigen::Vector3d eye = cloud.viewpoint.cast<double>();
  const std::int64_t count = static_cast<std::int64_t>(cloud.size());
#pragma omp parallel for schedule(dynamic, 4096)
  for (std::int64_t i = 0; i < count; ++i) {
    if (!cloud.valid(i)) continue;
    const Eigen::Vector3d p = cloud.point(i).cast<double>();
    const Eigen::Vector3d ray = (p - eye).normalized();
    bool inside = false;
    grid.for_each_within(cloud.point(i), static_cast<float>(radius), [&](std::uint32_t k, float) {
      if (!inside) inside = behind(openings[k], p, ray);
    });
    label[i] = inside ? 1 : 0;
  }
  return label;
}

}  // namespace groovetrace
