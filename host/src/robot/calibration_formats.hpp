#pragma once
// The calibration file layouts of docs/frames.md, recognised by content.

#include <groovetrace/frames.hpp>
#include <string>

namespace groovetrace::calib {

/// The transform in `text` (a calibration file's bytes). `extension` (lower case, e.g.
/// ".json") only picks JSON over YAML for a tree. Throws io::Rejected with the reason; the
/// translation is not bounded here (read_calibration does that).
Calibration parse_calibration(const std::string& text, const std::string& extension);

}  // namespace groovetrace::calib
