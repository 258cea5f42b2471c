#pragma once
// PCD access beyond read_cloud, through the same parser and the one writer (io/pcd.cpp): a
// PCD's fields as named columns (eval reads annotated.pcd's groove, synth its labels), and
// binary PCDs of named columns (scans, annotated.pcd, labels).

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace groovetrace::io {

/// A PCD's fields as float columns, one value per point in file order.
struct PcdTable {
  std::uint32_t width = 0, height = 0;                  ///< as in the header
  Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();  ///< VIEWPOINT translation, file units
  std::vector<std::string> names;                       ///< fields with COUNT 1, in file order
  std::vector<std::vector<float>> columns;              ///< columns[k] holds names[k]

  std::size_t size() const { return static_cast<std::size_t>(width) * height; }
  /// The column of field `name`; nullptr if the file has no such field (with COUNT 1).
  const std::vector<float>* column(const std::string& name) const;
};

/// Reads any PCD (ascii, binary, binary_compressed) with read_cloud's checks. Throws
/// InputError (one line, naming the path) for a missing, malformed or truncated file, no
/// points, or a field in `required` missing or not of COUNT 1.
PcdTable read_pcd_fields(const std::string& path, const std::vector<std::string>& required);

/// One column of a binary PCD: float32 values, or uint8 flags written as 0/1 (any nonzero
/// value is 1). Without values (nullptr) every point gets NaN (float) or 0 (flag).
struct PcdColumn {
  std::string name;
  const std::vector<float>* floats = nullptr;
  const std::vector<std::uint8_t>* flags = nullptr;
  bool is_flag = false;
};
PcdColumn float_column(std::string name, const std::vector<float>* values);
PcdColumn flag_column(std::string name, const std::vector<std::uint8_t>* values);

/// The bytes of a binary PCD of width x height points with these columns (little-endian).
/// `comment` follows "# .PCD v0.7 - " on the first line; the VIEWPOINT is `viewpoint` with
/// the identity orientation. Throws InternalError when a column does not have width x height
/// values or the viewpoint is not finite.
std::string binary_pcd_bytes(const std::string& comment, std::size_t width, std::size_t height,
                             const Eigen::Vector3f& viewpoint,
                             const std::vector<PcdColumn>& columns);

}  // namespace groovetrace::io
