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

struct Opening {
  Eigen::Vector3d centre, across, along, out;  // out: opening plane normal, towards the sensor
  double half_width, tolerance, reach;         // m
  bool disc;                                   // at a corner: a disc of half_width, not a slice
  int end;  // +1 / -1: the seam's open end lies along +along / -along; 0: inside
};

}  // namespace

std::vector<std::uint8_t> label_grooves(const Cloud& cloud,
                                        const std::vector<SeamCandidate>& seams) {
  std::vector<std::uint8_t> label(cloud.size(), 0);
  std::vector<Opening> openings;
  double radius = 0;
  for (const SeamCandidate& seam : seams) {
    if (!seam.accepted) continue;
    const std::size_t n = seam.sections.size();
    for (std::size_t k = 0; k < n; ++k) {
      const GrooveSection& s = seam.sections[k];
      Opening o;
      o.centre = 0.5 * (s.edge_left + s.edge_right);
      const Eigen::Vector3d chord = s.edge_right - s.edge_left;
      o.half_width = 0.5 * chord.norm();
      if (!(o.half_width > 0)) continue;
      o.across = chord / (2 * o.half_width);
      o.along = (s.tangent - s.tangent.dot(o.across) * o.across).normalized();
      o.out = o.across.cross(o.along);
      if (o.out.dot(s.normal) < 0) o.out = -o.out;
      // Half the spacing to the neighbours, with overlap so that the fan of sections around a
      // bend leaves no gaps; the open ends reach one spacing further (the seam runs to the
      // part's edge).
      double prev = k > 0 ? (s.root - seam.sections[k - 1].root).norm() : 0;
      double next = k + 1 < n ? (seam.sections[k + 1].root - s.root).norm() : 0;
      if (seam.closed) {
        if (k == 0) prev = (s.root - seam.sections[n - 1].root).norm();
        if (k + 1 == n) next = (seam.sections[0].root - s.root).norm();
      }
      const double spacing = std::max(prev, next);
      o.reach = 0.6 * spacing;
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
      radius = std::max(radius, o.half_width + s.depth + o.reach + o.tolerance);
      openings.push_back(o);
    }
  }
  if (openings.empty()) return label;
  Cloud centres;
  centres.resize(openings.size());
  centres.width = static_cast<std::uint32_t>(openings.size());
  for (std::size_t k = 0; k < openings.size(); ++k) {
    centres.x[k] = static_cast<float>(openings[k].centre.x());
    centres.y[k] = static_cast<float>(openings[k].centre.y());
    centres.z[k] = static_cast<float>(openings[k].centre.z());
  }
  // A groove point lies at most half a width across, a depth below and a reach along from
  // its section's opening centre.
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
      if (inside) return;
      const Opening& o = openings[k];
      const double height = (p - o.centre).dot(o.out);
      if (height > o.tolerance) return;  // in front of the opening: a top surface or beyond
      const double dn = ray.dot(o.out);
      if (std::abs(dn) < 1e-6) return;
      const Eigen::Vector3d q = p + ((o.centre - p).dot(o.out) / dn) * ray;
      const Eigen::Vector3d r = q - o.centre;
      if (o.disc) {
        inside = (r - r.dot(o.out) * o.out).norm() <= o.half_width;
        return;
      }
      if (std::abs(r.dot(o.along)) > o.reach) return;
      // Past an open end (a plate's edge) the ray may pass the opening's plane and meet the
      // table beyond the part: the point itself must lie within the seam's end too.
      if (o.end != 0 && o.end * (p - o.centre).dot(o.along) > o.reach) return;
      inside = std::abs(r.dot(o.across)) <= o.half_width;
    });
    label[i] = inside ? 1 : 0;
  }
  return label;
}

}  // namespace groovetrace
