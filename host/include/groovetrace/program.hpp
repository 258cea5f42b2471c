#pragma once
// What every robot program writer takes: the passes of a weld, in the order they are welded.

#include <groovetrace/trajectory.hpp>
#include <string>
#include <vector>

namespace groovetrace {

/// One pass of the torch along a seam: its name ("seam" for a single pass; "root", "fill K"
/// and "cap K" from multi-pass planning) and its poses (metres, in the path's frame).
struct WeldPass {
  std::string name;
  Trajectory path;
};

}  // namespace groovetrace
