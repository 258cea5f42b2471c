// Calibration transforms from YAML/JSON files, and moving a trajectory between frames.
// File format and conventions: docs/frames.md.

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <groovetrace/cloud.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/frames.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "io/text.hpp"

namespace groovetrace {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  std::string line = path + ": " + problem;
  // Parser messages may span lines; the CLI contract wants one line on stderr.
  std::replace_if(
      line.begin(), line.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  throw InputError(line);
}

// Regular files only (a FIFO hung the read), nested no deeper than the parsers can take.
std::string read_text(const std::string& path) {
  std::string text = io::read_all(path, true);
  io::require_shallow(text, path);
  return text;
}

std::string format_number(double v) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << v;
  return s.str();
}

void check_finite(const std::string& path, const char* key, std::size_t i, double v) {
  if (!std::isfinite(v)) {
    fail(path,
         std::string(key) + "[" + std::to_string(i) + "] is not finite (" + format_number(v) + ")");
  }
}

std::string wrong_length(const char* key, std::size_t got, std::size_t expected) {
  return std::string("field '") + key + "' has " + std::to_string(got) + " values, expected " +
         std::to_string(expected);
}

std::vector<double> yaml_numbers(const std::string& path, const YAML::Node& root, const char* key,
                                 std::size_t expected) {
  const YAML::Node node = root[key];
  if (!node.IsDefined() || node.IsNull()) fail(path, std::string("missing field '") + key + "'");
  if (!node.IsSequence()) {
    fail(path, std::string("field '") + key + "' must be a list of " + std::to_string(expected) +
                   " numbers");
  }
  if (node.size() != expected) fail(path, wrong_length(key, node.size(), expected));
  std::vector<double> values(expected);
  for (std::size_t i = 0; i < expected; ++i) {
    const YAML::Node item = node[i];
    const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
    if (!item.IsScalar()) fail(path, where + " is not a number");
    try {
      values[i] = item.as<double>();
    } catch (const YAML::Exception&) {
      fail(path, where + " is not a number ('" + item.Scalar() + "')");
    }
    check_finite(path, key, i, values[i]);
  }
  return values;
}

std::vector<double> json_numbers(const std::string& path, const nlohmann::json& root,
                                 const char* key, std::size_t expected) {
  const auto it = root.find(key);
  if (it == root.end() || it->is_null()) fail(path, std::string("missing field '") + key + "'");
  if (!it->is_array()) {
    fail(path, std::string("field '") + key + "' must be a list of " + std::to_string(expected) +
                   " numbers");
  }
  if (it->size() != expected) fail(path, wrong_length(key, it->size(), expected));
  std::vector<double> values(expected);
  for (std::size_t i = 0; i < expected; ++i) {
    const nlohmann::json& item = (*it)[i];
    if (!item.is_number()) {
      fail(path,
           std::string(key) + "[" + std::to_string(i) + "] is not a number (" + item.dump() + ")");
    }
    values[i] = item.get<double>();
    check_finite(path, key, i, values[i]);
  }
  return values;
}

}  // namespace

Eigen::Isometry3d read_transform(const std::string& path) {
  const std::string ext = io::lower_extension(path);
  const bool yaml = ext == ".yaml" || ext == ".yml";
  if (!yaml && ext != ".json") {
    fail(path, (ext.empty() ? std::string("transform file has no extension")
                            : "unknown transform file type '" + ext + "'") +
                   " (expected .yaml, .yml or .json)");
  }
  const std::string text = read_text(path);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) fail(path, "file is empty");

  std::vector<double> t, q;
  if (yaml) {
    YAML::Node root;
    try {
      root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
      fail(path, std::string("YAML parse error: ") + e.what());
    }
    if (!root.IsMap()) fail(path, "expected a mapping with 'translation' and 'rotation'");
    t = yaml_numbers(path, root, "translation", 3);
    q = yaml_numbers(path, root, "rotation", 4);
  } else {
    nlohmann::json root;
    try {
      root = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
      fail(path, std::string("JSON parse error: ") + e.what());
    }
    if (!root.is_object()) fail(path, "expected an object with 'translation' and 'rotation'");
    t = json_numbers(path, root, "translation", 3);
    q = json_numbers(path, root, "rotation", 4);
  }

  // A robot cell is metres across: a translation beyond kMaxCoordinate is a wrong unit or a
  // corrupt file (1e300 m ran the whole scan and failed in the URScript writer, exit 5).
  for (std::size_t i = 0; i < 3; ++i) {
    if (std::abs(t[i]) > kMaxCoordinate) {
      fail(path, "translation[" + std::to_string(i) + "] is " + format_number(t[i]) +
                     " m, beyond the " + format_number(kMaxCoordinate) + " m a cell can hold");
    }
  }
  // File order is x, y, z, w (ROS); Eigen's constructor takes w first.
  Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
  const double norm = rotation.norm();
  if (!(std::abs(norm - 1.0) <= 1e-3)) {
    fail(path, "rotation quaternion is not unit (norm " + format_number(norm) + ")");
  }
  rotation.normalize();

  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation.toRotationMatrix();
  T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return T;
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
