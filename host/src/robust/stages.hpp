#pragma once
// The robust method's stages (internal; docs/method-robust.md): detect_robust runs them in
// order, the tests and benches call them one by one. Frames and units as in
// groovetrace/robust.hpp: the cloud's frame, metres, angles in degrees.

#include <Eigen/Core>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <groovetrace/features.hpp>
#include <groovetrace/robust.hpp>
#include <string>
#include <vector>

namespace groovetrace {

// --- Stage 1: candidates ------------------------------------------------------------------

/// The cloud on voxels of `cell`, with the concavity of every voxel at radius `scale`.
struct CreaseMap {
  std::vector<Eigen::Vector3f> points;   ///< voxel centroids (m)
  std::vector<Eigen::Vector3f> normals;  ///< plane normal at `scale`, towards the viewpoint
  std::vector<float> concavity;          ///< m: upper envelope minus own height (> 0: concave)
  std::vector<std::int32_t> voxel;       ///< per input point: its voxel, -1 if invalid
  Eigen::Vector3f viewpoint{0, 0, 0};    ///< the cloud's viewpoint (m)
  double median = 0.0;                   ///< of concavity over voxels (m)
  double sigma = 0.0;                    ///< 1.4826 * MAD of concavity (m)
  double threshold = 0.0;                ///< candidate threshold (m)
};

/// Voxelizes `cloud` and measures, per voxel, how deep it lies in its neighbourhood: along the
/// plane normal (PCA of the voxels within `params.scale`), the 80th percentile of the
/// neighbours' heights minus the voxel's own height averaged within 0.3 `scale`. The threshold
/// is scale-free: median + threshold_k * 1.4826 MAD of the measure over the whole cloud. The
/// per-voxel measure runs on `backend` (FeatureBackend::crease); without one, on the cpu.
CreaseMap crease_map(const Cloud& cloud, const RobustParams& params, FeatureBackend& backend);
CreaseMap crease_map(const Cloud& cloud, const RobustParams& params);

/// Sets `map.threshold` (m) from its median and sigma: median + params.threshold_k * sigma,
/// never below 1 % of params.scale.
void set_threshold(CreaseMap& map, const RobustParams& params);

/// The voxel centroids of `map` as an unorganized cloud (same frame, metres; the map's
/// viewpoint): what FeatureBackend::crease measures.
Cloud voxel_cloud(const CreaseMap& map);

/// Crease nodes: candidate voxels that are the deepest across the seam (non-maximum
/// suppression in a slab across the local seam direction).
struct CreaseNodes {
  std::vector<std::int32_t> voxel;       ///< index into CreaseMap::points
  std::vector<Eigen::Vector3d> tangent;  ///< unit seam direction from the candidates' spread
};
CreaseNodes crease_nodes(const CreaseMap& map, const RobustParams& params);

// --- Stage 2: cross-section fit -----------------------------------------------------------

/// A V fitted to a 2-D profile: u across the seam, v along the surface normal (out of the
/// workpiece), both in metres in the section's frame. Left is u < root.
struct VProfile {
  bool ok = false;
  std::string why;                    ///< why not ok
  Eigen::Vector2d root{0, 0};         ///< intersection of the two wall lines
  Eigen::Vector2d edge_left{0, 0};    ///< left wall meets the top surface
  Eigen::Vector2d edge_right{0, 0};   ///< right wall meets the top surface
  Eigen::Vector2d bisector{0, 1};     ///< unit bisector of the walls, out of the groove
  Eigen::Vector3d top{0, 0, 0};       ///< top surface v = top[0] + top[1] u + top[2] u^2
  double wall_left_deg = 0.0;         ///< left wall's inclination to the top surface at its edge
  double wall_right_deg = 0.0;        ///< same, right
  double opening_deg = 0.0;           ///< included angle between the walls
  double width = 0.0;                 ///< |edge_right - edge_left| (m)
  double depth = 0.0;                 ///< root below the top surface (m)
  double noise = 0.0;                 ///< robust sigma of the top's residuals (m)
  double rms = 0.0;                   ///< rms of the wall residuals (m)
  int top_left = 0, top_right = 0;    ///< top-surface points left and right of the groove
  int wall_left = 0, wall_right = 0;  ///< points that fitted each wall
  /// One wall returned (almost) nothing (seen at a grazing angle): that wall's edge is where the
  /// top surface ends, the V taken symmetric about the top normal through the opening.
  bool one_wall = false;
  /// With one_wall: the unseen side is square (its mirror image would have faced the sensor),
  /// the root at its foot - a single bevel seen along its square side.
  bool square_side = false;
  /// The right top side's height minus the left's above the root (m): plates set high-low.
  /// From the tops beyond the edges on a two-wall V that passed, else `outer_step`.
  double misalignment = 0.0;
  /// Two-wall V's that passed: the right top side's slope minus the left's beyond the edges
  /// (dv/du, NaN when a side is too short, and on every other fit). Plates set high-low are
  /// parallel, near 0.
  double top_bend = NAN;
  /// The right top side's height minus the left's from lines through each side's outer half of
  /// the window (m): the step a stepped fit holds when the seam holds none (VFit::step).
  double outer_step = 0.0;
  /// Two-wall V's: the root gap's width estimated from the points below the walls (m, 0 when
  /// none; v_profile.cpp, step 7). `root` stays the walls' intersection.
  double gap = 0.0;
  /// The share of the opening's points that lie inside the walls, away from the root (a floor;
  /// v_profile.cpp, in_walls).
  double inside = 0.0;
  /// A concave corner between two faces with no top (fit_corner_profile): a fillet or lap
  /// joint. Edges are the weld's leg ends on the faces, `top` the weld face between them.
  bool corner = false;
  /// With corner: one face ends inside the window, where a face parallel to the other begins
  /// (a lap's upper plate: its edge face, then its top).
  bool short_face = false;
};

/// What a seam's first pass knows about its groove, for the second pass's fits.
struct VFit {
  /// The walls dip alike: after the free fit, the walls are refitted with equal dips about
  /// the top normal through the root, so a poorly sampled wall (a grazing view puts two image
  /// rows on it) takes its slope from the other and only its offset from its own points.
  bool symmetric = false;
  /// A single bevel: the side whose wall is square to the top (-1 left, +1 right, 0 none). The
  /// V is refitted with that wall straight down from its edge to the root (in a profile
  /// levelled to its top), and where that side is hidden, its foot is the root.
  int square = 0;
  /// The plates are set high-low: the two top sides are fitted with one slope and each its own
  /// height (their step held, see `step`), so the step does not tilt the top normal or move the
  /// edges. Not with `symmetric`.
  bool stepped = false;
  /// With `stepped`: the seam's step held at every station, right top side minus left (m), the
  /// median of the first pass's stations; NaN: each station's own (its outer half's lines).
  /// One station's step swings by 1-3 mm with the undulation under each side (a 1.5 mm
  /// high-low at 0.45 m, 640x480); held per station it turned the top normal by 3-5 deg this
  /// way and that along the seam.
  double step = NAN;
  /// The seam has a root gap (its first pass's median gap is above 0): where a station's
  /// slot shows, the V is refitted without the slot's points (v_profile.cpp, step 7). Only
  /// then: on a seam without a gap, a station's few stray deep points are noise.
  bool root_gap = false;
  /// The weld's leg on a corner joint (fillet or lap), m: where the V fails, a concave corner
  /// is fitted instead and its opening is the weld face between the legs' ends.
  double corner_leg = 0.007;
  /// Which models are fitted: a V and, where it fails, a corner (`any`: a node not yet on a
  /// seam), or only the kind of the seam being traced.
  enum class Kind { any, groove, corner };
  Kind kind = Kind::any;
};

/// Fits a V-groove to profile points within |u| <= half_window: the top surface as a robust
/// quadratic (so pipes work), then the whole V - root, both edges, the top's offset and slope -
/// by a Tukey-weighted Gauss-Newton fit to the points' orthogonal distances, started from the
/// run of points clearly below the top; edges are where the walls meet the top. `ok` only when
/// the profile is a V: both walls inclined into the material, both top sides present, depth
/// above the noise. Rims and root, which sensors round off, do not enter the fit. With one wall
/// seen and the other at a grazing angle, the V is taken symmetric (VProfile::one_wall).
/// `mode`: see VFit. `view`: unit direction towards the sensor in profile coordinates (it tells a
/// wall hidden at a grazing angle from a square side that cannot be seen).
VProfile fit_v_profile(const std::vector<Eigen::Vector2d>& uv, double half_window, VFit mode = {},
                       const Eigen::Vector2d& view = Eigen::Vector2d(0, 1));

/// Fits a concave corner (fillet or lap joint) to profile points within |u| <= half_window:
/// two straight faces meeting at the root, each at least `leg` (m) long, 60-120 deg apart,
/// open towards `view` (unit, towards the sensor), with no top surface or other face in the
/// window. Edges at `leg` from the root along each face; bisector between the faces.
VProfile fit_corner_profile(const std::vector<Eigen::Vector2d>& uv, double half_window, double leg,
                            const Eigen::Vector2d& view);

/// Fits the section at `origin` across `tangent`, taking the points of `cloud` within
/// `slab` (m) of the plane through origin normal to the tangent and within `half_window` (m)
/// of origin across it. `normal_hint` orients the profile (towards the viewpoint).
/// `mode` as in fit_v_profile; the view towards the sensor comes from cloud.viewpoint.
GrooveSection fit_section(const Cloud& cloud, const std::vector<std::uint32_t>& candidates,
                          const Eigen::Vector3d& origin, const Eigen::Vector3d& tangent,
                          const Eigen::Vector3d& normal_hint, double slab, double half_window,
                          VFit mode = {});

/// Where the walls return nothing (seen at a grazing angle) a groove still shows as a gap in
/// the top surface. Fits that instead of a V: both sides carry top surface, the gap nearest
/// the centre holds no point and is 0.6-1.6 times `width` (m) wide. The section has
/// `inferred` set, `ok` false, the root `depth` (m) below the gap's centre, edges at the
/// gap's centre +- width / 2, bisector = top normal.
GrooveSection fit_gap_section(const Cloud& cloud, const std::vector<std::uint32_t>& candidates,
                              const Eigen::Vector3d& origin, const Eigen::Vector3d& tangent,
                              const Eigen::Vector3d& normal_hint, double slab, double half_window,
                              double width, double depth);

// --- Stage 3: seams as ordered curves -----------------------------------------------------

/// One ordered chain of nodes.
struct NodePath {
  std::vector<int> nodes;  ///< indices into the input, in order along the seam
  bool closed = false;     ///< the ends meet: a ring
};

/// Orders scattered seam nodes into curves: nodes within `link` (m) are joined when the link
/// runs roughly along a node's tangent; the minimum spanning tree of each connected part is
/// walked along its longest path (the tree's diameter), so L-corners and S-curves come out in
/// order; the nodes near a path are then removed and the rest searched again for further
/// seams (branches). Paths with fewer than `min_nodes` nodes are dropped. A path whose ends
/// are within `link` of each other and which is long against `link` is closed.
std::vector<NodePath> order_nodes(const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector3d>& tangents, double link,
                                  std::size_t min_nodes);

/// Smooths an ordered polyline by local quadratic fits over 3 `half_window` (m) of arc length,
/// keeping sharp corners as corners, and resamples it every `spacing` (m). A corner is a turn
/// of over 45 degrees between the chords 3 half_window before and after a point, measured in
/// the surface (the plane normal to `normals`, one per point, when given: depth noise of the
/// roots must not look like a corner), kept at its maximum within 6 half_window, and held by
/// the lines fitted over 6 half_window on either side.
SeamCurve smooth_curve(const std::vector<Eigen::Vector3d>& ordered, bool closed, double half_window,
                       double spacing, const std::vector<Eigen::Vector3d>& normals = {});

// --- Stage 4: seam candidates, scores, region ---------------------------------------------

/// A single bevel's square side among a groove seam's sections: -1 left, +1 right, 0 when the
/// seam is a V (its passing sections' steeper wall, in the median, dips 75 deg or more and
/// 20 deg more than the other; the side is the one steeper in most of them).
int bevel_square_side(const std::vector<GrooveSection>& sections);

/// Scores a candidate and decides whether it is a V-groove seam (fills score, accepted,
/// reason and the medians).
void score_seam(SeamCandidate& seam, const RobustParams& params);

/// score_seam's reason for a seam that is a groove in every respect but its length.
inline constexpr const char* kTooShort = "shorter than min_length";

/// Labels groove points: a point is groove when its viewing ray (from cloud.viewpoint) passes
/// through the opening of an accepted seam (between the two fitted top edges of the nearest
/// sections) and the point lies at or below that opening. Returns 1/0 per point.
std::vector<std::uint8_t> label_grooves(const Cloud& cloud,
                                        const std::vector<SeamCandidate>& seams);

}  // namespace groovetrace
