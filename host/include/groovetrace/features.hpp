#pragma once
// The per-point work (smoothing, normals, groove descriptor) behind one interface, so the
// OpenCL kernels and the CPU reference are interchangeable and checked against each other.

#include <groovetrace/cloud.hpp>
#include <groovetrace/export.hpp>
#include <memory>
#include <string>
#include <vector>

namespace groovetrace {

/// Moving-least-squares smoothing settings.
struct SmoothParams {
  float radius = 0.003f;  ///< search radius (m); weights are Gaussian with h = radius
  int order = 2;          ///< 1 = project onto the weighted plane, 2 = onto a fitted quadric
  int min_neighbors = 5;  ///< fewer neighbours: the point is kept unchanged
};

/// Normals, benchmark normal and descriptor of one cloud, from one call.
struct FeatureSet {
  Normals normals;                   ///< oriented to the viewpoint (cloud frame)
  Eigen::Vector3f benchmark_normal;  ///< u_b (unit; NaN when no point has a normal)
  std::vector<float> descriptor;     ///< D (deg^2), NaN where undefined
};

/// Settings of the robust method's crease measure (docs/method-robust.md, "Candidates").
struct CreaseParams {
  float radius = 0.010f;      ///< ball of the plane fit and of the envelope (m)
  float own_radius = 0.003f;  ///< ball over which a point's own height is averaged (m)
  float quantile = 0.8f;      ///< the envelope: this quantile of the heights in the ball
  int min_neighbors = 10;     ///< fewer points in the ball (the point included): NaN
};

/// The crease measure of every point of a cloud.
struct CreaseMeasure {
  Normals normals;               ///< plane normal at `radius`, towards the viewpoint
  std::vector<float> concavity;  ///< m: envelope minus own height (> 0: concave), NaN
};

/// Per-point work of the pipeline. Every method keeps input order and size; invalid (NaN)
/// points stay invalid. Neighbours are the valid points within `radius` (m) in 3-D.
class GT_API FeatureBackend {
 public:
  virtual ~FeatureBackend() = default;
  /// "cpu" or "opencl".
  virtual std::string name() const = 0;
  /// Human-readable device, e.g. "OpenMP, 2 threads" or the OpenCL device name.
  virtual std::string device() const = 0;
  /// Why this backend stands in for the one asked for (e.g. "auto" found no OpenCL device);
  /// empty otherwise. Callers show it to the user.
  virtual std::string warning() const { return {}; }

  /// MLS-smoothed copy of `cloud` (same frame, metres).
  virtual Cloud smooth(const Cloud& cloud, const SmoothParams& params) = 0;

  /// PCA normals over the neighbours within `radius` (m), each flipped to face
  /// `cloud.viewpoint`. A point with fewer than `min_neighbors` neighbours (itself
  /// included) gets a NaN normal.
  virtual Normals normals(const Cloud& cloud, float radius, int min_neighbors) = 0;

  /// The paper's surface-variation descriptor D (deg^2) per point, eqs. 2-6:
  /// sigma_l = population variance of the angles between n_i and each neighbour's normal
  /// (neighbours j != i), sigma_g = population variance of the angles between each normal in
  /// the neighbourhood (i included) and `u_b`; D = sqrt(sigma_l^2 + sigma_g^2). Points
  /// without a normal, or with no neighbour that has one, get NaN.
  virtual std::vector<float> descriptor(const Cloud& cloud, const Normals& normals, float radius,
                                        const Eigen::Vector3f& u_b) = 0;

  /// The robust method's crease measure of each point p (cloud frame, metres): the plane
  /// normal n of the valid points within `radius` (PCA, flipped towards `cloud.viewpoint`);
  /// the heights h_j = n . (p_j - p) of those points; concavity = the `quantile` of the h_j
  /// (the k-th smallest, k = floor(quantile * (count - 1))) minus the mean h_j over the
  /// points within `own_radius`. NaN normal and concavity below `min_neighbors` points. The
  /// cpu backend selects the quantile exactly; the opencl backend brackets it and returns the
  /// bracket's midpoint, within 1e-4 `radius` of it (1 um at 10 mm).
  virtual CreaseMeasure crease(const Cloud& cloud, const CreaseParams& params) = 0;

  /// normals(), benchmark_normal() and descriptor() with the same radius, in one call: a
  /// device backend keeps the cloud, its search structure and the normals on the device
  /// between the three. Same results as the separate calls.
  virtual FeatureSet features(const Cloud& cloud, float radius, int min_neighbors);
};

/// The benchmark normal u_b = normalize(sum of all valid normals) (paper eq. 4).
/// Returns NaN if the normals sum to zero.
GT_API Eigen::Vector3f benchmark_normal(const Normals& normals);

/// Creates a backend by name: "cpu", "opencl" or "auto" (opencl when a device is present and
/// the kernels build on it, else cpu with a warning() saying why; a call that fails on the
/// device, e.g. a cloud too large for its memory, is rerun on the cpu, which then keeps the
/// backend's later calls, and warning() says why). `device` picks the OpenCL
/// device: an index into list_opencl_devices() or a name substring (see opencl.hpp); empty =
/// the first GPU, else the first device. Throws UsageError for an unknown name or a device
/// that matches nothing, OpenClError (an InternalError) when "opencl" cannot run.
GT_API std::unique_ptr<FeatureBackend> make_backend(const std::string& name,
                                                    const std::string& device = "");

/// The CPU reference backend (OpenMP + Eigen).
GT_API std::unique_ptr<FeatureBackend> make_cpu_backend();

}  // namespace groovetrace
