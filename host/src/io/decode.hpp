#pragma once
// Decoding scans through PCL, behind our own checks of each file's structure.
//
// PCL 1.13 trusts the header it parses: an empty or header-only PCD crashes PCDReader::read,
// a huge POINTS or vertex count is allocated before any data is read (a 100-byte file can ask
// for 24 GB), a short or non-numeric ASCII line silently becomes a (0,0,0) point, and an
// unknown DATA type is read as ASCII. So every file is first checked against its own header
// and size (io/pcd.cpp, io/ply.cpp), and PCL only decodes what passed; its console output is
// silenced so the one-line InputError is the only thing a user sees.

#include <pcl/PCLPointCloud2.h>

#include <Eigen/Core>
#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "io/text.hpp"

namespace groovetrace::io {

// What PCL decoded: the points as PCL's blob, and the sensor origin (file units).
struct Decoded {
  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
};

// A PCD held in memory, checked (header, data against the header, the fields in `required`
// present, at least one point) and decoded. Throws Rejected.
Decoded decode_pcd(const std::string& content, const std::vector<std::string>& required);
// A PLY file (`content` is its bytes; PCL reads `path` again), checked and decoded. Throws
// Rejected.
Decoded decode_ply(const std::string& path, const std::string& content);

// Field `name` of the blob, checked to lie inside a point; rejects a missing field or one of
// an unsupported type or layout.
const pcl::PCLPointField& blob_field(const pcl::PCLPointCloud2& blob, const std::string& name);
// The value of one field of one point, whatever its PCL datatype.
double field_value(const std::uint8_t* p, std::uint8_t datatype);

// PCL prints its own errors (with "\n" and internal function names) to stderr. Silence it
// for the duration of a read; a counter keeps concurrent reads from restoring the level
// while another one is still running.
class PclQuiet {
 public:
  PclQuiet();
  ~PclQuiet();
  PclQuiet(const PclQuiet&) = delete;
  PclQuiet& operator=(const PclQuiet&) = delete;
};

// Runs `decode` (PCL calls) quietly; PCL's exceptions become one-line rejections.
template <typename Decode>
void quietly(Decode&& decode) {
  PclQuiet quiet;
  try {
    decode();
  } catch (const Rejected&) {
    throw;
  } catch (const std::exception& e) {
    reject(std::string("cannot be parsed (") + shown(e.what(), 200) + ")");
  } catch (...) {
    reject("cannot be parsed");
  }
}

}  // namespace groovetrace::io
