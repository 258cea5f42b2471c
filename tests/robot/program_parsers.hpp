#pragma once
// Small readers of the generated robot programs, written for the tests from the controllers'
// conventions (docs/robot.md), not from the writers' code: each turns a program into the
// sequence of what the robot would do (moves with their poses, arc on/off, messages), in
// metres and rotation matrices of groovetrace's tool frame (z along the torch).

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace groovetrace::test {

struct ProgramEvent {
  enum Kind { kMove, kArcOn, kArcOff, kText } kind = kText;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  std::string text;  ///< kText: the message or comment; kMove: the instruction's line
};

inline std::vector<std::string> text_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream s(text);
  std::string line;
  while (std::getline(s, line)) lines.push_back(line);
  return lines;
}

inline std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(' ');
  return b == std::string::npos ? "" : s.substr(b, s.find_last_not_of(' ') - b + 1);
}

inline bool begins(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

/// The numbers in `s` separated by commas (C locale).
inline std::vector<double> numbers(const std::string& s) {
  std::vector<double> v;
  std::istringstream in(s);
  in.imbue(std::locale::classic());
  std::string item;
  while (std::getline(in, item, ',')) v.push_back(std::stod(item));
  return v;
}

inline Eigen::Matrix3d rot_x(double deg) {
  const double a = deg * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  return (Eigen::Matrix3d() << 1, 0, 0, 0, c, -s, 0, s, c).finished();
}
inline Eigen::Matrix3d rot_y(double deg) {
  const double a = deg * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  return (Eigen::Matrix3d() << c, 0, s, 0, 1, 0, -s, 0, c).finished();
}
inline Eigen::Matrix3d rot_z(double deg) {
  const double a = deg * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  return (Eigen::Matrix3d() << c, -s, 0, s, c, 0, 0, 0, 1).finished();
}

// --- URScript: p[x, y, z, rx, ry, rz] in m and a rotation vector (rad) -------------------
inline std::vector<ProgramEvent> parse_urscript(const std::string& program, int arc_output) {
  std::vector<ProgramEvent> events;
  const std::string on = "set_standard_digital_out(" + std::to_string(arc_output) + ", True)";
  const std::string off = "set_standard_digital_out(" + std::to_string(arc_output) + ", False)";
  for (const std::string& raw : text_lines(program)) {
    const std::string line = trimmed(raw);
    ProgramEvent e;
    if (begins(line, "movel(") || begins(line, "movep(")) {
      const auto open = line.find("p["), close = line.find(']');
      const std::vector<double> v = numbers(line.substr(open + 2, close - open - 2));
      if (v.size() != 6) throw std::runtime_error("UR pose without 6 numbers: " + line);
      e.kind = ProgramEvent::kMove;
      e.position = {v[0], v[1], v[2]};
      const Eigen::Vector3d r(v[3], v[4], v[5]);
      e.rotation = r.norm() < 1e-12 ? Eigen::Matrix3d::Identity()
                                    : Eigen::AngleAxisd(r.norm(), r.normalized()).matrix();
      e.text = line;
    } else if (line == on) {
      e.kind = ProgramEvent::kArcOn;
    } else if (line == off) {
      e.kind = ProgramEvent::kArcOff;
    } else if (begins(line, "textmsg(") || begins(line, "#")) {
      e.text = line;
    } else {
      continue;
    }
    events.push_back(e);
  }
  return events;
}

// --- ABB RAPID: robtargets [[x,y,z] mm,[q1,q2,q3,q4] = w,x,y,z,...] ----------------------
inline std::vector<ProgramEvent> parse_rapid(const std::string& module, int arc_output) {
  std::map<std::string, ProgramEvent> targets;
  std::vector<ProgramEvent> events;
  const std::string signal = "doArc" + std::to_string(arc_output);
  for (const std::string& raw : text_lines(module)) {
    const std::string line = trimmed(raw);
    if (line.find("CONST robtarget ") != std::string::npos) {
      const auto name_at = line.find("robtarget ") + 10;
      const std::string name = line.substr(name_at, line.find(' ', name_at) - name_at);
      const auto pos_at = line.find("[[") + 2;
      const std::vector<double> p = numbers(line.substr(pos_at, line.find(']', pos_at) - pos_at));
      const auto q_at = line.find("],[", pos_at) + 3;
      const std::vector<double> q = numbers(line.substr(q_at, line.find(']', q_at) - q_at));
      if (p.size() != 3 || q.size() != 4) throw std::runtime_error("bad robtarget: " + line);
      if (std::abs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1.0) > 1e-8) {
        throw std::runtime_error("quaternion not normalized: " + line);
      }
      ProgramEvent e;
      e.kind = ProgramEvent::kMove;
      e.position = Eigen::Vector3d(p[0], p[1], p[2]) / 1000.0;
      e.rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();  // w first
      targets[name] = e;
    } else if (begins(line, "MoveL ") || begins(line, "MoveJ ")) {
      const std::string name = line.substr(6, line.find(',') - 6);
      if (!targets.count(name)) throw std::runtime_error("move to an undeclared target: " + line);
      ProgramEvent e = targets[name];
      e.text = line;
      events.push_back(e);
    } else if (line == "SetDO " + signal + ", 1;") {
      events.push_back({ProgramEvent::kArcOn, {}, {}, line});
    } else if (line == "SetDO " + signal + ", 0;") {
      events.push_back({ProgramEvent::kArcOff, {}, {}, line});
    } else if (begins(line, "TPWrite ") || begins(line, "!")) {
      events.push_back({ProgramEvent::kText, {}, {}, line});
    }
  }
  return events;
}

