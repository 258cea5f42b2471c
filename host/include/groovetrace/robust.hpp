#pragma once
// The robust method (`--method robust`, docs/method-robust.md): concave-crease candidates at
// the groove's own scale, seams traced as ordered curves, a V model fitted across the seam at
// every station, waypoints on the fitted root, and the groove region labelled from the fitted
// openings. Works on organized and unorganized clouds in any frame: the only use of the
// sensor is the viewpoint (rays from it through each point).
//
// Frames and units: every 3-D quantity is in the cloud's frame, metres; angles in degrees.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <groovetrace/cloud.hpp>
#include <groovetrace/export.hpp>
#include <groovetrace/features.hpp>
#include <groovetrace/params.hpp>
#include <groovetrace/trajectory.hpp>
#include <string>
#include <vector>

namespace groovetrace {

// --- Results ------------------------------------------------------------------------------

/// A fitted cross-section in 3-D.
struct GrooveSection {
  bool ok = false;
  std::string why;
  double s = 0.0;                      ///< arc length of the station along the seam (m)
  Eigen::Vector3d root{0, 0, 0};       ///< wall intersection (m)
  Eigen::Vector3d tangent{1, 0, 0};    ///< unit, along the seam
  Eigen::Vector3d normal{0, 0, 1};     ///< unit, top surface normal, out of the workpiece
  Eigen::Vector3d bisector{0, 0, 1};   ///< unit wall bisector, out of the groove
  Eigen::Vector3d edge_left{0, 0, 0};  ///< top edges (m); left = -across side
  Eigen::Vector3d edge_right{0, 0, 0};
  double width = 0, depth = 0, opening_deg = 0, rms = 0, noise = 0;
  int support = 0;  ///< profile points in the slab
  /// One wall returned (almost) nothing (seen at a grazing angle): its edge is where the top
  /// surface ends, the V taken symmetric about the top normal through the opening.
  bool one_wall = false;
  /// With one_wall: the unseen side is square (its mirror image would have faced the sensor),
  /// the root at its foot - a single bevel seen along its square side.
  bool square_side = false;
  double wall_left_deg = 0, wall_right_deg = 0;  ///< each wall's dip below the top (deg)
  double misalignment = 0;  ///< top on the right (across) side minus the left's (m): high-low
  /// Two-wall V's: the right top side's slope minus the left's beyond the edges (dv/du in the
  /// section's frame; NaN when a side is too short). Plates set high-low stay parallel.
  double top_bend = NAN;
  /// The right top side's height minus the left's above the root from lines through each
  /// side's outer half of the window (m): the step a station fitted on its own holds.
  double outer_step = 0;
  /// The root gap measured at this station (m; two-wall V's, else 0). Once the seam's gap is
  /// applied, `root` is the middle of the opening at the root faces and `depth` is to there.
  double gap = 0;
  /// The share of the fitted V's opening points that lie inside its walls away from the root
  /// (a channel's floor, not a V; 0 on a clean V).
  double inside = 0;
  /// A concave corner between two faces (a fillet or lap joint), not a V: the edges are the
  /// weld's leg ends on the faces, `normal` and `bisector` the corner's bisector.
  bool corner = false;
  /// With corner: one face ends inside the window, where the upper plate of a lap joint begins.
  bool short_face = false;
  /// The V here reads shallower than the seam with its rims where the seam's are: something
  /// fills the groove (a tack weld); not `ok`, so the root follows the neighbours.
  bool filled = false;
  /// No V was measured here, only a gap of the groove's width in the top surface (walls at a
  /// grazing angle return nothing): root placed the seam's depth below the gap's centre.
  bool inferred = false;
  /// No fit here either: past an open seam's last fit the groove still shows in a slab across
  /// the seam's line (a part's end face blurs the fits of its last millimetres), and the end
  /// section is carried on along that line.
  bool extended = false;
  /// across = normal x tangent: u grows towards edge_right.
  Eigen::Vector3d across() const { return normal.cross(tangent).normalized(); }
};

/// A seam's centre line, resampled at a fixed arc-length spacing.
struct SeamCurve {
  std::vector<Eigen::Vector3d> points;    ///< m
  std::vector<Eigen::Vector3d> tangents;  ///< unit, in the order of the points
  std::vector<double> s;                  ///< arc length at each point (m)
  std::vector<double> corners;            ///< arc length of each sharp corner (m)
  bool closed = false;
  double length = 0.0;  ///< m (closed: the whole ring)
};

/// One candidate seam with its sections and score (docs/method-robust.md, "Score").
struct SeamCandidate {
  std::vector<GrooveSection> sections;  ///< along the seam, smoothed (`ok`: its own fit passed)
  std::vector<GrooveSection> raw;       ///< the same stations' own fits, before smoothing
  SeamCurve curve;                      ///< the smoothed root line
  bool closed = false;
  double length = 0.0;       ///< m
  double ok_fraction = 0.0;  ///< sections whose V fit passed
  double fit_quality = 0.0;  ///< median over sections of depth / (depth + 3 rms)
  double consistency = 0.0;  ///< 1 - relative spread of width and opening along the seam
  double width = 0, depth = 0, opening_deg = 0;  ///< medians (m, m, deg)
  double score = 0.0;  ///< length_mm * ok_fraction * fit_quality * consistency
  /// "V", "bevel" (one wall square to the top, the other inclined), "fillet" or "lap" (a
  /// corner between two faces); docs/method-robust.md.
  std::string joint = "V";
  /// Stretches where something fills the groove (tack welds): the arc length of each one's
  /// centre along the seam and its length (m), in order along the seam.
  struct Tack {
    double position = 0.0, length = 0.0;
  };
  std::vector<Tack> tacks;
  double misalignment = 0.0;  ///< |median high-low| of the tops over the ok sections (m)
  double gap = 0.0;           ///< root gap: median over the two-wall sections (m; 0 where not seen)
  double scale = 0.0;         ///< the search scale it was found at (m; RobustParams::scales)
  bool accepted = false;
  std::string reason;   ///< why rejected (empty when accepted)
  bool corner = false;  ///< traced as a corner joint (fillet, lap), not a groove (V, bevel)
  int id = -1;          ///< this candidate's number within its RobustDetection
  /// A stretch shorter than min_length accepted as the continuation of the seam numbered this
  /// past a clamp (docs/method-robust.md, "Beyond a clamp"); -1 on a seam accepted on its own.
  int continues = -1;
};

/// Torch poses along a seam: positions on the smoothed root line (its height along the top
/// normal smoothed further over `depth_smooth`) every `step` (or in `slices` equal parts), tool
/// z = -wall bisector, tool x along the seam, both blended over `orientation_blend`; rotation
/// vectors continuous. An open seam ends at larger x of the cloud's frame than it starts (ties: y,
/// then z); a closed seam starts at its smallest x, runs counter-clockwise about its mean top
/// normal and ends where it started.
GT_API Trajectory seam_trajectory(const SeamCandidate& seam, const RobustParams& params);

/// Arc length (m) along seam_trajectory's path of the point of `seam` at arc length `s` of its
/// sections (GrooveSection::s): an open seam's path may run from its last section to its
/// first, a ring's starts at its section of smallest x and may run against their order (then
/// modulo the ring's length, in [0, length)).
GT_API double travel_arc(const SeamCandidate& seam, double s);

/// What the search at one scale found (RobustParams::scales).
struct ScaleSearchSummary {
  double scale = 0.0;               ///< m
  double cell = 0.0;                ///< voxel edge at this scale (m)
  double threshold = 0.0;           ///< candidate concavity threshold (m)
  std::size_t candidates = 0;       ///< voxels above the threshold
  std::size_t nodes = 0;            ///< crease nodes
  std::size_t confirmed_nodes = 0;  ///< nodes whose cross-section is a V
  std::size_t seams = 0;            ///< candidate seams traced
  std::size_t kept = 0;             ///< of those, kept after the scales' duplicates were dropped
};

/// Everything the robust method decided. The per-point fields and the counts are those of the
/// search at RobustParams::scale; `scales` sums up every scale's search.
struct RobustDetection {
  std::vector<std::uint8_t> groove;  ///< per input point: 1 = groove
  std::vector<float> concavity;      ///< per input point: its voxel's concavity (m), NaN
  Normals normals;                   ///< per input point: its voxel's plane normal at `scale`
  double threshold = 0.0;            ///< candidate concavity threshold (m)
  double noise_sigma = 0.0;          ///< robust sigma of the concavity (m)
  double threshold_k = 0.0;          ///< the threshold's k (robust sigmas) of this result
  bool retried = false;              ///< a second search at retry_threshold_k ran
  std::size_t candidates = 0;        ///< voxels above the threshold
  std::size_t nodes = 0;             ///< crease nodes after non-maximum suppression
  std::size_t confirmed_nodes = 0;   ///< nodes whose cross-section is a V
  std::vector<SeamCandidate> seams;  ///< every candidate, best score first
  std::vector<ScaleSearchSummary> scales;
};

/// Runs stages 1-4 on `cloud` (metres; viewpoint = the sensor origin in its frame). Never
/// throws for "no groove": the caller checks whether any seam is accepted. `lap`, when given,
/// is called after each stage with its name ("candidates", "seams", "region"). The crease
/// measure runs on `backend`; the rest, and everything without a backend, on the CPU.
GT_API RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                                     FeatureBackend& backend,
                                     const std::function<void(const std::string&)>& lap = {});
GT_API RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                                     const std::function<void(const std::string&)>& lap = {});

/// Which of `seams` (best first) are exported as trajectories: the first `max_seams` accepted
/// on their own, and the accepted continuations of those (SeamCandidate::continues), which do
/// not count against `max_seams`. One flag per seam, in their order.
GT_API std::vector<bool> exported_seams(const std::vector<SeamCandidate>& seams, int max_seams);

}  // namespace groovetrace
