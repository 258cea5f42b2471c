// Rendering a synthetic scan: camera pose, one ray per pixel, the sensor model, and the
// truth (labels, and the seams' root lines with what of them the camera can see).

#include <cmath>
#include <groovetrace/error.hpp>
#include <limits>
#include <sstream>
#include <string>

#include "core/stats.hpp"
#include "synth/internal.hpp"

namespace groovetrace {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
// No ray travels further than this (m): the table is always closer.
constexpr double kFar = 10.0;
// A shadow ray that reaches within this distance of its target counts as reaching it (m).
constexpr double kShadowTolerance = 1e-4;

void require(bool ok, const std::string& what, double value, const std::string& range) {
  if (ok) return;
  std::ostringstream s;
  s << "synth: " << what << " " << value << " is out of range (" << range << ")";
  throw UsageError(s.str());
}

}  // namespace

namespace {

void require_shape(bool ok, const std::string& what, const SynthParams& p,
                   const std::string& allowed) {
  if (ok) return;
  throw UsageError("synth: " + what + " is not available for shape " + shape_name(p.shape) + " (" +
                   allowed + ")");
}

// The joint's cross-section and the conditions (issue 12).
void validate_joint(const SynthParams& p) {
  const bool corner = p.joint == JointType::kFillet || p.joint == JointType::kLap;
  const bool pipe = p.shape == Shape::kCylinder || p.shape == Shape::kPipeLong;
  require(std::isfinite(p.groove_width) && p.groove_width >= 0.002 &&
              p.groove_width <= (corner ? 0.04 : 0.10),
          "groove width", p.groove_width,
          corner ? "0.002-0.04 m for fillet and lap" : "0.002-0.10 m");
  if (p.groove_depth > 0.0) {
    require(std::isfinite(p.groove_depth) && p.groove_depth >= 0.001 && p.groove_depth <= 0.03,
            "groove depth", p.groove_depth, "0.001-0.03 m");
  } else if (p.joint == JointType::kBevel) {
    require(std::isfinite(p.groove_angle_deg) && p.groove_angle_deg >= 10.0 &&
                p.groove_angle_deg <= 80.0,
            "groove angle", p.groove_angle_deg, "10-80 deg for a bevel");
  } else {
    require(std::isfinite(p.groove_angle_deg) && p.groove_angle_deg >= 20.0 &&
                p.groove_angle_deg <= 170.0,
            "groove angle", p.groove_angle_deg, "20-170 deg");
  }
  require_shape(!corner || (!pipe && !(p.joint == JointType::kLap && p.shape == Shape::kMulti)),
                std::string("joint ") + joint_name(p.joint), p,
                p.joint == JointType::kFillet ? "fillet: straight, curve, lshape, multi, box"
                                              : "lap: straight, curve, lshape, box");
  require(std::isfinite(p.misalignment) && p.misalignment >= 0.0 && p.misalignment <= 0.005,
          "misalignment", p.misalignment, "0-0.005 m");
  if (p.misalignment > 0.0) {
    require_shape(p.shape != Shape::kMulti, "misalignment", p, "one seam: every shape but multi");
    if (corner)
      throw UsageError("synth: misalignment is for butt joints (V, bevel), not " +
                       std::string(joint_name(p.joint)));
  }
  require(p.tacks >= 0 && p.tacks <= 10, "tacks", p.tacks, "0-10");
  require(std::isfinite(p.tack_height_fraction) && p.tack_height_fraction >= 0.1 &&
              p.tack_height_fraction <= 1.0,
          "tack height fraction", p.tack_height_fraction, "0.1-1");
  require(p.clamps >= 0 && p.clamps <= 4, "clamps", p.clamps, "0-4");
  if (p.clamps > 0) require_shape(!pipe, "clamps", p, "plates and box");
  require(p.clutter >= 0 && p.clutter <= 2, "clutter", p.clutter, "0-2");
  require(std::isfinite(p.pipe_diameter) && p.pipe_diameter >= 0.06 && p.pipe_diameter <= 0.20,
          "pipe diameter", p.pipe_diameter, "0.06-0.20 m");
}

}  // namespace

