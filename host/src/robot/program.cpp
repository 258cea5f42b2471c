// The program interface (program.hpp): settings checks, the helpers every writer shares, and
// the choice of writer and file names by --robot.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <groovetrace/error.hpp>
#include <groovetrace/program.hpp>
#include <groovetrace/urscript.hpp>

#include "robot/program_text.hpp"

namespace groovetrace {

namespace robot {

std::string fixed(double v, int decimals) {
  char buffer[64];
  const auto result =
      std::to_chars(buffer, buffer + sizeof(buffer), v, std::chars_format::fixed, decimals);
  if (result.ec != std::errc()) throw InternalError("program: cannot format a number");
  std::string text(buffer, result.ptr);
  if (text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos) text.erase(0, 1);
  return text;
}

Eigen::Vector3d backed_off(const Waypoint& waypoint, double offset) {
  const Eigen::Vector3d tool_z = waypoint.orientation.normalized() * Eigen::Vector3d::UnitZ();
  return waypoint.position - offset * tool_z;
}

std::string check_passes(const std::vector<WeldPass>& passes) {
  if (passes.empty()) throw NoGrooveError("no weld pass: nothing to weld");
  for (const WeldPass& pass : passes) {
    if (pass.path.waypoints.empty()) throw NoGrooveError("no waypoints: nothing to weld");
    if (pass.path.frame != passes.front().path.frame) {
      throw InternalError("program: the passes are in different frames");
    }
    for (const Waypoint& w : pass.path.waypoints) {
      if (!w.position.allFinite() || !w.rotation_vector.allFinite() ||
          !w.orientation.coeffs().allFinite() || w.orientation.norm() < 0.5) {
        throw InternalError("program: a waypoint pose is not finite");
      }
    }
  }
  return passes.front().path.frame;
}

std::size_t total_waypoints(const std::vector<WeldPass>& passes) {
  std::size_t n = 0;
  for (const WeldPass& pass : passes) n += pass.path.waypoints.size();
  return n;
}

std::string safe_name(const std::string& name) {
  static const std::string kKept = " _-.,:+/()";
  std::string out;
  for (const char c : name.substr(0, 40)) {
    const bool alnum = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    out += alnum || kKept.find(c) != std::string::npos ? c : '_';
  }
  return out.empty() ? "pass" : out;
}

std::string pass_title(const std::vector<WeldPass>& passes, std::size_t k) {
  return "pass " + std::to_string(k + 1) + " of " + std::to_string(passes.size()) + ": " +
         safe_name(passes[k].name);
}

}  // namespace robot

double blend_radius_at(const Trajectory& trajectory, std::size_t i, double requested) {
  const auto& w = trajectory.waypoints;
  if (i >= w.size()) throw std::out_of_range("blend_radius_at: waypoint index out of range");
  // The robot stops exactly at both ends of the seam.
  if (i == 0 || i + 1 == w.size()) return 0.0;
  const double before = (w[i].position - w[i - 1].position).norm();
  const double after = (w[i + 1].position - w[i].position).norm();
  // 0.4 leaves a gap between the blends of neighbouring waypoints (0.4 + 0.4 < 1 of any
  // segment): overlapping blends make the UR controller stop the program.
  return std::max(0.0, std::min(requested, 0.4 * std::min(before, after)));
}

void check_program_params(const ProgramParams& p) {
  using robot::fixed;
  auto positive = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0)) {
      throw UsageError(std::string(name) + " must be positive (got " + fixed(v) + ")");
    }
  };
  auto non_negative = [](double v, const char* name) {
    if (!(std::isfinite(v) && v >= 0.0)) {
      throw UsageError(std::string(name) + " must not be negative (got " + fixed(v) + ")");
    }
  };
  positive(p.approach_speed, "approach_speed");
  positive(p.weld_speed, "weld_speed");
  positive(p.acceleration, "acceleration");
  non_negative(p.approach_offset, "approach_offset");
  non_negative(p.blend_radius, "blend_radius");
  non_negative(p.arc_delay, "arc_delay");
  const std::string got = " (got " + std::to_string(p.arc_output) + ")";
  switch (p.robot) {
    case Robot::ur:  // UR controllers have standard digital outputs 0..7.
      if (p.arc_output < 0 || p.arc_output > 7) {
        throw UsageError("arc_output must be a standard digital output 0..7" + got);
      }
      break;
    case Robot::kuka:  // $OUT[1] is the first output: 0 is no output at all.
      if (p.arc_output < 1 || p.arc_output > 4096) {
        throw UsageError("arc_output must be a KUKA output $OUT[1..4096]: give --arc-output N" +
                         got);
      }
      break;
    case Robot::abb:
      if (p.arc_output < 0 || p.arc_output > 4096) {
        throw UsageError("arc_output must be 0..4096, the N of the ABB signal doArcN" + got);
      }
      break;
  }
}

std::vector<std::pair<std::string, std::string>> program_files(const std::vector<WeldPass>& passes,
                                                               const ProgramParams& params,
                                                               const std::string& stem) {
  switch (params.robot) {
    case Robot::abb:
      return {{stem + ".mod", rapid_module(passes, params, stem)}};
    case Robot::kuka: {
      KrlProgram krl = krl_program(passes, params, stem);
      return {{stem + ".src", std::move(krl.src)}, {stem + ".dat", std::move(krl.dat)}};
    }
    case Robot::ur:
      break;
  }
  return {{stem + ".script", urscript_program(passes, params)}};
}

}  // namespace groovetrace
