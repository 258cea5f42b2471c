#pragma once
// What the program writers share (program.hpp): number text that does not depend on the locale,
// the approach and retreat poses, the checks of a pass list, and pass names made safe for
// strings and comments of any controller.

#include <Eigen/Core>
#include <groovetrace/program.hpp>
#include <string>
#include <vector>

namespace groovetrace::robot {

/// Fixed-point text with `decimals` digits (std::to_chars: no locale); a value that rounds to
/// zero prints without a sign, so -1e-17 and +1e-17 give the same program.
std::string fixed(double v, int decimals = 6);

/// The waypoint's position backed off by `offset` (m) along -tool z: the approach and
/// retreat point above it (metres, the path's frame).
Eigen::Vector3d backed_off(const Waypoint& waypoint, double offset);

/// Throws NoGrooveError for no pass or a pass without waypoints, InternalError for a pose
/// that is not finite or passes in different frames. Returns the frame of the passes.
std::string check_passes(const std::vector<WeldPass>& passes);

/// The waypoints of all passes together.
std::size_t total_waypoints(const std::vector<WeldPass>& passes);

/// A pass name for a string or a comment of any controller: letters, digits and " _-.,:+/()"
/// kept, any other byte '_', at most 40 characters; "pass" when empty.
std::string safe_name(const std::string& name);

/// "pass K of N: NAME" for pass index k (from 0).
std::string pass_title(const std::vector<WeldPass>& passes, std::size_t k);

}  // namespace groovetrace::robot