// --- KUKA KRL: E6POS {X, Y, Z mm, A, B, C deg}, R = Rz(A) Ry(B) Rx(C); tool X = torch -----
/// The named value `key` (e.g. "X") of an E6POS aggregate "{X 1.0,Y 2.0,...}".
inline double krl_component(const std::string& aggregate, const std::string& key) {
  for (const std::string& part : text_lines([&] {
         std::string s = aggregate.substr(1, aggregate.size() - 2);
         for (char& c : s)
           if (c == ',') c = '\n';
         return s;
       }())) {
    const std::string p = trimmed(part);
    if (begins(p, key + " ")) return std::stod(p.substr(key.size() + 1));
  }
  throw std::runtime_error("E6POS without " + key + ": " + aggregate);
}

inline std::vector<ProgramEvent> parse_krl(const std::string& src, const std::string& dat,
                                           int arc_output) {
  std::map<std::string, ProgramEvent> points;
  for (const std::string& raw : text_lines(dat)) {
    const std::string line = trimmed(raw);
    if (!begins(line, "DECL E6POS ")) continue;
    const auto eq = line.find('=');
    const std::string name = line.substr(11, eq - 11);
    const std::string agg = line.substr(eq + 1);
    ProgramEvent e;
    e.kind = ProgramEvent::kMove;
    e.position =
        Eigen::Vector3d(krl_component(agg, "X"), krl_component(agg, "Y"), krl_component(agg, "Z")) /
        1000.0;
    const Eigen::Matrix3d kuka = rot_z(krl_component(agg, "A")) * rot_y(krl_component(agg, "B")) *
                                 rot_x(krl_component(agg, "C"));
    // docs/robot.md: KUKA tool X = groovetrace z (torch), Y = y, Z = -x (against travel).
    e.rotation.col(0) = -kuka.col(2);
    e.rotation.col(1) = kuka.col(1);
    e.rotation.col(2) = kuka.col(0);
    points[name] = e;
  }
  std::vector<ProgramEvent> events;
  const std::string out = "$OUT[" + std::to_string(arc_output) + "]";
  for (const std::string& raw : text_lines(src)) {
    const std::string line = trimmed(raw);
    if (begins(line, "LIN ") || begins(line, "PTP ")) {
      std::string name = line.substr(4);
      name = name.substr(0, name.find(' '));
      if (!points.count(name)) throw std::runtime_error("motion to an undeclared point: " + line);
      ProgramEvent e = points[name];
      e.text = line;
      events.push_back(e);
    } else if (line == out + " = TRUE") {
      events.push_back({ProgramEvent::kArcOn, {}, {}, line});
    } else if (line == out + " = FALSE") {
      events.push_back({ProgramEvent::kArcOff, {}, {}, line});
    } else if (begins(line, ";")) {
      events.push_back({ProgramEvent::kText, {}, {}, line});
    }
  }
  return events;
}

// --- ROS nav_msgs/Path YAML (ros2 topic echo layout) -----------------------------------
struct RosPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::string frame_id;
};

/// The poses of the YAML, and in `path_frame` the frame_id of the path's own header.
inline std::vector<RosPose> parse_ros_path(const std::string& yaml, std::string& path_frame) {
  std::vector<RosPose> poses;
  std::string block;  // "position" or "orientation"
  double qx = 0, qy = 0, qz = 0;
  for (const std::string& line : text_lines(yaml)) {
    const std::string t = trimmed(line);
    const auto colon = t.find(':');
    const std::string key = t.substr(0, colon);
    const std::string value = colon == std::string::npos ? "" : trimmed(t.substr(colon + 1));
    if (line == "poses:") continue;
    if (begins(line, "- header:")) poses.emplace_back();
    if (key == "frame_id") (poses.empty() ? path_frame : poses.back().frame_id) = value;
    if (key == "position" || key == "orientation") block = key;
    if (poses.empty() || value.empty() || block.empty()) continue;
    if (block == "position" && (key == "x" || key == "y" || key == "z")) {
      poses.back().position[key[0] - 'x'] = std::stod(value);
    } else if (block == "orientation") {
      if (key == "x") qx = std::stod(value);
      if (key == "y") qy = std::stod(value);
      if (key == "z") qz = std::stod(value);
      if (key == "w") poses.back().orientation = Eigen::Quaterniond(std::stod(value), qx, qy, qz);
    }
  }
  return poses;
}

}  // namespace groovetrace::test
