#pragma once
// The steps of render and write_synth_scan (host/src/synth), declared apart from the public
// synth.hpp so that tests can check each alone: the scene and its ray casting, the camera
// pose, the ideal frame, the sensor model, and the truth files' contents.

#include <Eigen/Geometry>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <groovetrace/synth.hpp>
#include <memory>
#include <string>
#include <vector>

namespace groovetrace {

/// A surface point found by ray casting, workpiece frame.
struct RayHit {
  bool hit = false;
  double t = 0.0;          ///< distance along the unit ray direction (m)
  Eigen::Vector3d point;   ///< m
  Eigen::Vector3d normal;  ///< unit, out of the solid
  std::uint8_t label = 0;  ///< 1 = groove wall (or the table seen through the root gap), a
                           ///< fillet or lap corner's region, or a tack
  bool table = false;      ///< the hit is on the table plane
};

/// The workpiece of SynthParams (shape and groove) on the table, in the workpiece frame.
class SynthScene {
 public:
  explicit SynthScene(const SynthParams& params);
  ~SynthScene();
  SynthScene(const SynthScene&) = delete;
  SynthScene& operator=(const SynthScene&) = delete;

  /// First surface along origin + t * direction (unit) with t < t_max, workpiece frame.
  /// Sphere tracing on a 1-Lipschitz signed distance bound, then bisection to 1e-7 m.
  RayHit intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   double t_max) const;
  /// True if a surface lies between `from` and `to` closer than `tolerance` (m) to `from`'s
  /// side of `to` (i.e. `to` is hidden from `from`). Workpiece frame.
  bool occluded(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double tolerance) const;
  /// Signed distance bound of the workpiece (m): <= 0 inside, > 0 outside, 1-Lipschitz (not
  /// the table).
  double signed_distance(const Eigen::Vector3d& p) const;
  /// The seams' root lines in the workpiece frame (in_view all 1), with their joint and tacks.
  std::vector<Seam> seams() const;
  /// Adds what depends on the view (extras.cpp): tack welds along the part of each seam the
  /// camera sees, clamps near that part's ends, loose bars beside the part. Positions come
  /// from params.seed (a stream of its own: the sensor's noise does not change). Call once,
  /// before rendering.
  void place_extras(const SynthParams& params, const CameraModel& camera,
                    const Eigen::Isometry3d& T_workpiece_camera);
  /// The point the camera looks at: the seam's centre on the top surface (m).
  Eigen::Vector3d look_at() const;
  const GrooveGeometry& groove() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Camera pose for the params: looking straight down at scene.look_at() from `distance`
/// with image x along the seam (+x of the workpiece), then pitched by tilt about the camera
/// x axis and rolled about its optical axis, both about the look-at point. Fillet and lap
/// joints start pitched by 45 deg (the camera on the -y side, looking down the corner's
/// bisector); tilt adds to that.
Eigen::Isometry3d camera_pose(const SynthParams& params, const SynthScene& scene);

/// What an ideal sensor sees, per pixel in row-major order.
struct IdealFrame {
  std::vector<double> depth;           ///< camera-frame z of the hit (m); NaN: no surface
  std::vector<float> cos_incidence;    ///< |cos| of the angle between ray and surface normal
  std::vector<std::uint8_t> label;     ///< groove-wall label of the hit surface
  std::vector<std::uint8_t> shadowed;  ///< 1: the right imager cannot see the hit point
};

/// Ray casts every pixel. Shadow rays only when noise and stereo_shadow are on.
IdealFrame render_ideal(const SynthScene& scene, const CameraModel& camera,
                        const Eigen::Isometry3d& T_workpiece_camera, const SynthParams& params);

/// Applies the D415 model (the effects enabled in params) to an ideal frame and returns the
/// organized camera-frame cloud (m, NaN = no return). With noise off the points are the exact
/// hits.
Cloud simulate_sensor(const IdealFrame& ideal, const CameraModel& camera,
                      const SynthParams& params);

/// SCAN.truth.json contents. `scan_name` and `labels_name` are recorded as written.
std::string truth_json(const SynthTruth& truth, const std::string& scan_name,
                       const std::string& labels_name);
/// SCAN.labels.pcd contents.
std::string labels_pcd_bytes(const SynthTruth& truth);

}  // namespace groovetrace
