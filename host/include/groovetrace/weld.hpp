#pragma once
// What a welder sets around the torch path (docs/robot.md): torch angles, weaving and the
// passes of a multi-pass weld. Everything happens in each waypoint's tool frame (z along the
// torch into the part, x along travel, y = z x x); lengths in metres, angles in degrees.

#include <groovetrace/export.hpp>
#include <groovetrace/params.hpp>
#include <groovetrace/program.hpp>
#include <groovetrace/robust.hpp>
#include <string>
#include <vector>

namespace groovetrace {

/// The groove's cross-section at one waypoint, in its tool frame: the depth from the root to
/// the top (m) and how far each wall runs across per metre of height on the tool's +y and -y
/// sides (the tangent of the wall's angle to the tool axis; 0 for a square wall).
struct SectionShape {
  double depth = 0.0;
  double run_pos_y = 0.0, run_neg_y = 0.0;
  /// Width across the groove (m) at `height` (m) above the root.
  double width_at(double height) const { return (run_pos_y + run_neg_y) * height; }
};

/// One bead of a multi-pass plan, in the section it was planned for.
struct Bead {
  std::string name;         ///< "root", "fill K" or "cap K"
  int layer = 0;            ///< 0 = the root layer
  double height = 0.0;      ///< m above the root where the torch aims: the layer's base
  double mid_height = 0.0;  ///< m above the root: the layer's middle, where `lateral` is taken
  double lateral = 0.0;     ///< m along tool y from the root line, at mid_height
  double work_angle = 0.0;  ///< deg, added to WeldParams::work_angle: towards the bead's wall
};

/// The beads that fill a section, bottom layer first, each layer from +y to -y.
struct PassPlan {
  std::vector<Bead> beads;
  double section_area = 0.0;                   ///< m^2 between the walls from the root to the top
  double bead_area = 0.0;                      ///< m^2 per pass
  double bead_width = 0.0, bead_height = 0.0;  ///< m, of a flat parabolic bead 2.5 times wider
};

/// Plans the passes that fill `section` with beads of `bead_area` (m^2): layers whose area is
/// a whole number of beads, as many beads across as fit the layer's width, the last layer
/// (cap) across the whole top (docs/robot.md, "Multi-pass welds"). Throws UsageError for a
/// non-positive bead area or a section without depth or width.
GT_API PassPlan plan_passes(const SectionShape& section, double bead_area);

/// The groove's section at every waypoint of `path` (the seam's frame, before any move into
/// the base), from the seam's nearest fitted section; a section without a usable fit takes the
/// seam's median.
GT_API std::vector<SectionShape> section_shapes(const Trajectory& path, const SeamCandidate& seam);

/// Bead area (m^2) from the wire: its cross-section times wire feed over travel speed, unless
/// WeldParams::bead_area is set.
GT_API double bead_area(const WeldParams& weld, const ProgramParams& program);

/// The passes a program welds along `path`: one pass ("seam"), or with WeldParams::multi_pass
/// the planned beads, each offset from the root by its height and lateral scaled to the
/// waypoint's own section; then weaving and the torch angles. `shapes` are the path's sections
/// (section_shapes; empty: none fitted, so no multi-pass and an unbounded weave, with a
/// warning). Warnings (an amplitude cut to the opening...) are appended to `warnings`.
GT_API std::vector<WeldPass> weld_passes(const Trajectory& path,
                                         const std::vector<SectionShape>& shapes,
                                         const WeldParams& weld, const ProgramParams& program,
                                         std::vector<std::string>& warnings);

/// Tilts every pose's tool frame by the travel angle about its y and the work angle about its x
/// (deg): R' = R * Ry(travel) * Rx(work). Positions stay.
GT_API void apply_torch_angles(Trajectory& path, double travel_deg, double work_deg);

/// The path moved across the groove along each pose's tool y by a weave: "zigzag" (straight
/// legs to +-amplitude each half period), "sine" (16 poses per period) or "triangle" (per
/// period, straight across from +amplitude to -amplitude, then diagonally forward to
/// +amplitude). It starts and ends on the path. `max_amplitude[i]` (m; empty = none) bounds
/// the amplitude near waypoint i. Orientations are interpolated along the path.
GT_API Trajectory weave_path(const Trajectory& path, const std::string& pattern, double amplitude,
                             double wavelength, const std::vector<double>& max_amplitude);

}  // namespace groovetrace