void validate(const SynthParams& p) {
  require(std::isfinite(p.distance) && p.distance >= 0.2 && p.distance <= 1.5, "distance",
          p.distance, "0.2-1.5 m; D415 scans: 0.3-0.6 m");
  require(std::isfinite(p.tilt_deg) && std::abs(p.tilt_deg) <= 45.0, "tilt", p.tilt_deg,
          "-45..45 deg");
  require(std::isfinite(p.roll_deg) && std::abs(p.roll_deg) <= 180.0, "roll", p.roll_deg,
          "-180..180 deg");
  require(p.width >= 32 && p.width <= 4096, "width", p.width, "32-4096 px");
  require(p.height >= 32 && p.height <= 4096, "height", p.height, "32-4096 px");
  validate_joint(p);
  require(std::isfinite(p.root_gap) && p.root_gap >= 0.0 && p.root_gap <= 0.003 &&
              p.root_gap < p.groove_width,
          "root gap", p.root_gap, "0-0.003 m and below the groove width");
  require(std::isfinite(p.depth_unit) && p.depth_unit >= 1e-5 && p.depth_unit <= 0.01, "depth unit",
          p.depth_unit, "1e-5-0.01 m; D415: 0.001 or 0.0001");
  const GrooveGeometry g = groove_geometry(p);
  require(g.depth <= 0.03, "groove depth", g.depth, "at most 0.03 m; widen the angle");
  if (p.shape == Shape::kCylinder || p.shape == Shape::kPipeLong)
    require(g.thickness <= 0.6 * 0.5 * p.pipe_diameter, "groove depth", g.depth,
            "the pipe wall (depth + 1.5 mm) at most 0.6 of the pipe's radius");
}

double Seam::length() const {
  double l = 0.0;
  for (std::size_t i = 1; i < root.size(); ++i) l += (root[i] - root[i - 1]).norm();
  return l;
}

double Seam::length_in_view() const {
  double l = 0.0;
  for (std::size_t i = 1; i < root.size(); ++i)
    if (in_view[i] && in_view[i - 1]) l += (root[i] - root[i - 1]).norm();
  return l;
}

Eigen::Isometry3d camera_pose(const SynthParams& params, const SynthScene& scene) {
  // Straight down with image x along the seam: camera x = +x, y = -y, z = -z (workpiece).
  Eigen::Matrix3d down;
  down << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  // Fillet and lap joints are seen down their corner's bisector, from the -y side.
  const bool corner = params.joint == JointType::kFillet || params.joint == JointType::kLap;
  const double pitch_deg = corner ? params.tilt_deg + 45.0 : params.tilt_deg;
  const Eigen::Matrix3d R_workpiece_camera =
      down * Eigen::AngleAxisd(pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
      Eigen::AngleAxisd(params.roll_deg * kDeg, Eigen::Vector3d::UnitZ());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_workpiece_camera;
  T.translation() = scene.look_at() - params.distance * R_workpiece_camera.col(2);
  return T;
}

IdealFrame render_ideal(const SynthScene& scene, const CameraModel& camera,
                        const Eigen::Isometry3d& T_workpiece_camera, const SynthParams& params) {
  const int W = camera.width, H = camera.height;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  IdealFrame f;
  f.depth.assign(N, std::numeric_limits<double>::quiet_NaN());
  f.cos_incidence.assign(N, 0.0f);
  f.label.assign(N, 0);
  f.shadowed.assign(N, 0);
  const bool shadows = params.noise && params.effects.stereo_shadow;
  const Eigen::Matrix3d R = T_workpiece_camera.linear();
  const Eigen::Vector3d left = T_workpiece_camera.translation();
  const Eigen::Vector3d right = T_workpiece_camera * Eigen::Vector3d(params.sensor.baseline, 0, 0);

  // Rows differ in cost (the groove, silhouettes), hence dynamic scheduling.
#pragma omp parallel for schedule(dynamic, 4)
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      const Eigen::Vector3d ray = camera.ray(u, v);
      const double norm = ray.norm();
      const Eigen::Vector3d dir = R * (ray / norm);
      const RayHit hit = scene.intersect(left, dir, kFar);
      if (!hit.hit) continue;
      f.depth[i] = hit.t / norm;
      f.cos_incidence[i] = static_cast<float>(std::abs(hit.normal.dot(dir)));
      f.label[i] = hit.label;
      if (shadows) f.shadowed[i] = scene.occluded(right, hit.point, kShadowTolerance) ? 1 : 0;
    }
  }
  return f;
}

