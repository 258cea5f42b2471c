// Calibration transforms from files (the layouts: calibration_formats.cpp), and moving a
// trajectory between frames. Formats and conventions: docs/frames.md.

#include <algorithm>
#include <cmath>
#include <groovetrace/cloud.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/frames.hpp>

#include "io/text.hpp"
#include "robot/calibration_formats.hpp"
#include "robot/calibration_values.hpp"

namespace groovetrace {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  std::string line = io::shown(path) + ": " + problem;
  // Parser messages may span lines; the CLI contract wants one line on stderr.
  std::replace_if(
      line.begin(), line.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  throw InputError(line);
}

}  // namespace

Calibration read_calibration(const std::string& path) {
  // Regular files only (a FIFO hung the read), nested no deeper than the parsers can take.
  const std::string text = io::read_all(path, true);
  io::require_shallow(text, path);
  Calibration c;
  try {
    c = calib::parse_calibration(text, io::lower_extension(path));
  } catch (const io::Rejected& r) {
    fail(path, r.what);
  }
  // A robot cell is metres across: a translation beyond kMaxCoordinate is a wrong unit or a
  // corrupt file (1e300 m ran the whole scan and failed in the URScript writer, exit 5).
  const Eigen::Vector3d t = c.transform.translation();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(t[i]) > kMaxCoordinate) {
      fail(path, "translation[" + std::to_string(i) + "] is " + calib::format_number(t[i]) +
                     " m, beyond the " + calib::format_number(kMaxCoordinate) +
                     " m a cell can hold");
    }
  }
  return c;
}

Eigen::Isometry3d read_transform(const std::string& path) {
  return read_calibration(path).transform;
}

void transform_trajectory(Trajectory& trajectory, const Eigen::Isometry3d& T_base_camera) {
  const Eigen::Matrix3d R_base_camera = T_base_camera.linear();
  const Eigen::Quaterniond q_base_camera(R_base_camera);
  for (auto& w : trajectory.waypoints) {
    w.position = T_base_camera * w.position;
    w.orientation = (q_base_camera * w.orientation).normalized();
  }
  trajectory.direction = (R_base_camera * trajectory.direction).normalized();
  // Rotation vectors must be re-chosen for continuity in the new frame, not rotated.
  fill_rotation_representations(trajectory);
  trajectory.frame = "base";
}

}  // namespace groovetrace
