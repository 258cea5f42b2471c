// The calibration file layouts of docs/frames.md, told apart by content: OpenCV XML (`<`),
// OpenCV YAML (`%YAML:1.0`), a UR pose (`p[...]`), a plain 4x4 matrix (numbers only), else a
// YAML or JSON tree whose keys say its layout.

#include "robot/calibration_formats.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>

#include "io/text.hpp"
#include "robot/calibration_tree.hpp"
#include "robot/calibration_values.hpp"

namespace groovetrace::calib {
namespace {

constexpr double kPi = 3.14159265358979323846;

Calibration make(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const std::string& format) {
  Calibration c;
  c.transform.linear() = R;
  c.transform.translation() = t;
  c.format = format;
  return c;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// ---- quaternions and rotations in a tree ------------------------------------------------

enum class Order { unknown, xyzw, wxyz };

Order order_of_key(const std::string& key) {
  const std::string k = lower(key);
  if (ends_with(k, "xyzw")) return Order::xyzw;
  if (ends_with(k, "wxyz")) return Order::wxyz;
  return Order::unknown;
}

// A list of 4 under a key that does not say its order: both readings must agree.
Eigen::Matrix3d unordered_quaternion(const std::vector<double>& v, const std::string& key) {
  const Eigen::Quaterniond xyzw(v[3], v[0], v[1], v[2]), wxyz(v[0], v[1], v[2], v[3]);
  const Eigen::Matrix3d R = quaternion_rotation(xyzw, key);
  const double apart = xyzw.normalized().angularDistance(wxyz.normalized());
  if (apart > 1e-12) {
    io::reject("'" + io::shown(key, 40) +
               "' is a quaternion of 4 numbers that does not say its order: read as x, y, z, w "
               "and as w, x, y, z they are rotations " +
               format_number(apart * 180 / kPi) + " deg apart; name the fields (x, y, z, w) or " +
               "the key (" + io::shown(key, 40) + "_xyzw or " + io::shown(key, 40) + "_wxyz)");
  }
  return R;
}

Eigen::Matrix3d list_rotation(const Value& v, const std::string& key, Order order) {
  if (!v.items.empty() && v.items.front().is_list()) {
    return matrix_rotation(matrix_rows(v, key, 3, 3), key);
  }
  if (v.items.size() == 3) {
    io::reject("field '" + key +
               "' has 3 values: a rotation vector or Euler angles are not accepted here (their "
               "convention is not written in the file); give a quaternion, a 3x3 matrix or a "
               "UR pose p[x, y, z, rx, ry, rz]");
  }
  const std::vector<double> q = numbers(v, key, 4);
  if (order == Order::unknown) return unordered_quaternion(q, key);
  const Eigen::Quaterniond quat = order == Order::xyzw ? Eigen::Quaterniond(q[3], q[0], q[1], q[2])
                                                       : Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  return quaternion_rotation(quat, key);
}

// A rotation: a quaternion as a map of named fields (x, y, z, w or qx, qy, qz, qw), a list of 4
// (its order from the key or `order`), or a 3x3 matrix as a list of rows.
Eigen::Matrix3d rotation(const Value& v, const std::string& key, Order order) {
  if (v.is_map()) {
    const bool prefixed = v.find("qw") != nullptr;
    const auto q = prefixed ? named_numbers(v, key, {"qx", "qy", "qz", "qw"})
                            : named_numbers(v, key, {"x", "y", "z", "w"});
    return quaternion_rotation(Eigen::Quaterniond(q[3], q[0], q[1], q[2]), key);
  }
  if (v.is_list()) {
    const Order by_key = order_of_key(key);
    return list_rotation(v, key, by_key != Order::unknown ? by_key : order);
  }
  if (v.kind == Value::Kind::null) io::reject("missing field '" + key + "'");
  io::reject("field '" + key + "' must be a list of 4 numbers or a map of x, y, z, w");
}

Eigen::Vector3d position(const Value& v, const std::string& key) {
  const auto t = v.is_map() ? named_numbers(v, key, {"x", "y", "z"}) : numbers(v, key, 3);
  return Eigen::Vector3d(t[0], t[1], t[2]);
}

// ---- tree layouts -------------------------------------------------------------------------

// The one key of `candidates` (with _xyzw/_wxyz variants when `ordered`) that `m` has, or "".
std::string one_key(const Value& m, const std::vector<std::string>& candidates, bool ordered) {
  std::vector<std::string> found;
  for (const auto& c : candidates) {
    for (const std::string suffix : {"", "_xyzw", "_wxyz"}) {
      if (!suffix.empty() && !ordered) continue;
      if (m.find(c + suffix)) found.push_back(c + suffix);
    }
  }
  if (found.size() > 1) {
    io::reject("both '" + found[0] + "' and '" + found[1] + "': keep only one");
  }
  return found.empty() ? "" : found[0];
}

// translation + rotation (groovetrace; a bare list under `rotation` is x, y, z, w as documented)
// or position + orientation (ROS Pose). nullopt when `m` has neither kind of key.
std::optional<Calibration> pose_map(const Value& m, bool top_level) {
  const std::string pos = one_key(m, {"translation", "position"}, false);
  const std::string rot = one_key(m, {"rotation", "orientation", "quaternion", "quat"}, true);
  if (pos.empty() && rot.empty()) return std::nullopt;
  if (pos.empty()) {
    io::reject(std::string("missing field '") +
               (rot.rfind("orientation", 0) == 0 ? "position" : "translation") + "'");
  }
  if (rot.empty()) {
    io::reject(std::string("missing field '") + (pos == "position" ? "orientation" : "rotation") +
               "'");
  }
  const bool documented = top_level && pos == "translation" && rot == "rotation";
  const Eigen::Matrix3d R = rotation(*m.find(rot), rot, documented ? Order::xyzw : Order::unknown);
  return make(R, position(*m.find(pos), pos), pos == "translation" ? "groovetrace" : "ros_pose");
}

std::string text_of(const Value* v) {
  return v && v->kind == Value::Kind::scalar ? v->text : std::string();
}

std::optional<bool> yes_no(const Value* v, const std::string& where) {
  if (!v || v->kind == Value::Kind::null) return std::nullopt;
  const std::string t = lower(text_of(v));
  if (t == "true" || t == "1" || t == "yes") return true;
  if (t == "false" || t == "0" || t == "no") return false;
  io::reject(where + " is '" + io::shown(text_of(v), 40) + "', expected true or false");
}

// easy_handeye's frames: eye-in-hand T_effector_tracking, eye-on-base T_base_tracking.
void handeye_frames(Calibration& c, const Value& meta) {
  c.child_frame = text_of(meta.find("tracking_base_frame"));
  if (c.eye_on_hand) {
    c.parent_frame =
        text_of(meta.find(*c.eye_on_hand ? "robot_effector_frame" : "robot_base_frame"));
  }
}

// easy_handeye (ROS 1; also early easy_handeye2): transformation {x, y, z, qx, qy, qz, qw}, with
// eye_on_hand and the frame names at the top or under `parameters`.
Calibration easy_handeye(const Value& root) {
  const auto v = named_numbers(*root.find("transformation"), "transformation",
                               {"x", "y", "z", "qx", "qy", "qz", "qw"});
  Calibration c =
      make(quaternion_rotation(Eigen::Quaterniond(v[6], v[3], v[4], v[5]), "transformation"),
           Eigen::Vector3d(v[0], v[1], v[2]), "easy_handeye");
  const Value* params = root.find("parameters");
  const Value& meta = params && params->is_map() ? *params : root;
  c.eye_on_hand = yes_no(meta.find("eye_on_hand"), "eye_on_hand");
  handeye_frames(c, meta);
  return c;
}

// easy_handeye2 (a HandeyeCalibration message: parameters + transform {translation, rotation}),
// or a ROS TransformStamped (header.frame_id, child_frame_id, transform).
Calibration transform_message(const Value& root) {
  const Value& tf = *root.find("transform");
  if (!tf.is_map()) io::reject("field 'transform' must be a map of translation and rotation");
  Calibration c = make(
      rotation(tf.find("rotation") ? *tf.find("rotation") : Value{}, "transform.rotation",
               Order::unknown),
      position(tf.find("translation") ? *tf.find("translation") : Value{}, "transform.translation"),
      "ros_transform");
  const Value* params = root.find("parameters");
  if (params && params->is_map()) {
    c.format = "easy_handeye2";
    const std::string type = text_of(params->find("calibration_type"));
    if (type == "eye_in_hand" || type == "eye_on_base") {
      c.eye_on_hand = type == "eye_in_hand";
    } else if (!type.empty()) {
      io::reject("parameters.calibration_type is '" + io::shown(type, 40) +
                 "', expected eye_in_hand or eye_on_base");
    }
    handeye_frames(c, *params);
  } else {
    const Value* header = root.find("header");
    if (header) c.parent_frame = text_of(header->find("frame_id"));
    c.child_frame = text_of(root.find("child_frame_id"));
  }
  return c;
}

// ---- OpenCV FileStorage -------------------------------------------------------------------

bool is_cv_matrix(const Value& v) {
  return v.is_map() && v.find("rows") && v.find("cols") && v.find("data");
}

// A matrix's `data`: a list of numbers (YAML, JSON) or one text of them (XML).
std::vector<double> cv_data(const Value& data, const std::string& key) {
  std::vector<double> values;
  if (data.kind == Value::Kind::scalar && !data.number) {
    std::string text = data.text;
    std::replace(text.begin(), text.end(), '\n', ' ');
    for (const auto word : io::split_ws(text)) {
      double d = 0;
      if (!parse_decimal(word, d)) {
        io::reject(key + ".data holds '" + io::shown(word, 40) + "', not a number");
      }
      values.push_back(d);
    }
  } else if (data.is_list()) {
    for (std::size_t i = 0; i < data.items.size(); ++i) {
      values.push_back(number(data.items[i], key + ".data[" + std::to_string(i) + "]"));
    }
  } else if (data.number) {
    values.push_back(*data.number);
  }
  return values;
}

Eigen::MatrixXd cv_matrix(const Value& v, const std::string& key) {
  const double rows = number(*v.find("rows"), key + ".rows");
  const double cols = number(*v.find("cols"), key + ".cols");
  if (rows != std::floor(rows) || cols != std::floor(cols) || rows < 1 || cols < 1 || rows > 4 ||
      cols > 4) {
    io::reject(key + " is " + format_number(rows) + "x" + format_number(cols) +
               ", not a matrix of a transform");
  }
  const std::string dt = text_of(v.find("dt"));
  if (v.find("dt") && dt != "d" && dt != "f") {
    io::reject(key + ".dt is '" + io::shown(dt, 20) + "', expected d or f (numbers)");
  }
  const std::vector<double> values = cv_data(*v.find("data"), key);
  const auto r = static_cast<int>(rows), c = static_cast<int>(cols);
  if (values.size() != static_cast<std::size_t>(r * c)) {
    io::reject(key + ".data has " + std::to_string(values.size()) + " values, expected " +
               std::to_string(r * c) + " (" + std::to_string(r) + "x" + std::to_string(c) + ")");
  }
  Eigen::MatrixXd M(r, c);
  for (int i = 0; i < r * c; ++i) {
    const double d = values[static_cast<std::size_t>(i)];
    if (!std::isfinite(d)) io::reject(key + ".data[" + std::to_string(i) + "] is not finite");
    M(i / c, i % c) = d;
  }
  return M;
}

using Matrices = std::vector<std::pair<std::string, Eigen::MatrixXd>>;

const Eigen::MatrixXd* lookup(const Matrices& found, const std::string& key) {
  for (const auto& f : found) {
    if (f.first == key) return &f.second;
  }
  return nullptr;
}

// The translation key that goes with rotation key `r`: R -> t, R_x -> t_x, rotation_x ->
// translation_x (T for t too).
std::vector<std::string> partner_keys(const std::string& r) {
  if (r == "R") return {"t", "T"};
  if (r.rfind("R_", 0) == 0) return {"t" + r.substr(1), "T" + r.substr(1)};
  if (r.rfind("rotation", 0) == 0) return {"translation" + r.substr(8)};
  return {};
}

// Every (3x3 rotation key, 3-vector translation key) pair by the names above.
std::vector<std::pair<std::string, std::string>> rt_pairs(const Matrices& found) {
  std::vector<std::pair<std::string, std::string>> pairs;
  for (const auto& [key, M] : found) {
    for (const auto& tkey : partner_keys(key)) {
      const Eigen::MatrixXd* t = lookup(found, tkey);
      if (t && M.rows() == 3 && M.cols() == 3 && t->size() == 3) pairs.emplace_back(key, tkey);
    }
  }
  return pairs;
}

// Without an R/t pair: the one 4x4 matrix, else the refusal listing what the file holds.
Eigen::Isometry3d single_homogeneous(const Matrices& found) {
  std::vector<std::string> fours;
  std::string list;
  for (const auto& [key, M] : found) {
    list += (list.empty() ? "" : ", ") + io::shown(key, 40) + " (" + std::to_string(M.rows()) +
            "x" + std::to_string(M.cols()) + ")";
    if (M.rows() == 4 && M.cols() == 4) fours.push_back(key);
  }
  if (fours.size() == 1) return homogeneous(*lookup(found, fours[0]), fours[0]);
  io::reject(
      "OpenCV storage holds no R/t pair (3x3 and 3x1 named R/t, R_<name>/t_<name> or "
      "rotation<name>/translation<name>) and not one 4x4 matrix; it holds: " +
      (list.empty() ? std::string("no matrix") : list));
}

Calibration opencv(const Value& root, const std::string& format) {
  Matrices found;
  for (const auto& [key, v] : root.entries) {
    if (is_cv_matrix(v)) found.emplace_back(key, cv_matrix(v, io::shown(key, 40)));
  }
  const auto pairs = rt_pairs(found);
  if (pairs.size() > 1) {
    io::reject("holds more than one R/t pair (" + pairs[0].first + "/" + pairs[0].second + ", " +
               pairs[1].first + "/" + pairs[1].second + "): keep only the one to use");
  }
  if (pairs.empty()) {
    const Eigen::Isometry3d T = single_homogeneous(found);
    return make(T.linear(), T.translation(), format);
  }
  const Eigen::MatrixXd& t = *lookup(found, pairs[0].second);
  return make(matrix_rotation(*lookup(found, pairs[0].first), pairs[0].first),
              Eigen::Vector3d(t(0), t(1), t(2)), format);
}

// ---- dispatch -------------------------------------------------------------------------------

std::string keys_of(const Value& m) {
  std::string list;
  for (const auto& [key, v] : m.entries) {
    list += (list.empty() ? "" : ", ") + io::shown(key, 40);
    if (list.size() > 200) return list + ", ...";
  }
  return list.empty() ? "none" : list;
}

Calibration from_tree(const Value& root, const std::string& format_if_opencv) {
  if (root.is_list()) {
    const Eigen::Isometry3d T = homogeneous(matrix_rows(root, "matrix", 4, 4), "matrix");
    return make(T.linear(), T.translation(), "matrix_list");
  }
  if (!root.is_map()) {
    io::reject(
        "expected a mapping with 'translation' and 'rotation', or another layout of "
        "docs/frames.md");
  }
  if (std::any_of(root.entries.begin(), root.entries.end(),
                  [](const auto& e) { return is_cv_matrix(e.second); })) {
    return opencv(root, format_if_opencv);
  }
  if (root.find("transformation")) return easy_handeye(root);
  if (root.find("transform")) return transform_message(root);
  if (const Value* pose = root.find("pose"); pose && pose->is_map()) {
    if (auto c = pose_map(*pose, false)) return *c;
  }
  if (auto c = pose_map(root, true)) return *c;
  io::reject("holds no transform in a layout of docs/frames.md (its keys: " + keys_of(root) + ")");
}

std::string without_comments(const std::string& text) {
  std::string out;
  bool comment = false;
  for (char c : text) {
    if (c == '#') comment = true;
    if (c == '\n') comment = false;
    if (!comment) out += c;
  }
  return out;
}

// Whitespace, commas, semicolons and brackets between numbers; nullopt if any word is no number.
std::optional<std::vector<double>> numbers_only(const std::string& text) {
  std::string spaced = text;
  for (char& c : spaced) {
    if (c == ',' || c == ';' || c == '[' || c == ']' || c == '\r' || c == '\n') c = ' ';
  }
  std::vector<double> out;
  for (const auto word : io::split_ws(spaced)) {
    double d = 0;
    if (!parse_decimal(word, d)) return std::nullopt;
    out.push_back(d);
  }
  if (out.empty()) return std::nullopt;
  return out;
}

void require_finite(const std::vector<double>& v, const char* what) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      io::reject(std::string(what) + " value " + std::to_string(i + 1) + " is not finite (" +
                 format_number(v[i]) + ")");
    }
  }
}

