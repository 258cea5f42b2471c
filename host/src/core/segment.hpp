#pragma once
// The distance from a point to a line segment in a plane (an image's pixels, a cross-section's
// metres): the one formula the picture and the robust method's seam ends share.

#include <Eigen/Core>
#include <algorithm>

namespace groovetrace {

/// Distance from p to the segment a-b, in the units of the points; to a when a == b.
inline double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                               const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

}  // namespace groovetrace
