#pragma once
// Robot programs for every controller (docs/robot.md, "Controllers and program files"): one
// interface, a list of weld passes in weld order, written as URScript (ur), ABB RAPID (abb)
// or KUKA KRL (kuka).
//
// Every program welds each pass the same way: move above its first waypoint (approach_offset
// along -tool z), down to it, arc on, along the pass at weld_speed with capped blends, arc off,
// retreat along -tool z; then the next pass. Poses are the passes' poses in their frame (meant to
// be the robot base; a program in the camera frame says so in a comment).

#include <groovetrace/params.hpp>
#include <groovetrace/trajectory.hpp>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace {

/// One pass of a weld: a name for the operator ("root", "fill 1", "cap"; a single-pass weld is
/// one pass named "seam" or "root") and its torch path (metres, in path.frame).
struct WeldPass {
  std::string name;
  Trajectory path;
};

/// The blend radius (m) at waypoint i of a pass: min(requested, 0.4 * the shorter neighbouring
/// segment), 0 at both ends (the robot stops there). Neighbouring blends never overlap.
GT_API double blend_radius_at(const Trajectory& trajectory, std::size_t i, double requested);

/// Throws UsageError when a program setting is out of range for params.robot: speeds and
/// acceleration positive, offsets and blend radius not negative, and arc_output a valid
/// output (ur: standard digital output 0..7; kuka: $OUT[1..4096]; abb: 0..4096, naming the
/// signal doArcN).
GT_API void check_program_params(const ProgramParams& params);

/// URScript `def weld_seam(): ... end` (metres, rotation vectors in radians). A single pass
/// that is no dry run gives the same text as urscript_program(trajectory, params).
GT_API std::string urscript_program(const std::vector<WeldPass>& passes,
                                    const ProgramParams& params);

/// ABB RAPID module `MODULE name ... ENDMODULE` with the routine `PROC weld_<name>()`:
/// robtargets in mm with quaternions [q1, q2, q3, q4] = [w, x, y, z], robconf [0, 0, 0, 0],
/// external axes 9E9; tool tWeldGun, work object wobj0, arc signal doArcN (N = arc_output),
/// none of them declared in the module (docs/robot.md, "ABB RAPID").
GT_API std::string rapid_module(const std::vector<WeldPass>& passes, const ProgramParams& params,
                                const std::string& name);

/// KUKA KRL program: `name.src` (DEF name()) and `name.dat` (DEFDAT name, the E6POS points:
/// X, Y, Z in mm; A, B, C in degrees, R = Rz(A) Ry(B) Rx(C)). The KRL tool frame has X along
/// the torch (KUKA's tool direction): it is the path's tool frame turned -90 deg about its y
/// axis (docs/robot.md, "KUKA KRL").
struct KrlProgram {
  std::string src, dat;
};
GT_API KrlProgram krl_program(const std::vector<WeldPass>& passes, const ProgramParams& params,
                              const std::string& name);

/// The program files of params.robot for one seam, named from `stem` ("program",
/// "program_1"): ur: stem.script; abb: stem.mod; kuka: stem.src and stem.dat. Throws
/// UsageError for bad settings (check_program_params), NoGrooveError for no waypoints.
GT_API std::vector<std::pair<std::string, std::string>> program_files(
    const std::vector<WeldPass>& passes, const ProgramParams& params, const std::string& stem);

}  // namespace groovetrace