Calibration matrix_text(const std::vector<double>& v) {
  if (v.size() == 6) {
    io::reject("holds 6 numbers: a UR pose is written p[x, y, z, rx, ry, rz]; a 4x4 matrix has 16");
  }
  if (v.size() != 16) {
    io::reject("holds " + io::count_of(v.size(), "number") +
               "; a plain 4x4 matrix has 16 (4 rows of 4)");
  }
  require_finite(v, "matrix");
  Eigen::Matrix4d M;
  for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
  const Eigen::Isometry3d T = homogeneous(M, "the matrix");
  return make(T.linear(), T.translation(), "matrix_text");
}

// p[x, y, z, rx, ry, rz]: metres and a rotation vector (rad), as URScript writes poses.
Calibration ur_pose(const std::string& body) {
  const auto open = body.find('['), close = body.find(']');
  if (close == std::string::npos || close < open) io::reject("UR pose p[...] has no closing ']'");
  if (body.find_first_not_of(" \t\r\n", close + 1) != std::string::npos) {
    io::reject("text after the UR pose p[...]");
  }
  const std::string inner = body.substr(open + 1, close - open - 1);
  const auto v = numbers_only(inner);
  if (!v || inner.find_first_of("[]") != std::string::npos) {
    io::reject("UR pose p[...] must hold numbers separated by commas");
  }
  if (v->size() != 6) {
    io::reject("UR pose p[...] has " + io::count_of(v->size(), "number") +
               ", expected 6 (x, y, z in m, rx, ry, rz in rad)");
  }
  require_finite(*v, "UR pose");
  const auto& p = *v;
  if (!std::isfinite(Eigen::Vector3d(p[3], p[4], p[5]).norm())) {
    io::reject("UR pose p[...]: the rotation vector's length is not finite");
  }
  return make(rotation_vector_rotation(Eigen::Vector3d(p[3], p[4], p[5])),
              Eigen::Vector3d(p[0], p[1], p[2]), "ur_pose");
}

}  // namespace

