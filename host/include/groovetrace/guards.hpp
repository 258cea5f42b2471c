#pragma once
// Checks on a robot program's poses before it is written (docs/robot.md, "Guards"). A
// violation throws UnsafeProgramError (exit 7), so no program is written.

#include <Eigen/Geometry>
#include <groovetrace/export.hpp>
#include <groovetrace/params.hpp>
#include <groovetrace/program.hpp>
#include <vector>

namespace groovetrace {

/// Checks every pass of a program, approach and retreat poses included (approach_offset along
/// -tool z from each pass's ends): every pose finite; consecutive poses of a pass at most
/// guards.max_step apart (m) and turning by at most guards.max_step_rotation (deg); the tool z
/// axis pointing into the part, away from `viewpoint` (the sensor's origin in the passes'
/// frame, m): z . (p - viewpoint) > 0; with guards.workspace, every pose inside that box (the
/// passes must then be in the base frame). Throws UnsafeProgramError naming the pass, the pose
/// and the limit.
GT_API void check_program(const std::vector<WeldPass>& passes, const GuardParams& guards,
                          const ProgramParams& program, const Eigen::Vector3d& viewpoint);

}  // namespace groovetrace
