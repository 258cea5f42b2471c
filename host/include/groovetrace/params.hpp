#pragma once
// Every tunable of a `run`, with its default: the common ones, then each method's own. Config
// files and flags both write into this through one table (config.hpp).
//
// Units: lengths in metres, speeds in m/s, angles in degrees, times in seconds.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <groovetrace/export.hpp>
#include <optional>
#include <string>
#include <vector>

namespace groovetrace {

/// The detection method of a run.
enum class Method {
  robust,  ///< the default: docs/method-robust.md
  paper,   ///< as published (Peng et al.): README, "Paper method notes"
};

/// "robust" or "paper", as in `--method` and report.json.
GT_API const char* to_string(Method method);

/// The paper method's own parameters (`--method paper`).
struct PaperParams {
  bool smooth = true;           ///< run MLS smoothing before normals
  double mls_radius = 0.003;    ///< MLS search radius (m)
  int mls_order = 2;            ///< MLS polynomial order: 1 = plane projection, 2 = quadric
  double radius = 0.003;        ///< neighbourhood radius r for normals and the GFH (m)
  int min_neighbors = 5;        ///< fewer neighbours within r: no normal, never groove
  bool threshold_auto = false;  ///< Otsu on log(D) instead of a fixed threshold
  double threshold = 4.5;       ///< descriptor threshold (deg^2); paper range 4.5-5
  int min_component = 50;       ///< connected groove parts smaller than this are dropped (points)
  double link_distance = 0.0;   ///< max gap inside one groove component (m); 0 = radius
  int slices = 50;              ///< equal-width slices along the groove = waypoints
  int median_max_iterations = 1000;
  double median_tolerance = 1e-7;  ///< Weiszfeld stop: step below this (m), the paper's 1e-4 mm
};

/// The robust method's parameters (`--method robust`, docs/method-robust.md). The defaults are
/// the one configuration used on every shape, distance, tilt and resolution; only `step`,
/// `slices`, `max_seams`, `orientation_blend` and `fillet_leg` are run parameters (flags).
struct RobustParams {
  /// Radius of the concavity measure and half of a cross-section's window (m): grooves up to
  /// about 1.6 times this wide fit the window (docs/method-robust.md, "One configuration").
  double scale = 0.010;
  /// The scales searched (m), each with voxels of max(cell, scale / 10); a groove is kept at
  /// the scale that fits it best (docs/method-robust.md, "Scales"). Empty: `scale` alone.
  std::vector<double> scales = {0.005, 0.010, 0.020, 0.040};
  double cell = 0.001;       ///< voxel edge of the coarse cloud the candidates live on (m)
  double threshold_k = 4.0;  ///< candidate: concavity > median + k * robust sigma
  /// When no seam is accepted at `threshold_k`, the search runs once more with this k (0 or
  /// >= threshold_k: never; docs/method-robust.md, "A second search").
  double retry_threshold_k = 3.0;
  double station = 0.0015;  ///< spacing of the fitted cross-sections along a seam (m)
  double slab = 0.0015;     ///< half-thickness of a cross-section along the seam (m)
  /// Half-window of the smoothing along the seam (m): the seam's curve and roots over it, the
  /// groove's shape over 5 times it. At scales beyond 20 mm, 0.3 times the scale.
  double smooth = 0.006;
  /// Half-window of the torch path's smoothing in depth, along the top normal (m): the top
  /// above the roots over it, a groove's depth below the top over 3 times it
  /// (docs/method-robust.md, "Trajectory").
  double depth_smooth = 0.024;
  double min_length = 0.015;  ///< seams shorter than this are rejected (m)
  double step = 0.002;        ///< waypoint spacing along the seam (m)
  int slices = 0;             ///< > 0: this many equal arc-length parts instead of `step`
  int max_seams = 1;          ///< seams exported as trajectories, best first
  /// Arc length (m) over which the torch's orientation is blended either side of each point (a
  /// triangle-weighted mean of the wall bisector and the travel tangent; 0 = none): through a
  /// corner the torch turns at about turn / blend, for 90 deg at most 1.27 times that - 4.6
  /// deg/mm at 0.025 m, 37 deg/s at the default weld speed of 8 mm/s (docs/method-robust.md,
  /// "Trajectory").
  double orientation_blend = 0.025;
  /// The leg of the fillet weld on a corner joint (fillet or lap; m): its ends on the two faces
  /// bound the joint region and the weld face between them (z7, a throat of 5 mm at 90 deg).
  double fillet_leg = 0.007;
};

/// The robot controller a program is written for (`--robot`, program.hpp).
enum class Robot {
  ur,    ///< Universal Robots URScript: program.script
  abb,   ///< ABB RAPID module: program.mod
  kuka,  ///< KUKA KRL: program.src and program.dat
};

/// "ur", "abb" or "kuka", as in `--robot` and report.json.
GT_API const char* to_string(Robot robot);

/// The robot program's controller, motion and arc settings (program.hpp).
struct ProgramParams {
  Robot robot = Robot::ur;        ///< the controller whose program is written
  double approach_offset = 0.05;  ///< approach/retreat distance along -tool z (m)
  double approach_speed = 0.1;    ///< m/s for approach and retreat moves
  double weld_speed = 0.008;      ///< m/s along the seam
  double acceleration = 0.5;      ///< m/s^2 for all moves
  double blend_radius = 0.002;    ///< requested movep blend radius (m), capped per segment
  /// The output that switches the arc: ur: standard digital output 0..7; kuka: $OUT[n],
  /// 1..4096; abb: the signal doArcN.
  int arc_output = 0;
  double arc_delay = 0.5;  ///< s to wait after arc on before moving
  bool dry_run = false;    ///< the same program with the arc never switched on
};

/// What a welder sets around the path (docs/robot.md): torch angles, weaving and passes. Angles
/// are applied in the tool frame (z into the workpiece, x along travel, y = z x x).
struct WeldParams {
  double travel_angle = 0.0;     ///< deg, about tool y: + push (the torch leans forward), - drag
  double work_angle = 0.0;       ///< deg, about tool x (the seam): + tilts the torch's z towards -y
  std::string weave = "none";    ///< none, zigzag, sine or triangle
  double weave_amplitude = 0.0;  ///< m, from the root line to either side (half the width)
  double weave_wavelength = 0.004;  ///< m along the seam per period
  bool multi_pass = false;  ///< plan root, fill and cap passes from the fitted V (robust only)
  double bead_area = 0.0;   ///< m^2 of weld metal per pass; 0 = wire area * wire_feed / weld_speed
  double wire_diameter = 0.0012;  ///< m
  double wire_feed = 0.1;         ///< m/s (6 m/min)
};

/// Checks on every robot program before it is written (guards.hpp); a violation is exit 7.
struct GuardParams {
  double max_step = 0.05;           ///< largest distance between consecutive poses (m)
  double max_step_rotation = 30.0;  ///< largest rotation between consecutive poses (deg)
  /// Every pose, approach and retreat included, inside this box of the base frame (m); unset:
  /// no box. Needs the calibration files.
  std::optional<Eigen::AlignedBox3d> workspace;
  /// Write the program even when its poses are in the camera frame (no calibration files).
  bool camera_frame_program = false;
};

/// Parameters of a run: what both methods share, then each method's own (only the chosen
/// method's are used; the CLI warns about flags of the other).
struct Params {
  Method method = Method::robust;
  std::string backend = "auto";  ///< "auto", "cpu" or "opencl"
  std::string device;        ///< OpenCL device: index or name part; empty = first GPU, else first
  double units_scale = 1.0;  ///< input coordinates * units_scale = metres (mm: 0.001)
  std::optional<Eigen::Vector3f> viewpoint;  ///< overrides the PCD VIEWPOINT (cloud frame, m)

  PaperParams paper;
  RobustParams robust;
  ProgramParams program;
  WeldParams weld;
  GuardParams guards;

  // Frames: robot base frame output when both are given (files, see docs/frames.md).
  std::string hand_eye_file;     ///< T_flange_camera
  std::string flange_pose_file;  ///< T_base_flange at capture time

  /// Depth PNG scans: the intrinsics JSON (fx, fy, ppx, ppy in pixels, depth_scale in m per
  /// unit); empty: STEM.json beside the PNG, else intrinsics.json in its folder.
  std::string intrinsics_file;
};

}  // namespace groovetrace
