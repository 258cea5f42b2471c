#pragma once
// Every tunable of a `run`, with its default. Config files and flags both write into this.

#include <Eigen/Core>
#include <optional>
#include <string>

namespace groovetrace {

/// Parameters of the pipeline. Lengths in metres, speeds in m/s, angles in degrees.
struct Params {
  // Method and backend.
  std::string method = "robust";  ///< "robust" (docs/method-robust.md) or "paper" (as published)
  std::string backend = "auto";  ///< "auto", "cpu" or "opencl"
  std::string device;            ///< OpenCL device: index or name part; empty = first GPU, else first
  double units_scale = 1.0;      ///< input coordinates * units_scale = metres (mm: 0.001)

  // Features.
  bool smooth = true;            ///< run MLS smoothing before normals
  double mls_radius = 0.003;     ///< MLS search radius (m)
  int mls_order = 2;             ///< MLS polynomial order: 1 = plane projection, 2 = quadric
  double radius = 0.003;         ///< neighbourhood radius r for normals and the GFH (m)
  int min_neighbors = 5;         ///< fewer neighbours within r: no normal, never groove
  std::optional<Eigen::Vector3f> viewpoint;  ///< overrides the PCD VIEWPOINT (cloud frame, m)

  // Detection.
  bool threshold_auto = false;   ///< Otsu on log(D) instead of a fixed threshold
  double threshold = 4.5;        ///< descriptor threshold (deg^2); paper range 4.5-5
  int min_component = 50;        ///< connected groove parts smaller than this are dropped (points)
  double link_distance = 0.0;    ///< max gap inside one groove component (m); 0 = radius

  // Trajectory.
  int slices = 50;               ///< equal-width slices along the groove = waypoints
  bool slices_given = false;     ///< slices was set (flag or config): robust uses it over step
  double step = 0.002;           ///< robust: waypoint spacing along the seam (m)
  int max_seams = 1;             ///< robust: seams exported as trajectories, best first
  int median_max_iterations = 1000;
  double median_tolerance = 1e-7;  ///< Weiszfeld stop: step below this (m), the paper's 1e-4 mm

  // Robot program (URScript).
  double approach_offset = 0.05;  ///< approach/retreat distance along -tool z (m)
  double approach_speed = 0.1;    ///< m/s for approach and retreat moves
  double weld_speed = 0.008;      ///< m/s along the seam
  double acceleration = 0.5;      ///< m/s^2 for all moves
  double blend_radius = 0.002;    ///< requested movep blend radius (m), capped per segment
  int arc_output = 0;             ///< standard digital output that switches the arc
  double arc_delay = 0.5;         ///< s to wait after arc on before moving

  // Frames: robot base frame output when both are given (files, see docs/frames.md).
  std::string hand_eye_file;      ///< T_flange_camera
  std::string flange_pose_file;   ///< T_base_flange at capture time
};

}  // namespace groovetrace
