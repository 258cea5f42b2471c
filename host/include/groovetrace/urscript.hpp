#pragma once
// The robot program: URScript for a Universal Robots controller (program.hpp has the
// multi-pass form and the other controllers).

#include <groovetrace/params.hpp>
#include <groovetrace/program.hpp>
#include <groovetrace/trajectory.hpp>
#include <string>

namespace groovetrace {

/// URScript program `def weld_seam(): ... end` for one pass: move above the first waypoint
/// (offset params.approach_offset along -tool z), down to it, arc on
/// (set_standard_digital_out(params.arc_output, True)), `movep` through the waypoints at
/// params.weld_speed with blend radius blend_radius_at(...) (0 at the last), arc off, retreat
/// along -tool z. Poses are the trajectory's positions (m) and rotation vectors (rad) in its
/// frame (meant to be the robot base). The same as urscript_program({{"seam", trajectory}}).
GT_API std::string urscript_program(const Trajectory& trajectory, const ProgramParams& params);

}  // namespace groovetrace
