#pragma once
// Synthetic RealSense D415 scans of V-groove workpieces, with ground truth (issue 3).
//
// No public labelled scans of V-grooves exist, so accuracy claims rest on these: an analytic
// workpiece on a welding table is ray cast through a pinhole camera, then a D415 sensor model
// (docs/design.md, the D415 sensor facts) turns the ideal depth into what the camera returns.
//
// Frames. The workpiece frame W: the table is the plane z = 0, z points up out of the table,
// the seam runs along +x through the origin's vertical (x, y in the table plane). The camera
// frame C is the RealSense depth frame: x right, y down, z forward (metres), origin at the
// left imager's centre; the right imager sits at (+baseline, 0, 0). `T_workpiece_camera`
// maps camera coordinates to workpiece coordinates: p_workpiece = T_workpiece_camera * p_camera.

#include <Eigen/Geometry>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <groovetrace/export.hpp>
#include <string>
#include <vector>

namespace groovetrace {

/// The workpieces. The paper's four are straight, curve, box and cylinder.
enum class Shape {
  kStraight,  ///< butt V-groove straight across a 300 x 200 mm plate lying on the table
  kCurve,     ///< V-groove along an S curve (two tangent arcs) in the same plate
  kBox,       ///< straight groove across the top of a raised 160 x 100 x 60 mm block
  kCylinder,  ///< circumferential groove around a pipe (SynthParams::pipe_diameter, 100 mm)
              ///< lying on the table
  kPipeLong,  ///< longitudinal groove along the top of the same pipe
  kLShape,    ///< a seam with a 90 degree corner in the plate
  kMulti,     ///< two parallel straight grooves, 80 mm apart, in the plate
};

/// The joint whose seam the workpiece carries (issue 12). docs/synthetic-scans.md, "Joints".
enum class JointType {
  kV,       ///< butt joint, symmetric V groove (the paper's)
  kBevel,   ///< butt joint, single bevel: vertical wall on the -y side, inclined wall on +y
  kFillet,  ///< T-joint: a web standing on the plate along the seam; the seam is the corner
  kLap,     ///< lap joint: a second plate lying on the +y side; the seam is its edge's corner
};

/// Truth-file and CLI name of a joint: "V", "bevel", "fillet", "lap" (the CLI also takes "v").
GT_API const char* joint_name(JointType joint);
/// Inverse of joint_name (also "v"); throws UsageError listing the known names.
GT_API JointType parse_joint(const std::string& name);

/// Lower-case CLI name of a shape ("straight", "curve", "box", "cylinder", "pipe-long",
/// "lshape", "multi").
GT_API const char* shape_name(Shape shape);
/// Inverse of shape_name; throws UsageError listing the known names.
GT_API Shape parse_shape(const std::string& name);
/// All shape names, in enum order.
GT_API std::vector<std::string> shape_names();

/// Which sensor effects the D415 model applies (all only when SynthParams::noise is on).
struct SensorEffects {
  bool depth_noise = true;      ///< per-pixel disparity noise (docs/design.md depth RMS formula)
  bool undulation = true;       ///< spatially correlated disparity error over 5-20 mm
  bool blur = true;             ///< stereo matching window averages disparity across creases
  bool flying_pixels = true;    ///< depths between foreground and background at jumps
  bool grazing_dropout = true;  ///< no return at high incidence angles
  bool stereo_shadow = true;    ///< no return where the right imager cannot see the point
  bool left_band = true;        ///< no return in the left band the right imager does not see
  bool random_dropout = true;   ///< isolated missing pixels
  bool min_z = true;            ///< no return closer than SensorModel::min_z
  bool quantize = true;         ///< depth rounded to SynthParams::depth_unit

