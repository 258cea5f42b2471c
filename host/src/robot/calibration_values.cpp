// Checked numbers, quaternions and matrices from calibration trees (calibration_values.hpp).

#include "robot/calibration_values.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

#include "io/text.hpp"

namespace groovetrace::calib {

std::string format_number(double v) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << v;
  return s.str();
}

bool parse_decimal(std::string_view word, double& value) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (end != word.data() + word.size() || word.empty()) return false;
  if (ec == std::errc::result_out_of_range) value = std::numeric_limits<double>::quiet_NaN();
  return ec == std::errc() || ec == std::errc::result_out_of_range;
}

double number(const Value& v, const std::string& where) {
  if (v.kind != Value::Kind::scalar || !v.number) {
    const std::string shown = v.kind == Value::Kind::scalar ? " ('" + io::shown(v.text, 40) + "')"
                              : v.kind == Value::Kind::null ? " (null)"
                                                            : "";
    io::reject(where + " is not a number" + shown);
  }
  if (!std::isfinite(*v.number)) {
    io::reject(where + " is not finite (" + format_number(*v.number) + ")");
  }
  return *v.number;
}

std::vector<double> numbers(const Value& v, const std::string& where, std::size_t n) {
  if (v.kind == Value::Kind::null) io::reject("missing field '" + where + "'");
  if (!v.is_list()) {
    io::reject("field '" + where + "' must be a list of " + std::to_string(n) + " numbers");
  }
  if (v.items.size() != n) {
    io::reject("field '" + where + "' has " + std::to_string(v.items.size()) +
               " values, expected " + std::to_string(n));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < n; ++i) {
    out.push_back(number(v.items[i], where + "[" + std::to_string(i) + "]"));
  }
  return out;
}

std::vector<double> named_numbers(const Value& v, const std::string& where,
                                  const std::vector<std::string>& names) {
  std::string expected;
  for (const auto& n : names) expected += (expected.empty() ? "" : ", ") + n;
  if (!v.is_map()) io::reject("field '" + where + "' must be a map of " + expected);
  for (const auto& [key, value] : v.entries) {
    if (std::find(names.begin(), names.end(), key) == names.end()) {
      io::reject("field '" + where + "' has an unexpected key '" + io::shown(key, 40) +
                 "' (expected " + expected + ")");
    }
  }
  std::vector<double> out;
  for (const auto& name : names) {
    const Value* item = v.find(name);
    if (!item) io::reject("field '" + where + "' has no '" + name + "'");
    out.push_back(number(*item, where + "." + name));
  }
  return out;
}

Eigen::MatrixXd matrix_rows(const Value& v, const std::string& where, int rows, int cols) {
  if (!v.is_list() || v.items.size() != static_cast<std::size_t>(rows)) {
    io::reject(where + " must be a list of " + std::to_string(rows) + " rows");
  }
  Eigen::MatrixXd M(rows, cols);
  for (int r = 0; r < rows; ++r) {
    const auto row = numbers(v.items[static_cast<std::size_t>(r)],
                             where + "[" + std::to_string(r) + "]", static_cast<std::size_t>(cols));
    for (int c = 0; c < cols; ++c) M(r, c) = row[static_cast<std::size_t>(c)];
  }
  return M;
}

Eigen::Matrix3d quaternion_rotation(const Eigen::Quaterniond& q, const std::string& where) {
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= kUnitTolerance)) {
    io::reject(where + " quaternion is not unit (norm " + format_number(norm) + ")");
  }
  return q.normalized().toRotationMatrix();
}

Eigen::Matrix3d matrix_rotation(const Eigen::Matrix3d& R, const std::string& where) {
  const double off = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(off <= kOrthonormalTolerance)) {
    io::reject(where + " is not a rotation: R^T R differs from the identity by " +
               format_number(off) + " (at most " + format_number(kOrthonormalTolerance) + ")");
  }
  const double det = R.determinant();
  if (!(det > 0)) {
    io::reject(where + " is a reflection (determinant " + format_number(det) + "), not a rotation");
  }
  // The nearest rotation (polar decomposition): U V^T of the SVD.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

Eigen::Isometry3d homogeneous(const Eigen::Matrix4d& M, const std::string& where) {
  const Eigen::RowVector4d last = M.row(3);
  if (!((last - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() <= kLastRowTolerance)) {
    io::reject(where + "'s last row is " + format_number(last[0]) + " " + format_number(last[1]) +
               " " + format_number(last[2]) + " " + format_number(last[3]) +
               ", expected 0 0 0 1 (the matrix is written by rows)");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = matrix_rotation(M.topLeftCorner<3, 3>(), where + "'s rotation");
  T.translation() = M.topRightCorner<3, 1>();
  return T;
}

Eigen::Matrix3d rotation_vector_rotation(const Eigen::Vector3d& r) {
  const double angle = r.norm();
  if (angle == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
}

}  // namespace groovetrace::calib