SynthScan render(const SynthParams& params) {
  validate(params);
  SynthScene scene(params);
  const CameraModel camera = d415_camera(params.width, params.height, params.sensor);
  const Eigen::Isometry3d T_workpiece_camera = camera_pose(params, scene);
  if (params.tacks > 0 || params.clamps > 0 || params.clutter > 0)
    scene.place_extras(params, camera, T_workpiece_camera);
  const IdealFrame ideal = render_ideal(scene, camera, T_workpiece_camera, params);

  SynthScan scan;
  scan.cloud = simulate_sensor(ideal, camera, params);

  SynthTruth& truth = scan.truth;
  truth.params = params;
  truth.groove = scene.groove();
  truth.camera = camera;
  truth.T_workpiece_camera = T_workpiece_camera;
  truth.label = ideal.label;
  truth.valid.resize(scan.cloud.size());
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) truth.valid[i] = scan.cloud.valid(i) ? 1 : 0;

  // A root vertex is in view when a detector could find the groove there: inside the image
  // where the sensor returns depth, facing the camera, and the groove's opening above it not
  // hidden by the workpiece.
  const Eigen::Isometry3d T_camera_workpiece = T_workpiece_camera.inverse();
  const Eigen::Vector3d eye = T_workpiece_camera.translation();
  const bool sensor_limits = params.noise;
  for (Seam seam : scene.seams()) {
    for (std::size_t k = 0; k < seam.root.size(); ++k) {
      const Eigen::Vector3d& p = seam.root[k];
      const Eigen::Vector3d c = T_camera_workpiece * p;
      bool in = c.z() > 0.0;
      if (in) {
        const double u = camera.fx * c.x() / c.z() + camera.cx;
        const double v = camera.fy * c.y() / c.z() + camera.cy;
        in = u >= 0.0 && u <= camera.width - 1.0 && v >= 0.0 && v <= camera.height - 1.0;
        if (sensor_limits && params.effects.left_band)
          in = in && u >= camera.fx * params.sensor.baseline / c.z();
        if (sensor_limits && params.effects.min_z) in = in && c.z() >= params.sensor.min_z;
      }
      in = in && seam.normal[k].dot(eye - p) > 0.0;
      // Beyond grazing_full_deg of incidence the sensor model returns nothing at all
      // (simulate_sensor), so no detector can see the groove there.
      if (sensor_limits && params.effects.grazing_dropout) {
        const double cos_incidence = seam.normal[k].normalized().dot((eye - p).normalized());
        in = in && cos_incidence >= std::cos(deg_to_rad(params.sensor.grazing_full_deg));
      }
      const Eigen::Vector3d opening = p + truth.groove.depth * seam.bisector[k];
      in = in && !scene.occluded(eye, opening, kShadowTolerance);
      seam.in_view[k] = in ? 1 : 0;
      seam.root[k] = c;
      seam.normal[k] = T_camera_workpiece.linear() * seam.normal[k];
      seam.bisector[k] = T_camera_workpiece.linear() * seam.bisector[k];
    }
    for (Tack& tack : seam.tacks) tack.centre = T_camera_workpiece * tack.centre;
    truth.seams.push_back(std::move(seam));
  }
  return scan;
}

}  // namespace groovetrace