  static SensorEffects all() { return {}; }
  static SensorEffects none();
  bool any() const;
};

/// Parses a comma-separated effect list: "all", "none", or names from
/// {depth,undulation,blur,flying,grazing,shadow,band,dropout,minz,quantize}; the named effects
/// are on, the others off. Throws UsageError for an unknown name.
GT_API SensorEffects parse_effects(const std::string& list);
/// The comma-separated names of the effects that are on ("none" if no effect is on).
GT_API std::string effects_string(const SensorEffects& effects);

/// D415 constants of the sensor model. Defaults follow docs/design.md; change them to model
/// another stereo camera.
struct SensorModel {
  double hfov_deg = 65.0;              ///< horizontal field of view at every resolution (deg)
  double vfov_deg = 40.0;              ///< vertical field of view of the native 16:9 frame (deg)
  double baseline = 0.055;             ///< left-right imager distance (m)
  double subpixel = 0.08;              ///< per-pixel disparity noise RMS (px)
  bool correlate_noise = true;         ///< per-pixel noise correlated over the matching window
                                       ///< (RMS unchanged); false: white noise
  double undulation_disparity = 0.10;  ///< correlated disparity error std (px); 0.45 mm at 0.5 m
  double undulation_min_wavelength = 0.010;  ///< undulation wavelengths (m, at the look-at
  double undulation_max_wavelength = 0.040;  ///< distance): half-waves of 5-20 mm
  int blur_radius_1280 = 2;          ///< matching window half-width (px) at 1280 columns, scaled
  double jump_disparity = 1.0;       ///< neighbours whose disparities differ more are a depth jump
  double flying_probability = 0.35;  ///< chance that a pixel at a jump becomes a flying pixel
  double grazing_start_deg = 75.0;   ///< incidence where returns start to drop out
  double grazing_full_deg = 82.0;    ///< incidence beyond which nothing returns
  double dropout_probability = 0.005;  ///< independent missing pixels
  double min_z = 0.28;  ///< closest depth (m); a D415 with disparity shift for close range
};

/// Everything that determines a synthetic scan. Lengths in metres, angles in degrees.
struct SynthParams {
  Shape shape = Shape::kStraight;
  double groove_width = 0.010;     ///< top width of the V between its two top edges (m);
                                   ///< bevel, fillet, lap: GrooveGeometry
  double groove_angle_deg = 60.0;  ///< included angle between the two walls (deg)
  double groove_depth = 0.0;       ///< depth of the V (m); > 0 overrides groove_angle_deg
  double root_gap = 0.0005;        ///< gap between the two parts at the root (m)
  double distance = 0.40;          ///< camera origin to the look-at point on the seam (m)
  double tilt_deg = 0.0;           ///< camera pitch about its x axis, across the seam (deg)
  double roll_deg = 0.0;           ///< camera roll about its optical axis (deg)
  int width = 1280;                ///< image columns (D415 modes: 1280x720, 848x480, 640x480)
  int height = 720;                ///< image rows
  std::uint64_t seed = 1;          ///< every random choice comes from this
  bool noise = true;               ///< false: ideal geometry, no sensor effect at all
  SensorEffects effects;           ///< which effects apply when noise is on
  double depth_unit = 0.001;       ///< depth quantisation step (m): 0.001 default, 0.0001 fine
  SensorModel sensor;

