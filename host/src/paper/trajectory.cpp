// The paper's trajectory (section IV): PCA direction, equal-width slices, one geometric
// median per slice, tool axis from the slice's mean normal.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <groovetrace/paper.hpp>
#include <limits>
#include <string>

namespace groovetrace {
namespace {

/// Sign convention of the header: along +x of the cloud's frame, +y if perpendicular to x
/// (and +z if the axis is z itself). The cut-off only has to beat rounding noise.
Eigen::Vector3d signed_direction(Eigen::Vector3d d) {
  constexpr double kPerpendicular = 1e-9;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(d[axis]) > kPerpendicular) return d[axis] < 0.0 ? Eigen::Vector3d(-d) : d;
  }
  return d;
}

}  // namespace

Trajectory paper_trajectory(const Cloud& cloud, const Normals& normals,
                            const std::vector<std::uint8_t>& mask, int slices,
                            int median_max_iterations, double median_tolerance) {
  if (slices < 1)
    throw UsageError("slices must be at least 1 (got " + std::to_string(slices) + ")");
  if (mask.size() != cloud.size() || normals.size() != cloud.size()) {
    throw InternalError("paper_trajectory: cloud (" + std::to_string(cloud.size()) +
                        "), normals (" + std::to_string(normals.size()) + ") and mask (" +
                        std::to_string(mask.size()) + ") differ in size");
  }

  std::vector<std::size_t> groove;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (mask[i] != 0 && cloud.valid(i) && normals.valid(i)) groove.push_back(i);
  }
  if (groove.size() < 2) {
    throw NoGrooveError("too few groove points with normals for a trajectory (" +
                        std::to_string(groove.size()) + ")");
  }

  // Double and centred: float sums over 10^5 points 0.5 m from the origin lose the mm.
  std::vector<Eigen::Vector3d> points(groove.size());
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < groove.size(); ++k) {
    points[k] = cloud.point(groove[k]).cast<double>();
    centroid += points[k];
  }
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - centroid;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(points.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Eigenvalues come ascending: the last column is the first principal axis.
  const Eigen::Vector3d direction = signed_direction(solver.eigenvectors().col(2).normalized());

  std::vector<double> along(points.size());
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < points.size(); ++k) {
    along[k] = direction.dot(points[k] - centroid);
    lo = std::min(lo, along[k]);
    hi = std::max(hi, along[k]);
  }
  const double length = hi - lo;
  const double width = length / slices;

  std::vector<std::vector<Eigen::Vector3d>> slice_points(static_cast<std::size_t>(slices));
  std::vector<Eigen::Vector3d> normal_sums(static_cast<std::size_t>(slices),
                                           Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k < points.size(); ++k) {
    int s = width > 0.0 ? static_cast<int>(std::floor((along[k] - lo) / width)) : 0;
    s = std::clamp(s, 0, slices - 1);  // the point at `hi` belongs to the last slice
    slice_points[static_cast<std::size_t>(s)].push_back(points[k]);
    normal_sums[static_cast<std::size_t>(s)] += normals.normal(groove[k]).cast<double>();
  }

  Trajectory trajectory;
  trajectory.direction = direction;
  trajectory.length = length;
  for (std::size_t s = 0; s < slice_points.size(); ++s) {
    if (slice_points[s].empty()) continue;
    Waypoint w;
    // Waypoint's Eigen members start uninitialized; filled for real below.
    w.rotation_vector.setZero();
    w.euler_zyx_deg.setZero();
    w.position = geometric_median(slice_points[s], median_max_iterations, median_tolerance);
    w.orientation = tool_orientation(normal_sums[s].normalized(), direction);
    w.support = static_cast<int>(slice_points[s].size());
    trajectory.waypoints.push_back(w);
  }
  if (trajectory.waypoints.size() < 2) {
    throw NoGrooveError("groove points span a single slice: no trajectory (length " +
                        std::to_string(length * 1000.0) + " mm)");
  }
  fill_rotation_representations(trajectory);
  return trajectory;
}

}  // namespace groovetrace
