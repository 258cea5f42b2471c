#pragma once
// Warnings for a detection that is implausible although it passed its method's own tests
// (docs/robot.md, "Warnings before welding").

#include <groovetrace/pipeline.hpp>
#include <string>
#include <vector>

namespace groovetrace {

/// Share of the valid points marked groove above which a detection is implausible: a weld
/// joint is a strip of a scan, not most of it.
constexpr double kMaxGrooveShare = 0.30;
/// Median distance (m) of the groove points from the path above which they do not lie along it,
/// unless the joint's fitted opening is wider.
constexpr double kMaxGrooveSpread = 0.015;

/// The warnings for `result` (trajectories in the cloud's frame, before any move into the
/// base): the share of groove points, their spread about the best path, a path longer than
/// twice the scan's extent.
std::vector<std::string> plausibility_warnings(const Cloud& cloud, const RunResult& result);

}  // namespace groovetrace