  // Real-shop joints and conditions (issue 12). At their defaults the scan is the V groove
  // of the paper's scenes, byte for byte.
  JointType joint = JointType::kV;    ///< the joint (fillet and lap: plate shapes only)
  double misalignment = 0.0;          ///< high-low (m, 0-0.005): the +y part's top is this higher
  int tacks = 0;                      ///< tack welds per seam (0-10), in the in-view part
  double tack_height_fraction = 0.7;  ///< tack height as a fraction of the joint depth (0.1-1)
  int clamps = 0;                     ///< clamp blocks on the plates beside the seam (0-4)
  int clutter = 0;                    ///< loose bars lying on the table beside the part (0-2)
  double pipe_diameter = 0.10;        ///< outer diameter of cylinder and pipe-long (m, 0.06-0.20)
};

/// Checks parameter ranges; throws UsageError naming the offending parameter.
GT_API void validate(const SynthParams& params);

/// The groove's cross-section as built (metres, degrees). The V's walls run from the two top
/// edges (top_width apart) down to the root at `depth`; below the root a vertical gap of
/// width root_gap runs through the rest of the part (`thickness`).
///
/// Other joints (docs/synthetic-scans.md, "Joints"): bevel - top_width from the vertical wall
/// to the inclined wall's top edge, included_angle between the two walls; fillet and lap -
/// top_width is the weld face (the hypotenuse of the isosceles right triangle in the corner),
/// depth its throat (top_width / 2), included_angle 90, root_gap 0.
struct GrooveGeometry {
  double top_width = 0.0;
  double depth = 0.0;
  double included_angle_deg = 0.0;
  double root_gap = 0.0;
  double thickness = 0.0;     ///< plate, block top or pipe wall thickness (m)
  double misalignment = 0.0;  ///< high-low (m): the +y part's top above the -y part's
};
/// The geometry SynthParams describe: V: depth = (top_width - root_gap) / (2 tan(angle / 2)),
/// bevel: depth = (top_width - root_gap) / tan(angle), unless groove_depth is given;
/// thickness = max(10 mm, depth + 1.5 mm). Fillet and lap: depth = top_width / 2, leg =
/// top_width / sqrt(2), thickness = max(10 mm, leg + 1.5 mm).
GT_API GrooveGeometry groove_geometry(const SynthParams& params);

/// Pinhole camera (no distortion, as RealSense depth streams). Pixel (u, v) = (column, row)
/// looks along (u - cx) / fx, (v - cy) / fy, 1 in the camera frame.
struct CameraModel {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< pixels
  /// Ray through pixel (u, v), camera frame, z = 1 (so a point at depth Z is Z * ray).
  Eigen::Vector3d ray(double u, double v) const { return {(u - cx) / fx, (v - cy) / fy, 1.0}; }
};
/// D415 intrinsics at a resolution: fx = 0.5 width / tan(HFOV / 2); fy from the VFOV of the
/// native 16:9 frame, fy = 0.5 (width * 9 / 16) / tan(VFOV / 2) (so 4:3 modes see more rows);
/// cx = (width - 1) / 2, cy = (height - 1) / 2. 1280x720: fx 1004.6, fy 989.1.
GT_API CameraModel d415_camera(int width, int height, const SensorModel& sensor = {});

/// A tack weld in a seam: a rounded hump filling the joint up to a fraction of its depth.
struct Tack {
  double position = 0.0;                             ///< arc length along the seam's root (m)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< on the root line (m)
  double length = 0.0;                               ///< along the seam (m)
  double height = 0.0;  ///< top above the root, along the seam's normal (m)
};

/// One seam's true root line. Vertices are about 1 mm apart; a closed seam repeats its first
/// vertex at the end. All vectors in the frame of the container (camera frame in SynthTruth).
struct Seam {
  std::vector<Eigen::Vector3d> root;      ///< root line (m): centre of the gap at the V's bottom
  std::vector<Eigen::Vector3d> normal;    ///< unit surface normal of the part there, out of the
                                          ///< workpiece (towards the camera side); fillet and
                                          ///< lap: the bisector (the root is a corner)
  std::vector<Eigen::Vector3d> bisector;  ///< unit bisector of the two walls, out of the
                                          ///< groove; the tool z axis should be -bisector
  std::vector<std::uint8_t> in_view;      ///< 1: inside the image where the sensor can return,
                                          ///< facing the camera, the groove above it unhidden
  bool closed = false;
  JointType joint = JointType::kV;  ///< the joint along this seam
  std::vector<Tack> tacks;          ///< tack welds on it (centres in the container's frame)
  double length() const;            ///< polyline length (m)
  double length_in_view() const;    ///< length of the segments with both ends in view (m)
};

/// Ground truth of a scan, aligned with its cloud.
struct SynthTruth {
  SynthParams params;
  GrooveGeometry groove;
  CameraModel camera;
  Eigen::Isometry3d T_workpiece_camera = Eigen::Isometry3d::Identity();
  std::vector<std::uint8_t> label;  ///< per point, cloud order: 1 = on a groove wall (between
                                    ///< the two top edges, root gap included), in a fillet or
                                    ///< lap corner's region, or on a tack; else 0
  std::vector<std::uint8_t> valid;  ///< per point: 1 = the scan has a return (finite point)
  std::vector<Seam> seams;          ///< camera frame
};

/// A rendered scan: organized cloud in the camera frame (metres, NaN where the sensor returns
/// nothing, viewpoint at the origin) and its truth.
struct SynthScan {
  Cloud cloud;
  SynthTruth truth;
};

/// Renders a scan. Deterministic: the same params (seed included) give the same bytes,
/// independent of the thread count. Throws UsageError for invalid params.
GT_API SynthScan render(const SynthParams& params);

// --- Files --------------------------------------------------------------------------------

/// The three files of a synthetic scan: SCAN.pcd (binary organized XYZ), SCAN.truth.json
/// (params, camera, pose, counts, seams) and SCAN.labels.pcd (binary PCD, same WIDTH and
/// HEIGHT, uint8 fields `label valid`). See docs/synthetic-scans.md.
struct SynthFiles {
  std::string scan, truth, labels;
};
/// File names for a scan path, which must end in ".pcd" (UsageError otherwise).
GT_API SynthFiles synth_files(const std::string& scan_path);

/// Writes SCAN.pcd and its truth files, each atomically. Returns their names.
GT_API SynthFiles write_synth_scan(const SynthScan& scan, const std::string& scan_path);

/// Reads the truth of SCAN.pcd (its .truth.json and .labels.pcd; the scan itself is not
/// read). Throws InputError for missing or malformed files.
GT_API SynthTruth read_synth_truth(const std::string& scan_path);

}  // namespace groovetrace
