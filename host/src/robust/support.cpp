// The plane the workpiece stands on, and the corners that lie on it.
//
// A part standing on the table makes a concave corner with it all round its foot, and a plate
// lying on the table is, in geometry, a lap joint: no cross-section tells them from a fillet or
// lap weld. What does is the table: a large plane with nothing seen behind it (the one holding
// the most voxels, if several), and the corners along it are the parts' feet, not joints.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "robust/context.hpp"

namespace groovetrace::robust_detail {
namespace {

// A plane is large when this share of the map's voxels lies within kPlaneTolerance of it.
constexpr double kLargeShare = 0.15;
constexpr double kPlaneTolerance = 0.002;  // m
constexpr double kBehindShare = 0.02;
// Planes tried: through this many voxels spread evenly over the map, each with its normal.
constexpr std::size_t kTries = 256;

// The plane fitted (principal axes) to the voxels within kPlaneTolerance of `plane`, twice: a
// plane through one voxel takes that voxel's normal, a degree or two off the table's, which
// puts it millimetres off the table 100 mm away; the table's own points put it back.
SupportPlane refit(const CreaseMap& map, SupportPlane plane) {
  for (int round = 0; round < 2; ++round) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    std::size_t n = 0;
    for (const Eigen::Vector3f& qf : map.points) {
      const Eigen::Vector3d q = qf.cast<double>();
      if (std::abs(plane.normal.dot(q - plane.point)) > kPlaneTolerance) continue;
      mean += q;
      cov += q * q.transpose();
      ++n;
    }
    if (n < 3) return plane;
    mean /= static_cast<double>(n);
    cov = cov / static_cast<double>(n) - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    Eigen::Vector3d normal = eig.eigenvectors().col(0);
    if (normal.dot(plane.normal) < 0) normal = -normal;
    plane = SupportPlane{mean, normal};
  }
  return plane;
}

// How many of the map's voxels `plane` holds within kPlaneTolerance when it can be the table:
// that is at least kLargeShare of them, with at most kBehindShare behind it (nothing is seen
// through a table; a plate's top above it has the table behind). 0 when it cannot.
std::size_t table_support(const CreaseMap& map, const SupportPlane& plane) {
  std::size_t on = 0, behind = 0;
  for (const Eigen::Vector3f& q : map.points) {
    const double h = plane.normal.dot(q.cast<double>() - plane.point);
    on += std::abs(h) <= kPlaneTolerance;
    behind += h < -3 * kPlaneTolerance;
  }
  const auto n = static_cast<double>(map.points.size());
  const bool table =
      static_cast<double>(on) >= kLargeShare * n && static_cast<double>(behind) <= kBehindShare * n;
  return table ? on : 0;
}

}  // namespace

std::optional<SupportPlane> support_plane(const CreaseMap& map) {
  const std::size_t n = map.points.size();
  std::optional<SupportPlane> best;
  std::size_t best_support = 0;
  const std::size_t stride = std::max<std::size_t>(1, n / kTries);
  for (std::size_t k = 0; k < n; k += stride) {
    SupportPlane plane{map.points[k].cast<double>(), map.normals[k].cast<double>()};
    if (!plane.point.allFinite() || !(plane.normal.norm() > 0.5)) continue;
    // A voxel on the best plane so far would refit to it again (most of a table's voxels).
    if (best && std::abs(best->normal.dot(plane.point - best->point)) <= kPlaneTolerance) continue;
    if (table_support(map, plane) == 0) continue;
    plane = refit(map, plane);
    const std::size_t support = table_support(map, plane);
    if (support > best_support) {
      best_support = support;
      best = plane;
    }
  }
  return best;
}

void reject_corners_on_table(const CreaseMap& map, std::vector<SeamCandidate>& seams) {
  const bool any = std::any_of(seams.begin(), seams.end(),
                               [](const SeamCandidate& s) { return s.accepted && s.corner; });
  if (!any) return;  // the table is looked for only when a corner needs it
  const std::optional<SupportPlane> table = support_plane(map);
  if (table) reject_corners_on(*table, seams);
}

void reject_corners_on(const SupportPlane& plane, std::vector<SeamCandidate>& seams) {
  for (SeamCandidate& seam : seams) {
    if (!seam.accepted || !seam.corner) continue;
    std::size_t on = 0, ok = 0;
    for (const GrooveSection& s : seam.sections) {
      if (!s.ok) continue;
      ++ok;
      on += std::abs(plane.normal.dot(s.root - plane.point)) <= kFootHeight;
    }
    if (2 * on > ok) {
      seam.accepted = false;
      seam.reason =
          "a corner along the table (a large plane with nothing behind it): a part's foot";
    }
  }
}

}  // namespace groovetrace::robust_detail
