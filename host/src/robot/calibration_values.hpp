#pragma once
// Numbers, quaternions and matrices out of a calibration tree, checked: each function throws
// io::Rejected naming the value (`where`, e.g. "translation" or "transformation.qw").

#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "robot/calibration_tree.hpp"

namespace groovetrace::calib {

/// Tolerances of docs/frames.md: |q| within kUnitTolerance of 1; every entry of R^T R - I
/// within kOrthonormalTolerance; a homogeneous matrix's last row 0 0 0 1 within kLastRowTolerance.
constexpr double kUnitTolerance = 1e-3;
constexpr double kOrthonormalTolerance = 1e-3;
constexpr double kLastRowTolerance = 1e-9;

/// A scalar that is a finite number.
double number(const Value& v, const std::string& where);
/// A list of exactly `n` finite numbers.
std::vector<double> numbers(const Value& v, const std::string& where, std::size_t n);
/// A map with exactly the fields `names` (no others), each a finite number, in that order.
std::vector<double> named_numbers(const Value& v, const std::string& where,
                                  const std::vector<std::string>& names);
/// Rows of numbers: a list of `rows` lists of `cols` numbers.
Eigen::MatrixXd matrix_rows(const Value& v, const std::string& where, int rows, int cols);

/// The rotation of a unit quaternion (x, y, z, w), normalized.
Eigen::Matrix3d quaternion_rotation(const Eigen::Quaterniond& q, const std::string& where);
/// A 3x3 rotation matrix checked to be one, made exactly orthonormal (nearest rotation).
Eigen::Matrix3d matrix_rotation(const Eigen::Matrix3d& R, const std::string& where);
/// A 4x4 homogeneous matrix (rows) checked to be rigid.
Eigen::Isometry3d homogeneous(const Eigen::Matrix4d& M, const std::string& where);
/// The rotation of a rotation vector (axis * angle, rad).
Eigen::Matrix3d rotation_vector_rotation(const Eigen::Vector3d& r);

/// A decimal number of a text layout (nan and inf included); one too large for a double reads
/// as NaN, so that it is refused as not finite instead of read as 0.
bool parse_decimal(std::string_view word, double& value);

/// A number for a message, as few digits as show it.
std::string format_number(double v);

}  // namespace groovetrace::calib
