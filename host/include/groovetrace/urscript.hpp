#pragma once
// The robot program: URScript for a Universal Robots controller.

#include <groovetrace/params.hpp>
#include <groovetrace/trajectory.hpp>
#include <string>

namespace groovetrace {

/// URScript program `def weld_seam(): ... end`: move above the first waypoint (offset
/// params.approach_offset along -tool z), down to it, arc on
/// (set_standard_digital_out(params.arc_output, True)), `movep` through the waypoints at
/// params.weld_speed with blend radius min(params.blend_radius, 0.4 * shorter neighbouring
/// segment) (0 at the last), arc off, retreat along -tool z. Poses are the trajectory's
/// positions (m) and rotation vectors (rad) in its frame (meant to be the robot base).
GT_API std::string urscript_program(const Trajectory& trajectory, const ProgramParams& params);

/// Blend radius (m) at waypoint i, as described above.
GT_API double blend_radius_at(const Trajectory& trajectory, std::size_t i, double requested);

}  // namespace groovetrace
