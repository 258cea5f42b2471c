#pragma once
// The published method (`--method paper`, Peng et al.): the descriptor threshold, connected
// groove parts, and the trajectory of slices and geometric medians (paper section IV). Its
// per-point work (MLS, normals, descriptor) runs on a FeatureBackend (features.hpp).
//
// Frames and units: every 3-D quantity is in the cloud's frame, metres; D in deg^2.

#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <groovetrace/export.hpp>
#include <groovetrace/trajectory.hpp>
#include <vector>

namespace groovetrace {

/// Otsu's threshold on log(D) over the finite, positive descriptor values (deg^2).
/// log because D spans orders of magnitude between flats and creases. NaN if < 2 values.
GT_API double otsu_threshold(const std::vector<float>& descriptor);

/// Connected parts of the points with mask[i] != 0: two points are linked when they are
/// within `link_distance` (m) in 3-D. Returns a label per point (-1 outside the mask),
/// labels ordered by decreasing part size, and the size of each part.
struct Components {
  std::vector<int> label;
  std::vector<std::size_t> sizes;
};
GT_API Components connected_components(const Cloud& cloud, const std::vector<std::uint8_t>& mask,
                                       float link_distance);

/// Result of detection: groove mask (1 = groove) and what was decided on the way.
struct Detection {
  std::vector<std::uint8_t> groove;          ///< 1 for points of the kept groove parts
  double threshold = 0.0;                    ///< threshold used (deg^2)
  std::size_t above_threshold = 0;           ///< points with D > threshold before speck removal
  std::size_t components = 0;                ///< parts kept
  std::vector<std::size_t> component_sizes;  ///< sizes of the kept parts, largest first
  std::vector<int> component_label;          ///< per point: kept part index, -1 otherwise
};

/// Thresholds `descriptor` and keeps the connected parts with at least `min_component`
/// points. `threshold` is used unless it is NaN, in which case Otsu's threshold is used.
GT_API Detection detect_groove(const Cloud& cloud, const std::vector<float>& descriptor,
                               double threshold, int min_component, float link_distance);

/// Geometric median (minimum sum of distances) of `points` by Weiszfeld's iteration, which
/// is gradient descent with the step that makes it monotone. Stops when a step moves less
/// than `tolerance` (same unit as the points) or after `max_iterations`.
/// Throws std::invalid_argument for an empty set.
GT_API Eigen::Vector3d geometric_median(const std::vector<Eigen::Vector3d>& points,
                                        int max_iterations = 1000, double tolerance = 1e-7);

/// Builds the paper's trajectory from the groove points (mask != 0 and a valid normal).
/// The direction is the first principal axis of those points, signed so that it points
/// along +x of the cloud's frame (+y if the axis is perpendicular to x); `slices` equal
/// slices along it each give one waypoint (empty slices give none).
/// Throws NoGrooveError if fewer than 2 waypoints result, UsageError for slices < 1.
GT_API Trajectory paper_trajectory(const Cloud& cloud, const Normals& normals,
                                   const std::vector<std::uint8_t>& mask, int slices,
                                   int median_max_iterations = 1000,
                                   double median_tolerance = 1e-7);

}  // namespace groovetrace
