#pragma once
// The picture of a run (overview.png), also as the batch report's thumbnail.

#include <groovetrace/pipeline.hpp>
#include <string>

namespace groovetrace {

/// The run drawn in the scan's frame (trajectories moved into the base are moved back) with
/// its caption (file, method, seams and lengths, status), as PNG bytes. `max_side`: the long
/// side in pixels, 0 for the picture's own size (picture::render_overview).
std::string run_overview_png(const Cloud& input, const RunResult& result, const Params& params,
                             const std::string& input_path, int max_side);

}  // namespace groovetrace
