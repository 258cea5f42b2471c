#include <charconv>
#include <cstdio>
#include <groovetrace/config.hpp>
#include <groovetrace/trajectory_io.hpp>
#include <groovetrace/version.hpp>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace groovetrace {

std::string trajectory_csv(const Trajectory& trajectory) {
  std::string out = "idx,x_m,y_m,z_m,qx,qy,qz,qw,rx,ry,rz\n";
  char line[512];
  for (std::size_t i = 0; i < trajectory.waypoints.size(); ++i) {
    const Waypoint& w = trajectory.waypoints[i];
    const Eigen::Quaterniond& q = w.orientation;
    std::snprintf(line, sizeof line, "%zu,%.7f,%.7f,%.7f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f\n", i,
                  w.position.x(), w.position.y(), w.position.z(), q.x(), q.y(), q.z(), q.w(),
                  w.rotation_vector.x(), w.rotation_vector.y(), w.rotation_vector.z());
    out += line;
  }
  return out;
}

namespace {

std::string tool_frame_text(Method method) {
  const char* z = method == Method::robust ? "-bisector of the two fitted walls"
                                           : "-mean surface normal of the slice";
  return std::string("z along the torch into the workpiece (") + z +
         "), x along the travel direction, y = z cross x";
}

}  // namespace

std::string trajectory_json(const Trajectory& trajectory, const Params& params) {
  using nlohmann::json;
  auto vec = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  json waypoints = json::array();
  for (std::size_t i = 0; i < trajectory.waypoints.size(); ++i) {
    const Waypoint& w = trajectory.waypoints[i];
    const Eigen::Quaterniond& q = w.orientation;
    waypoints.push_back({{"idx", i},
                         {"position_m", vec(w.position)},
                         {"quaternion_xyzw", json::array({q.x(), q.y(), q.z(), q.w()})},
                         {"rotation_vector_rad", vec(w.rotation_vector)},
                         {"euler_zyx_deg", vec(w.euler_zyx_deg)},
                         {"support", w.support}});
  }
  json doc = {
      {"version", version()},
      {"frame", trajectory.frame},
      {"units", {{"position", "m"}, {"rotation_vector", "rad"}, {"euler", "deg"}}},
      {"tool_frame", tool_frame_text(params.method)},
      {"euler_convention", "euler_zyx_deg = [yaw, pitch, roll], R = Rz(yaw) Ry(pitch) Rx(roll)"},
      {"direction", vec(trajectory.direction)},
      {"length_m", trajectory.length},
      {"parameters", json::parse(params_json(params))},
      {"waypoints", waypoints}};
  return doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

namespace {

// 0.4, -0.1, 1.0: up to 9 decimals, trailing zeros dropped but one kept; no sign on zero.
std::string ros_float(double v) {
  char buffer[512];  // any double: at most 309 digits before the point
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, v, std::chars_format::fixed, 9);
  if (end.ec != std::errc()) throw std::length_error("trajectory_ros_yaml: number too long");
  std::string text(buffer, end.ptr);
  if (text.find_first_not_of("-0.") == std::string::npos) return "0.0";
  text.erase(text.find_last_not_of('0') + 1);
  if (text.back() == '.') text += '0';
  return text;
}

// A std_msgs/Header at `indent`: stamp zero (a path has no capture time here) and the frame.
std::string ros_header(const std::string& indent, const std::string& frame) {
  return indent + "header:\n" + indent + "  stamp:\n" + indent + "    sec: 0\n" + indent +
         "    nanosec: 0\n" + indent + "  frame_id: " + frame + "\n";
}

}  // namespace

std::string trajectory_ros_yaml(const Trajectory& trajectory) {
  // "base" and "camera" are plain YAML scalars; any other name is quoted (a JSON string is a
  // YAML double-quoted scalar).
  const std::string& f = trajectory.frame;
  const bool plain =
      !f.empty() && f.find_first_not_of(
                        "abcdefghijklmnopqrstuvwxyz"
                        "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_/") == std::string::npos;
  const std::string frame =
      plain ? f : nlohmann::json(f).dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
  std::string out = ros_header("", frame) + "poses:";
  if (trajectory.waypoints.empty()) return out + " []\n";
  out += "\n";
  for (const Waypoint& w : trajectory.waypoints) {
    const Eigen::Quaterniond q = w.orientation.normalized();
    out += "- " + ros_header("  ", frame).substr(2);
    out += "  pose:\n    position:\n";
    out += "      x: " + ros_float(w.position.x()) + "\n";
    out += "      y: " + ros_float(w.position.y()) + "\n";
    out += "      z: " + ros_float(w.position.z()) + "\n";
    out += "    orientation:\n";
    out += "      x: " + ros_float(q.x()) + "\n";
    out += "      y: " + ros_float(q.y()) + "\n";
    out += "      z: " + ros_float(q.z()) + "\n";
    out += "      w: " + ros_float(q.w()) + "\n";
  }
  return out;
}

}  // namespace groovetrace
