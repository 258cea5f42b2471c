#pragma once
// What the steps of detect_robust after the candidates share (internal): one detection's
// inputs and look-up structures, and the steps one file calls in another. Frames and units as
// in groovetrace/robust.hpp: the cloud's frame, metres.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/neighbor_grid.hpp"
#include "robust/bins.hpp"
#include "robust/stages.hpp"

namespace groovetrace::robust_detail {

/// One detection's inputs and look-up structures, built once by detect_robust.
struct Context {
  const Cloud& cloud;
  const RobustParams& params;
  const CreaseMap& map;
  NeighborGrid voxel_grid;  ///< the map's voxel centroids, cells of params.scale
  BoxBins bins;             ///< the cloud's points, for the sections' balls
  double half_window;       ///< half-width of a cross-section's window (m)
};

// --- surface.cpp ----------------------------------------------------------------------------

/// `tangent` (unit) laid into the top surface at p, whose normal is taken from the voxels beside
/// the groove; `normal` is the fallback and orientation of that normal. `curved`: the seam
/// bends out of its surface (a pipe), whose normal at p is then that of a curved surface fitted
/// to those voxels, not their plane's.
Eigen::Vector3d surface_tangent(const Context& ctx, const Eigen::Vector3d& p,
                                const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal,
                                bool curved = false);

/// Whether the surface with `normal` at p is seen at a slant from the viewpoint (where a gap in
/// it may stand for a groove whose walls the sensor cannot see).
bool grazing(const Context& ctx, const Eigen::Vector3d& p, const Eigen::Vector3d& normal);

// --- trace.cpp ------------------------------------------------------------------------------

/// Fits the section at `origin` (m) across `tangent` laid into the surface, the profile taken
/// within `slab` (m) along it and oriented by `normal`; `scratch` holds the ball's points.
/// `mode` as in fit_v_profile; `curved` as in surface_tangent.
GrooveSection section_at(const Context& ctx, const Eigen::Vector3d& origin,
                         const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal, double slab,
                         std::vector<std::uint32_t>& scratch, VFit mode = {}, bool curved = false);

/// Traces one seam along its ordered node roots (m) with their surface normals: sections
/// fitted at stations along it, twice, smoothed along it, and its ends extended and trimmed.
/// `corner`: the nodes are a corner joint's (fillet, lap), fitted with the corner model only.
SeamCandidate trace_seam(const Context& ctx, std::vector<Eigen::Vector3d> ordered,
                         std::vector<Eigen::Vector3d> normals, bool closed, bool corner);

/// Where an open seam continues `steps` stations (params.station) past the last of `secs`, on
/// the line through its last ok roots (m), and that line's unit direction, outwards. False
/// with too few roots to tell.
bool continue_seam(const Context& ctx, const std::vector<GrooveSection>& secs, int steps,
                   Eigen::Vector3d& at, Eigen::Vector3d& tangent);

/// The seam's length, arc lengths and corners measured along its sections' roots (m).
void measure_along_roots(SeamCandidate& seam, bool closed);

// --- seam_ends.cpp --------------------------------------------------------------------------

/// Extends an open groove seam (V or bevel) at both ends, one station at a time along the line
/// through its last roots, while a slab across it there still holds the groove and the top surface
/// on both sides of it as the end section's does (up to params.scale), and measures it again.
/// The added sections are not `ok` (no fit was made there); called once the seam is scored.
void extend_to_groove_ends(const Context& ctx, SeamCandidate& seam);

// --- section_smoothing.cpp ------------------------------------------------------------------

/// The sections `raw` fitted at the stations of `curve`, smoothed along the seam over the
/// half-window `h` (m); stations without a fit within reach are dropped.
std::vector<GrooveSection> smooth_sections(const std::vector<GrooveSection>& raw,
                                           const SeamCurve& curve, double h);

// --- merge.cpp ------------------------------------------------------------------------------

/// The gap (m) between two open seams that continue each other across it (each end's
/// direction points at the other end within 30 deg), or infinity.
double collinear_gap(const SeamCandidate& a, const SeamCandidate& b);

/// Accepts the seams of one scale's search (at `scale`, m) rejected only for their length
/// (kTooShort) that continue an accepted groove seam beyond one of its open ends, past a
/// clamp standing on the groove: in its line, within 10 scales of the end, of its width and
/// depth. They stay seams of their own.
void accept_continuations(std::vector<SeamCandidate>& seams, double scale);

/// Joins seams that are stretches of one (overlapping, touching or continuing each other
/// across a gap of up to 3 `link`, m) and traces the joined ones again.
void merge_seams(const Context& ctx, std::vector<SeamCandidate>& seams, double link);

/// The seams of every scale's search, ranked best first, without the ones that repeat a better
/// seam: a seam is dropped when half or more of its root line runs within the groove (half its
/// width, at least 3 mm) of a seam kept before it, or when it reads only the bottom of a wider,
/// better scored groove found at a coarser scale. Order kept. A repeat that reads the kept
/// seam's groove half as long again, over all of it, and `fits_scale`, takes its place.
std::vector<SeamCandidate> drop_duplicate_scales(std::vector<SeamCandidate> ranked,
                                                 bool (*fits_scale)(const SeamCandidate&));

// --- support.cpp ----------------------------------------------------------------------------

/// A plane: a point on it (m) and its unit normal, towards the viewpoint.
struct SupportPlane {
  Eigen::Vector3d point, normal;
};

/// The table the workpiece stands on, if seen: of the planes through the voxels of `map` (each
/// with its own normal, refitted to the voxels within 2 mm) that hold at least 15 % of them and
/// have at most 2 % behind them, the one holding the most.
std::optional<SupportPlane> support_plane(const CreaseMap& map);

/// Corner roots this near the support plane (m) are a part's foot on the table.
constexpr double kFootHeight = 0.003;

/// Unaccepts the fillet and lap seams most of whose roots lie within kFootHeight of `plane`.
void reject_corners_on(const SupportPlane& plane, std::vector<SeamCandidate>& seams);

/// The same against the support_plane of `map`, looked for only when an accepted corner seam
/// is among `seams`.
void reject_corners_on_table(const CreaseMap& map, std::vector<SeamCandidate>& seams);

}  // namespace groovetrace::robust_detail