Calibration parse_calibration(const std::string& text, const std::string& extension) {
  std::string body = text.rfind("\xEF\xBB\xBF", 0) == 0 ? text.substr(3) : text;
  const auto first = body.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) io::reject("file is empty");
  if (body[first] == '<') return from_tree(parse_opencv_xml(body), "opencv_xml");
  if (body.compare(first, 6, "%YAML:") == 0) {
    // OpenCV's header line is no YAML directive yaml-cpp takes; the rest is YAML.
    const auto eol = body.find('\n', first);
    return from_tree(parse_yaml(eol == std::string::npos ? "" : body.substr(eol + 1)),
                     "opencv_yaml");
  }
  const std::string plain = without_comments(body);
  const auto start = plain.find_first_not_of(" \t\r\n");
  if (start != std::string::npos && plain[start] == 'p') {
    const auto bracket = plain.find_first_not_of(" \t", start + 1);
    if (bracket != std::string::npos && plain[bracket] == '[')
      return ur_pose(plain.substr(bracket));
  }
  if (const auto v = numbers_only(plain)) return matrix_text(*v);
  const bool json = extension == ".json";
  return from_tree(json ? parse_json(body) : parse_yaml(body),
                   json ? "opencv_json" : "opencv_yaml");
}

}  // namespace groovetrace::calib
