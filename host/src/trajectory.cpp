// The paper's trajectory (section IV): PCA direction, equal-width slices, one geometric
// median per slice, tool axis from the slice's mean normal.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <groovetrace/rotation.hpp>
#include <groovetrace/trajectory.hpp>
#include <limits>
#include <string>

namespace groovetrace {

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

/// Yaw, pitch, roll (deg) with R = Rz(yaw) Ry(pitch) Rx(roll); pitch in [-90, 90].
Eigen::Vector3d euler_zyx_deg(const Eigen::Matrix3d& R) {
  // Row 2 of Rz Ry Rx is (-sin p, cos p sin r, cos p cos r); column 0 is
  // (cos y cos p, sin y cos p, -sin p).
  const double cos_pitch = std::hypot(R(0, 0), R(1, 0));
  const double pitch = std::atan2(-R(2, 0), cos_pitch);  // cos_pitch >= 0: in [-90, 90]
  double yaw = 0.0;
  double roll = 0.0;
  if (cos_pitch > 1e-9) {
    yaw = std::atan2(R(1, 0), R(0, 0));
    roll = std::atan2(R(2, 1), R(2, 2));
  } else {
    // Gimbal lock: only yaw -/+ roll is defined. Put it all in yaw (roll = 0), where
    // R(0,1) = -sin(yaw) and R(1,1) = cos(yaw).
    yaw = std::atan2(-R(0, 1), R(1, 1));
  }
  return {yaw * kRadToDeg, pitch * kRadToDeg, roll * kRadToDeg};
}

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

Eigen::Quaterniond tool_orientation(const Eigen::Vector3d& normal, const Eigen::Vector3d& travel) {
  Eigen::Vector3d z = -normal;
  const double zn = z.norm();
  // A slice whose normals cancel has no surface direction; look along the frame's +z (the
  // camera's viewing axis) rather than produce NaN poses.
  z = (std::isfinite(zn) && zn > 1e-12) ? Eigen::Vector3d(z / zn) : Eigen::Vector3d::UnitZ();
  Eigen::Vector3d x = travel - travel.dot(z) * z;
  const double xn = x.norm();
  x = (std::isfinite(xn) && xn > 1e-9 * std::max(1.0, travel.norm()))
          ? Eigen::Vector3d(x / xn)
          : Eigen::Vector3d(z.unitOrthogonal());
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = z;
  return Eigen::Quaterniond(R).normalized();
}

void fill_rotation_representations(Trajectory& trajectory) {
  bool first = true;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (auto& w : trajectory.waypoints) {
    w.orientation.normalize();
    w.rotation_vector =
        first ? rotation_vector(w.orientation) : rotation_vector_near(w.orientation, previous);
    previous = w.rotation_vector;
    first = false;
    w.euler_zyx_deg = euler_zyx_deg(w.orientation.toRotationMatrix());
  }
}

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
