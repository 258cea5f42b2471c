// Reading scans and writing PCDs: round trips through PCL's own writers and readers, every
// kind of bad input (type, one-line message, helpful phrase), and atomic file writes.
#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "io/pcd.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// x = i, y = 2i, z = 0.5 + i/1000 (all exact in float for small i except z, which the
// binary formats must still return bit for bit); some points NaN.
pcl::PointCloud<pcl::PointXYZ> sample_cloud(std::size_t n, std::vector<std::size_t> nan_at = {}) {
  pcl::PointCloud<pcl::PointXYZ> c;
  c.width = static_cast<std::uint32_t>(n);
  c.height = 1;
  c.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Multiples of 1/4 and 1/2 m: exact in ASCII, and within kMaxCoordinate for 2000 points.
    c[i].x = 0.25f * static_cast<float>(i);
    c[i].y = 0.5f * static_cast<float>(i);
    c[i].z = 0.5f + static_cast<float>(i) / 1000.0f;
  }
  for (std::size_t i : nan_at) c[i].x = c[i].y = c[i].z = kNaN;
  c.is_dense = nan_at.empty();
  return c;
}

// An ascii PCD with float fields; the caller gives WIDTH/HEIGHT/POINTS and the data lines.
std::string ascii_pcd(const std::string& fields, std::size_t width, std::size_t height,
                      std::size_t points, const std::string& data,
                      const std::string& viewpoint = "0 0 0 1 0 0 0") {
  std::string sizes, types, counts;
  std::istringstream ss(fields);
  for (std::string f; ss >> f;) {
    sizes += " 4";
    types += " F";
    counts += " 1";
  }
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE" + sizes + "\nTYPE" + types +
         "\nCOUNT" + counts + "\nWIDTH " + std::to_string(width) + "\nHEIGHT " +
         std::to_string(height) + "\nVIEWPOINT " + viewpoint + "\nPOINTS " +
         std::to_string(points) + "\nDATA ascii\n" + data;
}

std::string xyz_lines(std::size_t n) {
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    s += std::to_string(i) + " " + std::to_string(2 * i) + " 1\n";
  }
  return s;
}

class CloudIo : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string templ = (fs::path(::testing::TempDir()) / "cloud_io.XXXXXX").string();
    ASSERT_NE(::mkdtemp(templ.data()), nullptr) << std::strerror(errno);
    dir_ = templ;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path file(const std::string& name, const std::string& bytes) {
    const fs::path p = dir_ / name;
    spit(p, bytes);
    return p;
  }

  // read_cloud must throw InputError whose one-line message names the file and says why.
  void expect_rejected(const fs::path& p, const std::string& phrase, ReadOptions options = {}) {
    try {
      read_cloud(p.string(), options);
      ADD_FAILURE() << p << " was accepted; expected an error containing '" << phrase << "'";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(e.code(), ExitCode::kInput);
      EXPECT_NE(msg.find(phrase), std::string::npos) << "message: " << msg;
      EXPECT_NE(msg.find(p.filename().string()), std::string::npos) << "message: " << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << "message: " << msg;
      EXPECT_FALSE(msg.empty());
    } catch (const std::exception& e) {
      ADD_FAILURE() << "wrong exception type for " << p << ": " << e.what();
    }
  }

  fs::path dir_;
};

void expect_same_points(const Cloud& got, const pcl::PointCloud<pcl::PointXYZ>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    if (!std::isfinite(want[i].x)) {
      EXPECT_FALSE(got.valid(i)) << i;
      continue;
    }
    EXPECT_EQ(got.x[i], want[i].x) << i;
    EXPECT_EQ(got.y[i], want[i].y) << i;
    EXPECT_EQ(got.z[i], want[i].z) << i;
  }
}

// ---- good input --------------------------------------------------------------------------

TEST_F(CloudIo, BinaryPcdRoundTripIsExact) {
  auto c = sample_cloud(300, {0, 17, 299});
  c.sensor_origin_ = Eigen::Vector4f(0.1f, -0.2f, 0.3f, 0.0f);
  const fs::path p = dir_ / "scan.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinary(p.string(), c), 0);
  const Cloud got = read_cloud(p.string());
  expect_same_points(got, c);
  EXPECT_EQ(got.width, 300u);
  EXPECT_EQ(got.height, 1u);
  EXPECT_FALSE(got.organized());
  EXPECT_EQ(got.count_valid(), 297u);
  EXPECT_EQ(got.viewpoint, Eigen::Vector3f(0.1f, -0.2f, 0.3f));
}

TEST_F(CloudIo, BinaryCompressedPcdRoundTripIsExact) {
  const auto c = sample_cloud(1000, {5, 500});
  const fs::path p = dir_ / "scan.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(p.string(), c), 0);
  const Cloud got = read_cloud(p.string());
  expect_same_points(got, c);
  EXPECT_EQ(got.count_valid(), 998u);
}

TEST_F(CloudIo, AsciiPcdRoundTrip) {
  const auto c = sample_cloud(200, {3});
  const fs::path p = dir_ / "scan.pcd";
  ASSERT_EQ(pcl::io::savePCDFileASCII(p.string(), c), 0);
  const Cloud got = read_cloud(p.string());
  ASSERT_EQ(got.size(), c.size());
  EXPECT_FALSE(got.valid(3));
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (i == 3) continue;
    // PCL prints 8 significant digits; a float needs 9 to round-trip exactly.
    EXPECT_FLOAT_EQ(got.x[i], c[i].x) << i;
    EXPECT_FLOAT_EQ(got.y[i], c[i].y) << i;
    EXPECT_FLOAT_EQ(got.z[i], c[i].z) << i;
  }
}

TEST_F(CloudIo, ExtensionIsCaseInsensitive) {
  const fs::path p = dir_ / "SCAN.PcD";
  ASSERT_EQ(pcl::io::savePCDFileBinary(p.string(), sample_cloud(150)), 0);
  EXPECT_EQ(read_cloud(p.string()).size(), 150u);
}

TEST_F(CloudIo, Organized640x480KeepsRowMajorLayout) {
  pcl::PointCloud<pcl::PointXYZ> c(640, 480);
  for (std::uint32_t row = 0; row < 480; ++row) {
    for (std::uint32_t col = 0; col < 640; ++col) {
      auto& p = c.at(col, row);
      p.x = static_cast<float>(col);
      p.y = static_cast<float>(row);
      p.z = (col == 7 && row == 11) ? kNaN : 0.5f;
    }
  }
  c.is_dense = false;
  const fs::path p = dir_ / "frame.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinary(p.string(), c), 0);
  const Cloud got = read_cloud(p.string());
  EXPECT_EQ(got.width, 640u);
  EXPECT_EQ(got.height, 480u);
  EXPECT_TRUE(got.organized());
  ASSERT_EQ(got.size(), 640u * 480u);
  for (std::size_t row : {0u, 1u, 11u, 479u}) {
    for (std::size_t col : {0u, 1u, 8u, 639u}) {
      const std::size_t i = row * 640 + col;
      EXPECT_EQ(got.x[i], static_cast<float>(col));
      EXPECT_EQ(got.y[i], static_cast<float>(row));
    }
  }
  // A point with only z missing is invalid as a whole, in its own pixel.
  const std::size_t hole = 11 * 640 + 7;
  EXPECT_FALSE(got.valid(hole));
  EXPECT_TRUE(std::isnan(got.x[hole]));
  EXPECT_TRUE(got.valid(hole - 1));
  EXPECT_EQ(got.count_valid(), 640u * 480u - 1);
}

TEST_F(CloudIo, WidthOneHeightNIsUnorganized) {
  const fs::path p = file("column.pcd", ascii_pcd("x y z", 1, 150, 150, xyz_lines(150)));
  const Cloud got = read_cloud(p.string());
  EXPECT_EQ(got.width, 150u);
  EXPECT_EQ(got.height, 1u);
  EXPECT_FALSE(got.organized());
  EXPECT_EQ(got.x[149], 149.0f);
  EXPECT_EQ(got.y[149], 298.0f);
}

TEST_F(CloudIo, WindowsLineEndsBlankLinesAndCommentsAreAccepted) {
  // PCL's own header parser stops at a line holding only "\r"; a file edited on Windows
  // must still load, with every point where it belongs.
  std::string text = ascii_pcd("x y z", 120, 1, 120, xyz_lines(60) + "\n\n" + xyz_lines(60));
  text.insert(text.find("WIDTH"), "# a comment\n\n");
  std::string crlf;
  for (char ch : text) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
  const Cloud got = read_cloud(file("windows.pcd", crlf).string());
  ASSERT_EQ(got.size(), 120u);
  EXPECT_EQ(got.x[59], 59.0f);
  EXPECT_EQ(got.x[60], 0.0f);
  EXPECT_EQ(got.y[119], 118.0f);
}

TEST_F(CloudIo, NanPointsStayInPlace) {
  std::string data = xyz_lines(120);
  data += "nan nan nan\n5 nan 1\n100 200 1\n";
  const fs::path p = file("holes.pcd", ascii_pcd("x y z", 123, 1, 123, data));
  const Cloud got = read_cloud(p.string());
  ASSERT_EQ(got.size(), 123u);
  EXPECT_FALSE(got.valid(120));
  EXPECT_FALSE(got.valid(121));
  EXPECT_TRUE(std::isnan(got.x[121])) << "a partly NaN point must be NaN in every coordinate";
  EXPECT_TRUE(got.valid(122));
  EXPECT_EQ(got.x[122], 100.0f);
  EXPECT_EQ(got.x[119], 119.0f);
  EXPECT_EQ(got.count_valid(), 121u);
}

TEST_F(CloudIo, ViewpointAndMillimetreUnits) {
  const fs::path p = file("mm.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(120),
                                              "10 -20 300 0.7071068 0 0.7071068 0"));
  const Cloud metres = read_cloud(p.string());
  EXPECT_EQ(metres.viewpoint, Eigen::Vector3f(10.0f, -20.0f, 300.0f));

  ReadOptions mm;
  mm.units_scale = 0.001;
  const Cloud got = read_cloud(p.string(), mm);
  EXPECT_FLOAT_EQ(got.viewpoint.x(), 0.010f);
  EXPECT_FLOAT_EQ(got.viewpoint.y(), -0.020f);
  EXPECT_FLOAT_EQ(got.viewpoint.z(), 0.300f);
  EXPECT_FLOAT_EQ(got.x[100], 0.100f);
  EXPECT_FLOAT_EQ(got.y[100], 0.200f);
  EXPECT_FLOAT_EQ(got.z[100], 0.001f);
}

TEST_F(CloudIo, OtherFieldsAndOffsetsAreHandled) {
  // x is not the first field, fields have counts > 1 and sizes other than 4.
  std::string data;
  for (int i = 0; i < 110; ++i) {
    data += "7 " + std::to_string(i) + " 1 2 3 " + std::to_string(-i) + " 0.25 9\n";
  }
  const std::string text =
      "VERSION 0.7\nFIELDS intensity x rgb y z label\nSIZE 2 4 1 8 4 4\nTYPE U F U F F I\n"
      "COUNT 1 1 3 1 1 1\nWIDTH 110\nHEIGHT 1\nPOINTS 110\nDATA ascii\n" +
      data;
  const fs::path p = file("mixed.pcd", text);
  const Cloud got = read_cloud(p.string());
  ASSERT_EQ(got.size(), 110u);
  EXPECT_EQ(got.x[42], 42.0f);
  EXPECT_EQ(got.y[42], -42.0f);
  EXPECT_EQ(got.z[42], 0.25f);
}

TEST_F(CloudIo, PointXyzRgbNormalBinaryReadsOnlyCoordinates) {
  pcl::PointCloud<pcl::PointXYZRGBNormal> c;
  c.width = 120;
  c.height = 1;
  c.resize(120);
  for (std::size_t i = 0; i < c.size(); ++i) {
    c[i].x = 1.0f + static_cast<float>(i);
    c[i].y = 2.0f;
    c[i].z = 3.0f;
    c[i].normal_x = 99.0f;
    c[i].r = 200;
  }
  const fs::path p = dir_ / "rgbn.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(p.string(), c), 0);
  const Cloud got = read_cloud(p.string());
  ASSERT_EQ(got.size(), 120u);
  EXPECT_EQ(got.x[119], 120.0f);
  EXPECT_EQ(got.y[119], 2.0f);
  EXPECT_EQ(got.z[119], 3.0f);
}

TEST_F(CloudIo, Float64FieldsBinary) {
  const std::size_t n = 130;
  std::string text =
      "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 130\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 130\nDATA binary\n";
  for (std::size_t i = 0; i < n; ++i) {
    const double v[3] = {0.1 * static_cast<double>(i), -1e-3, 123.45678901};
    text.append(reinterpret_cast<const char*>(v), sizeof(v));
  }
  const fs::path p = file("double.pcd", text);
  const Cloud got = read_cloud(p.string());
  ASSERT_EQ(got.size(), n);
  EXPECT_EQ(got.x[77], static_cast<float>(0.1 * 77));
  EXPECT_EQ(got.y[77], static_cast<float>(-1e-3));
  EXPECT_EQ(got.z[77], static_cast<float>(123.45678901));
}

TEST_F(CloudIo, PlyAsciiAndBinaryRoundTrip) {
  const auto c = sample_cloud(250, {10});
  const fs::path ascii = dir_ / "scan_ascii.ply";
  const fs::path binary = dir_ / "scan_binary.ply";
  ASSERT_EQ(pcl::io::savePLYFile(ascii.string(), c, false), 0);
  ASSERT_EQ(pcl::io::savePLYFile(binary.string(), c, true), 0);
  expect_same_points(read_cloud(binary.string()), c);
  const Cloud got = read_cloud(ascii.string());
  ASSERT_EQ(got.size(), c.size());
  EXPECT_FALSE(got.valid(10));
  EXPECT_FLOAT_EQ(got.z[249], c[249].z);
  EXPECT_EQ(got.width, 250u);
  EXPECT_EQ(got.height, 1u);
}

TEST_F(CloudIo, PlyFloat64AndMillimetres) {
  std::string text =
      "ply\nformat ascii 1.0\nelement vertex 120\nproperty double x\nproperty double y\n"
      "property double z\nend_header\n";
  for (int i = 0; i < 120; ++i) text += std::to_string(i) + ".5 -3 1000.25\n";
  const fs::path p = file("double.ply", text);
  ReadOptions mm;
  mm.units_scale = 0.001;
  const Cloud got = read_cloud(p.string(), mm);
  ASSERT_EQ(got.size(), 120u);
  EXPECT_FLOAT_EQ(got.x[9], 0.0095f);
  EXPECT_FLOAT_EQ(got.y[9], -0.003f);
  EXPECT_FLOAT_EQ(got.z[9], 1.00025f);
}

TEST_F(CloudIo, MinValidPointsIsAnOption) {
  const fs::path p = file("small.pcd", ascii_pcd("x y z", 5, 1, 5, xyz_lines(5)));
  ReadOptions few;
  few.min_valid_points = 5;
  EXPECT_EQ(read_cloud(p.string(), few).size(), 5u);
}

TEST_F(CloudIo, BadUnitsScaleIsAUsageError) {
  const fs::path p = file("ok.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(120)));
  ReadOptions bad;
  bad.units_scale = 0.0;
  EXPECT_THROW(read_cloud(p.string(), bad), UsageError);
}

// ---- bad input ---------------------------------------------------------------------------

TEST_F(CloudIo, MissingFile) { expect_rejected(dir_ / "nope.pcd", "No such file"); }

TEST_F(CloudIo, DirectoryInsteadOfFile) {
  fs::create_directory(dir_ / "scan.pcd");
  expect_rejected(dir_ / "scan.pcd", "is a directory");
}

TEST_F(CloudIo, UnreadableFile) {
  // Permissions do not stop root (CI runs as root), but reading /proc/self/mem from offset 0
  // fails with an I/O error for everyone: a file that opens and cannot be read.
  const fs::path p = dir_ / "locked.pcd";
  fs::create_symlink("/proc/self/mem", p);
  expect_rejected(p, "locked.pcd");
}

TEST_F(CloudIo, UnknownExtension) {
  const fs::path p = file("scan.xyz", "1 2 3\n");
  expect_rejected(p, "unsupported file type ('.xyz'; expected .pcd, .ply or a 16-bit depth .png)");
  expect_rejected(file("noext", "1 2 3\n"), "unsupported file type (no file extension");
}

TEST_F(CloudIo, EmptyFile) {
  expect_rejected(file("empty.pcd", ""), "is empty");
  expect_rejected(file("empty.ply", ""), "is empty");
}

TEST_F(CloudIo, MalformedPcdHeaders) {
  expect_rejected(file("text.pcd", "hello world\nnot a cloud\n"),
                  "malformed PCD header: line 1 ('hello') is not a PCD header line");
  // PCL 1.13 segfaults on this one if given it unchecked.
  expect_rejected(file("nodata.pcd", "VERSION 0.7\n# just a comment\n"), "no DATA line");
  expect_rejected(file("sizes.pcd",
                       "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\n"
                       "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n"),
                  "SIZE has 2 values but FIELDS has 3");
  expect_rejected(file("shape.pcd", ascii_pcd("x y z", 3, 1, 2, "1 2 3\n4 5 6\n")),
                  "WIDTH x HEIGHT (3 x 1) is not POINTS (2)");
  expect_rejected(file("kind.pcd",
                       "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                       "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA weird\n1 2 3\n"),
                  "unknown DATA type 'weird'");
  expect_rejected(file("negative.pcd",
                       "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                       "WIDTH 2\nHEIGHT 1\nPOINTS -2\nDATA ascii\n1 2 3\n"),
                  "POINTS must be one non-negative integer");
  expect_rejected(file("floatsize.pcd",
                       "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 2\nTYPE F F F\n"
                       "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n"),
                  "field z is a float of size 2");
  expect_rejected(file("view.pcd", ascii_pcd("x y z", 1, 1, 1, "1 2 3\n", "0 0 nan 1 0 0 0")),
                  "VIEWPOINT must be 7 finite numbers");
}

TEST_F(CloudIo, TruncatedBinaryPcd) {
  const fs::path p = dir_ / "cut.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinary(p.string(), sample_cloud(300)), 0);
  fs::resize_file(p, fs::file_size(p) - 1);
  expect_rejected(p, "truncated PCD data: 300 points need 3600 bytes, the file has 3599");
}

TEST_F(CloudIo, TruncatedCompressedPcd) {
  const fs::path p = dir_ / "cut.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(p.string(), sample_cloud(300)), 0);
  fs::resize_file(p, fs::file_size(p) - 10);
  expect_rejected(p, "truncated PCD data: the compressed block has");
}

TEST_F(CloudIo, CorruptCompressedPcd) {
  const fs::path p = dir_ / "corrupt.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(p.string(), sample_cloud(300)), 0);
  std::string bytes = slurp(p);
  const std::size_t data = bytes.find("DATA binary_compressed\n") + 23;
  // A back-reference far before the start of the output: LZF must refuse it.
  bytes[data + 8] = static_cast<char>(0xff);
  bytes[data + 9] = static_cast<char>(0xff);
  spit(p, bytes);
  expect_rejected(p, "malformed PCD data");
}

TEST_F(CloudIo, TruncatedAsciiPcdMissingLines) {
  const fs::path p = dir_ / "cut.pcd";
  ASSERT_EQ(pcl::io::savePCDFileASCII(p.string(), sample_cloud(300)), 0);
  fs::resize_file(p, fs::file_size(p) - 100);
  expect_rejected(p, "truncated PCD data");
}

TEST_F(CloudIo, TruncatedAsciiPcdInsideTheLastLine) {
  // PCL 1.13 reads a short last line as a (0,0,0) point and reports success.
  const fs::path p = file("cut.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(119) + "119 2"));
  expect_rejected(p, "truncated PCD data: line 131 has 2 values, expected 3");
}

TEST_F(CloudIo, MalformedAsciiPcdValues) {
  std::string data = xyz_lines(119) + "1 2 3 4\n";
  expect_rejected(file("long.pcd", ascii_pcd("x y z", 120, 1, 120, data)),
                  "malformed PCD data: line 131 has 4 values, expected 3");
  data = xyz_lines(60) + "foo bar baz\n" + xyz_lines(59);
  expect_rejected(file("words.pcd", ascii_pcd("x y z", 120, 1, 120, data)),
                  "malformed PCD data: line 72: 'foo' is not a number");
}

TEST_F(CloudIo, HugePointCountIsRejectedWithoutAllocating) {
  // PCL would resize its buffer to 24 GB before noticing the data is missing.
  const std::string text =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2000000000\n"
      "HEIGHT 1\nPOINTS 2000000000\nDATA binary\n0123456789";
  expect_rejected(file("huge.pcd", text), "POINTS is too large");
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 200000000\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n0123456789";
  expect_rejected(file("huge.ply", ply), "truncated PLY data");
}

TEST_F(CloudIo, MalformedAndTruncatedPly) {
  expect_rejected(file("text.ply", "hello\nworld\n"), "malformed PLY header: no 'ply' magic");
  expect_rejected(file("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"),
                  "no end_header line");
  const fs::path binary = dir_ / "cut_binary.ply";
  ASSERT_EQ(pcl::io::savePLYFile(binary.string(), sample_cloud(300), true), 0);
  fs::resize_file(binary, fs::file_size(binary) - 200);
  expect_rejected(binary, "PLY data");
  const fs::path ascii = dir_ / "cut_ascii.ply";
  ASSERT_EQ(pcl::io::savePLYFile(ascii.string(), sample_cloud(300), false), 0);
  fs::resize_file(ascii, fs::file_size(ascii) - 200);
  expect_rejected(ascii, "PLY data");
}

TEST_F(CloudIo, NoXyzFields) {
  expect_rejected(file("rgb.pcd", ascii_pcd("a b c", 120, 1, 120, xyz_lines(120))),
                  "has no x/y/z fields (fields: a b c)");
  expect_rejected(file("xy.pcd", ascii_pcd("x y", 2, 1, 2, "1 2\n3 4\n")),
                  "has no x/y/z fields (fields: x y)");
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float a\nproperty float b\n"
      "end_header\n1 2\n3 4\n";
  expect_rejected(file("ab.ply", ply), "has no x/y/z fields");
}

TEST_F(CloudIo, ZeroPoints) {
  expect_rejected(file("zero.pcd", ascii_pcd("x y z", 0, 1, 0, "")), "has no points");
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  expect_rejected(file("zero.ply", ply), "has no points");
}

TEST_F(CloudIo, AllPointsNaN) {
  std::string data;
  for (int i = 0; i < 150; ++i) data += "nan nan nan\n";
  expect_rejected(file("nan.pcd", ascii_pcd("x y z", 150, 1, 150, data)),
                  "has no valid points (all 150 are NaN)");
}

TEST_F(CloudIo, TooFewValidPoints) {
  std::string data = xyz_lines(40);
  for (int i = 0; i < 110; ++i) data += "nan nan nan\n";
  const fs::path p = file("sparse.pcd", ascii_pcd("x y z", 150, 1, 150, data));
  expect_rejected(p, "has only 40 valid points (at least 100 needed)");
  ReadOptions loose;
  loose.min_valid_points = 40;
  EXPECT_EQ(read_cloud(p.string(), loose).count_valid(), 40u);
}

TEST_F(CloudIo, InfiniteCoordinates) {
  std::string data = xyz_lines(118) + "inf 1 1\n1 -inf 1\n";
  expect_rejected(file("inf.pcd", ascii_pcd("x y z", 120, 1, 120, data)),
                  "has 2 points with infinite coordinates");
  // A double beyond float range cannot be kept either.
  std::string text =
      "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 120\nHEIGHT 1\n"
      "POINTS 120\nDATA binary\n";
  for (int i = 0; i < 120; ++i) {
    const double v[3] = {i == 50 ? 1e300 : 1.0, 2.0, 3.0};
    text.append(reinterpret_cast<const char*>(v), sizeof(v));
  }
  expect_rejected(file("big.pcd", text), "has 1 point with infinite coordinates");
}

// A coordinate beyond a kilometre is a corrupt file or a wrong unit: one point at 1e8 m
// crashed the OpenCL crease kernel (its cell keys overflow 32-bit ints), at 1e16 m the CPU
// path's 64-bit keys. The bound applies after units.
TEST_F(CloudIo, CoordinatesBeyondAKilometre) {
  expect_rejected(file("far.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(119) + "1e8 1 1\n")),
                  "has 1 point beyond 1000 m");
  EXPECT_EQ(
      read_cloud(file("edge.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(119) + "-1000 1 1\n"))
                     .string())
          .count_valid(),
      120u);
  const fs::path mm_file =
      file("mm.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(119) + "1 900000 1\n"));
  ReadOptions mm;
  mm.units_scale = 0.001;
  EXPECT_EQ(read_cloud(mm_file.string(), mm).count_valid(), 120u);  // 900 m
  expect_rejected(mm_file, "has 1 point beyond 1000 m");            // 900 km
  // The sensor's origin too: at 1e30 m every normal turned towards it and the run gave exit 0.
  for (const char* far : {"1e30 0 0", "0 -1e300 0", "0 0 1000.5"}) {
    expect_rejected(file("far_view.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(120),
                                                   std::string(far) + " 1 0 0 0")),
                    "has its VIEWPOINT beyond 1000 m");
  }
  const fs::path km_view =
      file("km_view.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(120), "0 0 -1000 1 0 0 0"));
  EXPECT_EQ(read_cloud(km_view.string()).viewpoint.z(), -1000.0f);
}

// An ASCII PLY of `n` vertices with `extra` header lines before the vertex element and
// `after` header lines after it; `data_after` follows the vertex lines.
std::string crafted_ply(int n, const std::string& extra, const std::string& after = "",
                        const std::string& data_after = "") {
  return "ply\nformat ascii 1.0\n" + extra + "element vertex " + std::to_string(n) +
         "\nproperty float x\nproperty float y\nproperty float z\n" + after + "end_header\n" +
         xyz_lines(static_cast<std::size_t>(n)) + data_after;
}

// PLY headers PCL's reader mishandles are refused before it reads them: a range_grid (its
// vertex indices are written through unchecked: -1 crashed it), an obj_info grid that is not
// the vertices' shape (1 x 1 for 120 vertices tripped an assertion, exit 134; 2000 x 2000
// made a 4-million-point cloud from a small file), an element count beyond the file's size
// (2^64 - 1 entries with no properties looped for minutes). A matching grid still reads as
// an organized cloud.
TEST_F(CloudIo, CraftedPlyHeadersAreRefused) {
  std::string grid;
  for (int i = 0; i < 120; ++i) grid += "1 " + std::to_string(i == 5 ? -1 : i) + "\n";
  expect_rejected(file("rg.ply", crafted_ply(120, "obj_info num_cols 12\nobj_info num_rows 10\n",
                                             "element range_grid 120\nproperty list uchar int "
                                             "vertex_indices\n",
                                             grid)),
                  "range_grid elements are not read");
  expect_rejected(file("one.ply", crafted_ply(120, "obj_info num_cols 1\nobj_info num_rows 1\n")),
                  "grid 1 x 1 does not hold its 120 vertices");
  expect_rejected(
      file("big.ply", crafted_ply(120, "obj_info num_cols 2000\nobj_info num_rows 2000\n")),
      "grid 2000 x 2000 does not hold");
  expect_rejected(file("half.ply", crafted_ply(120, "obj_info num_cols 12\n")),
                  "num_cols without num_rows");
  expect_rejected(file("junk.ply", crafted_ply(120, "", "element junk 18446744073709551615\n")),
                  "without properties declares 18446744073709551615 entries");
  const Cloud grid_ok = read_cloud(
      file("ok.ply", crafted_ply(120, "obj_info num_cols 12\nobj_info num_rows 10\n")).string());
  EXPECT_EQ(grid_ok.count_valid(), 120u);
}

// An ASCII PLY of 120 vertices: x y z, then the vertex `properties` (header lines) with
// `values` on every vertex line; `more_header` follows the vertex element.
std::string ply_with_properties(const std::string& properties, const std::string& values,
                                const std::string& more_header = "") {
  std::string text =
      "ply\nformat ascii 1.0\nelement vertex 120\nproperty float x\nproperty float y\n"
      "property float z\n" +
      properties + more_header + "end_header\n";
  for (int i = 0; i < 120; ++i) text += std::to_string(i) + " 0 0.5 " + values + "\n";
  return text;
}

// Found by fuzz_ply (docs/fuzzing.md): vertex layouts that made PCL's PLYReader write past its
// data, an assertion in it (exit 134), are refused before it reads them. Colours without red
// (its blue moves on by an rgb field only red adds), alpha alone, a property between the
// colours, a vertex list property (sized by the first vertex's list), a second vertex element
// (the cloud restarted, the first one's count kept), and a header line starting with a blank
// (PCL splits an obj_info line itself: an empty first word). Colours in order still read.
TEST_F(CloudIo, PlyLayoutsPclWritesPastAreRefused) {
  expect_rejected(
      file("gb.ply", ply_with_properties("property uchar green\nproperty uchar blue\n", "1 2")),
      "vertex colours must be uchar red, green, blue");
  expect_rejected(file("alpha.ply", ply_with_properties("property uchar alpha\n", "1")),
                  "vertex colours");
  expect_rejected(file("split.ply", ply_with_properties("property uchar red\nproperty float f\n"
                                                        "property uchar green\nproperty uchar "
                                                        "blue\n",
                                                        "1 0.5 2 3")),
                  "vertex colours");
  expect_rejected(file("list.ply", ply_with_properties("property list uchar float f\n", "1 0.5")),
                  "vertex list properties are not read");
  expect_rejected(file("two.ply", ply_with_properties("", "",
                                                      "element vertex 1\nproperty uchar "
                                                      "q\n") +
                                      "7\n"),
                  "a second vertex element");
  expect_rejected(
      file("blank.ply", crafted_ply(120, " obj_info num_cols 120\nobj_info num_rows 1\n")),
      "line 3 starts with white space");
  const std::string rgba =
      "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
      "property float intensity\n";
  EXPECT_EQ(
      read_cloud(file("rgba.ply", ply_with_properties(rgba, "1 2 3 4 0.5")).string()).count_valid(),
      120u);
}

// Found by fuzz_ply: PCL finds a header line's keyword past any white space but hands an
// obj_info line as written to its callback, which splits it at blanks and tabs only and asserts
// that the first word is obj_info (exit 134). A line starting with a carriage return
// ("\robj_info isrgb_pixelsize ...") passed the blank check; a vertical tab or form feed would
// have too. A carriage return inside an obj_info line joined its words for PCL only: a 1 x 1
// grid for 120 vertices went unchecked (the same assertion). Tabs, runs of blanks and CRLF
// line ends split alike for both and still read as a grid.
TEST_F(CloudIo, PlyHeaderLinesPclSplitsOtherwiseAreRefused) {
  for (const char* lead : {"\r", "\v", "\f", "\t", " "}) {
    SCOPED_TRACE(static_cast<int>(lead[0]));
    expect_rejected(
        file("lead.ply", crafted_ply(120, std::string(lead) + "obj_info isrgb_pixelsize 3\n")),
        "line 3 starts with white space");
  }
  expect_rejected(
      file("cr.ply", crafted_ply(120, "obj_info\rx num_cols 1\nobj_info\rx num_rows 1\n")),
      "line 3 has a carriage return between its words");
  for (const char* grid : {"obj_info\tnum_cols 12\nobj_info  num_rows\t 10\n",
                           "obj_info num_cols 12\r\nobj_info num_rows 10\r\n"}) {
    const Cloud c = read_cloud(file("grid.ply", crafted_ply(120, grid)).string());
    EXPECT_EQ(c.width, 12u);
    EXPECT_EQ(c.height, 10u);
  }
}

TEST_F(CloudIo, FailuresPrintNothing) {
  // PCL would print its own multi-line errors; the caller's one line must be all there is.
  const fs::path cut = dir_ / "cut.ply";
  ASSERT_EQ(pcl::io::savePLYFile(cut.string(), sample_cloud(300), true), 0);
  fs::resize_file(cut, fs::file_size(cut) - 7);
  const fs::path bad = file("bad.pcd", ascii_pcd("x y z", 120, 1, 120, xyz_lines(119) + "1 2"));
  const fs::path ok = dir_ / "ok.ply";
  ASSERT_EQ(pcl::io::savePLYFile(ok.string(), sample_cloud(300), false), 0);
  ::testing::internal::CaptureStderr();
  ::testing::internal::CaptureStdout();
  EXPECT_THROW(read_cloud(cut.string()), InputError);
  EXPECT_THROW(read_cloud(bad.string()), InputError);
  EXPECT_EQ(read_cloud(ok.string()).size(), 300u);  // PCL warns about its camera element
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "");
  EXPECT_EQ(out, "");
}

// ---- writing PCDs ------------------------------------------------------------------------

Cloud organized_cloud() {
  Cloud c;
  c.width = 3;
  c.height = 2;
  c.resize(6);
  for (std::size_t i = 0; i < 6; ++i) {
    c.x[i] = 0.1f * static_cast<float>(i);
    c.y[i] = -0.2f;
    c.z[i] = 0.5f + 0.01f * static_cast<float>(i);
  }
  c.x[4] = c.y[4] = c.z[4] = kNaN;
  c.viewpoint = Eigen::Vector3f(0.125f, -0.3f, 1e-7f);
  return c;
}

template <typename T>
T value_at(const pcl::PCLPointCloud2& blob, std::size_t i, const std::string& field) {
  for (const auto& f : blob.fields) {
    if (f.name == field) {
      T v;
      std::memcpy(&v, blob.data.data() + i * blob.point_step + f.offset, sizeof(T));
      return v;
    }
  }
  ADD_FAILURE() << "no field " << field;
  return T{};
}

TEST_F(CloudIo, AnnotatedPcdIsReadByPcl) {
  const Cloud c = organized_cloud();
  Normals normals;
  normals.resize(6);
  normals.x[1] = 0.6f;
  normals.y[1] = 0.0f;
  normals.z[1] = -0.8f;
  const std::vector<float> descriptor = {1.0f, 2.5f, kNaN, 4.0f, kNaN, 6.0f};
  const std::vector<std::uint8_t> groove = {0, 1, 0, 1, 0, 7};
  const std::string bytes = annotated_pcd_bytes(c, {&normals, &descriptor, &groove});
  const fs::path p = file("annotated.pcd", bytes);

  pcl::PCLPointCloud2 blob;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0;
  ASSERT_EQ(pcl::PCDReader().read(p.string(), blob, origin, orientation, version), 0);
  EXPECT_EQ(blob.width, 3u);
  EXPECT_EQ(blob.height, 2u);
  EXPECT_EQ(origin.head<3>(), c.viewpoint);
  EXPECT_EQ(orientation.coeffs(), Eigen::Quaternionf::Identity().coeffs());
  const std::vector<std::string> names = {"x",        "y",        "z",          "normal_x",
                                          "normal_y", "normal_z", "descriptor", "groove"};
  ASSERT_EQ(blob.fields.size(), names.size());
  for (std::size_t k = 0; k < names.size(); ++k) {
    EXPECT_EQ(blob.fields[k].name, names[k]);
    EXPECT_EQ(blob.fields[k].count, 1u);
    EXPECT_EQ(blob.fields[k].datatype,
              k < 7 ? pcl::PCLPointField::FLOAT32 : pcl::PCLPointField::UINT8);
  }
  EXPECT_EQ(blob.point_step, 29u);
  for (std::size_t i = 0; i < 6; ++i) {
    if (i == 4) {
      EXPECT_TRUE(std::isnan(value_at<float>(blob, i, "x")));
    } else {
      EXPECT_EQ(value_at<float>(blob, i, "x"), c.x[i]) << i;
      EXPECT_EQ(value_at<float>(blob, i, "z"), c.z[i]) << i;
    }
  }
  EXPECT_EQ(value_at<float>(blob, 1, "normal_x"), 0.6f);
  EXPECT_EQ(value_at<float>(blob, 1, "normal_z"), -0.8f);
  EXPECT_TRUE(std::isnan(value_at<float>(blob, 0, "normal_x")));
  EXPECT_EQ(value_at<float>(blob, 1, "descriptor"), 2.5f);
  EXPECT_TRUE(std::isnan(value_at<float>(blob, 2, "descriptor")));
  EXPECT_EQ(value_at<std::uint8_t>(blob, 0, "groove"), 0);
  EXPECT_EQ(value_at<std::uint8_t>(blob, 3, "groove"), 1);
  EXPECT_EQ(value_at<std::uint8_t>(blob, 5, "groove"), 1) << "labels are written as 0/1";

  // Our reader takes it back too, layout included.
  ReadOptions any;
  any.min_valid_points = 1;
  const Cloud back = read_cloud(p.string(), any);
  EXPECT_EQ(back.width, 3u);
  EXPECT_EQ(back.height, 2u);
  EXPECT_EQ(back.viewpoint, c.viewpoint);
  EXPECT_EQ(back.z[5], c.z[5]);
  EXPECT_FALSE(back.valid(4));
}

TEST_F(CloudIo, AnnotatedPcdFieldsReadBack) {
  // read_pcd_fields gives every field of COUNT 1 by name, with the header's shape.
  const Cloud c = organized_cloud();
  Normals normals;
  normals.resize(6);
  normals.z[1] = -0.8f;
  const std::vector<float> descriptor = {1.0f, 2.5f, kNaN, 4.0f, kNaN, 6.0f};
  const std::vector<std::uint8_t> groove = {0, 1, 0, 1, 0, 7};
  const fs::path p =
      file("annotated.pcd", annotated_pcd_bytes(c, {&normals, &descriptor, &groove}));
  const io::PcdTable t = io::read_pcd_fields(p.string(), {"groove", "normal_z"});
  EXPECT_EQ(t.width, 3u);
  EXPECT_EQ(t.height, 2u);
  EXPECT_EQ(t.viewpoint, c.viewpoint);
  EXPECT_EQ(t.names, (std::vector<std::string>{"x", "y", "z", "normal_x", "normal_y", "normal_z",
                                               "descriptor", "groove"}));
  EXPECT_EQ(*t.column("groove"), (std::vector<float>{0, 1, 0, 1, 0, 1}));
  EXPECT_EQ((*t.column("normal_z"))[1], -0.8f);
  EXPECT_TRUE(std::isnan((*t.column("normal_z"))[0]));
  EXPECT_EQ((*t.column("descriptor"))[1], 2.5f);
  EXPECT_EQ((*t.column("z"))[5], c.z[5]);
  EXPECT_EQ(t.column("intensity"), nullptr);
}

TEST_F(CloudIo, PcdFieldsHaveTheScanChecks) {
  const auto expect_fails = [](const fs::path& p, std::vector<std::string> required,
                               const std::string& phrase) {
    try {
      io::read_pcd_fields(p.string(), required);
      ADD_FAILURE() << p << " was accepted; expected '" << phrase << "'";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(p.filename().string()), std::string::npos) << msg;
      EXPECT_NE(msg.find(phrase), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  };
  // No x/y/z needed here, but the named fields are.
  const std::string labels =
      "VERSION 0.7\nFIELDS label valid\nSIZE 1 1\nTYPE U U\nWIDTH 2\nPOINTS 2\n"
      "DATA ascii\n1 0\n0 1\n";
  const fs::path ok = file("labels.pcd", labels);
  EXPECT_EQ(*io::read_pcd_fields(ok.string(), {"label"}).column("valid"),
            (std::vector<float>{0, 1}));
  expect_fails(ok, {"groove"}, "has no groove field (fields: label valid)");
  expect_fails(file("cut.pcd", labels.substr(0, labels.size() - 2)), {},
               "truncated PCD data: line 9 has 1 value, expected 2");
  expect_fails(file("word.pcd", ascii_pcd("x y groove", 2, 1, 2, "1 2 0\n3 4 x\n")), {},
               "malformed PCD data: line 13: 'x' is not a number");
  expect_fails(dir_ / "missing.pcd", {}, "No such file");
  const std::string histogram =
      "VERSION 0.7\nFIELDS h\nSIZE 4\nTYPE F\nCOUNT 2\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2\n";
  expect_fails(file("histogram.pcd", histogram), {"h"}, "field h has COUNT > 1");
}

TEST_F(CloudIo, AnnotatedPcdHeaderIsExact) {
  const std::string bytes = annotated_pcd_bytes(organized_cloud(), {});
  const std::string header =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
      "FIELDS x y z normal_x normal_y normal_z descriptor groove\n"
      "SIZE 4 4 4 4 4 4 4 1\nTYPE F F F F F F F U\nCOUNT 1 1 1 1 1 1 1 1\n"
      "WIDTH 3\nHEIGHT 2\nVIEWPOINT 0.125 -0.3 1e-07 1 0 0 0\nPOINTS 6\nDATA binary\n";
  ASSERT_EQ(bytes.size(), header.size() + 6 * 29);
  EXPECT_EQ(bytes.substr(0, header.size()), header);
}

TEST_F(CloudIo, AnnotatedPcdWithoutAnnotationsHasNaNAndZero) {
  const fs::path p = file("plain.pcd", annotated_pcd_bytes(organized_cloud(), {}));
  pcl::PCLPointCloud2 blob;
  ASSERT_EQ(pcl::PCDReader().read(p.string(), blob), 0);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_TRUE(std::isnan(value_at<float>(blob, i, "normal_y")));
    EXPECT_TRUE(std::isnan(value_at<float>(blob, i, "descriptor")));
    EXPECT_EQ(value_at<std::uint8_t>(blob, i, "groove"), 0);
  }
}

TEST_F(CloudIo, WritersRejectInconsistentInput) {
  const Cloud c = organized_cloud();
  const std::vector<float> short_descriptor(5, 1.0f);
  EXPECT_THROW(annotated_pcd_bytes(c, {nullptr, &short_descriptor, nullptr}), InternalError);
  Normals normals;
  normals.resize(7);
  EXPECT_THROW(annotated_pcd_bytes(c, {&normals, nullptr, nullptr}), InternalError);
  Cloud wrong_shape = c;
  wrong_shape.width = 4;
  EXPECT_THROW(pcd_bytes(wrong_shape), InternalError);
}

TEST_F(CloudIo, PcdBytesRoundTrip) {
  // A cloud built with resize() has width 0; the writer makes it a proper list.
  Cloud c;
  c.resize(150);
  for (std::size_t i = 0; i < c.size(); ++i) {
    c.x[i] = static_cast<float>(i) * 1e-3f;
    c.y[i] = 0.25f;
    c.z[i] = 0.3333333f;
  }
  c.x[9] = c.y[9] = c.z[9] = kNaN;
  const fs::path p = file("plain.pcd", pcd_bytes(c));
  pcl::PointCloud<pcl::PointXYZ> pcl_cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(p.string(), pcl_cloud), 0);
  EXPECT_EQ(pcl_cloud.width, 150u);
  EXPECT_EQ(pcl_cloud.height, 1u);
  EXPECT_EQ(pcl_cloud[77].x, c.x[77]);
  const Cloud back = read_cloud(p.string());
  EXPECT_EQ(back.width, 150u);
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (i == 9) continue;
    EXPECT_EQ(back.x[i], c.x[i]);
    EXPECT_EQ(back.z[i], c.z[i]);
  }
  EXPECT_FALSE(back.valid(9));

  const Cloud organized = organized_cloud();
  const std::string bytes = pcd_bytes(organized);
  EXPECT_NE(bytes.find("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 2\n"),
            std::string::npos);
}

// ---- write_file_atomic -------------------------------------------------------------------

TEST_F(CloudIo, AtomicWriteWritesAndReplaces) {
  const fs::path p = dir_ / "out.bin";
  const std::string first("first\0with a zero byte", 22);
  write_file_atomic(p.string(), first);
  EXPECT_EQ(slurp(p), first);
  write_file_atomic(p.string(), "second");
  EXPECT_EQ(slurp(p), "second");
  EXPECT_EQ(listing(dir_), std::vector<std::string>{"out.bin"}) << "a temporary file was left";
}

TEST_F(CloudIo, AtomicWriteRespectsUmask) {
  const mode_t old = ::umask(022);
  write_file_atomic((dir_ / "mode.txt").string(), "x");
  ::umask(old);
  struct stat st {};
  ASSERT_EQ(::stat((dir_ / "mode.txt").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);
}

TEST_F(CloudIo, AtomicWriteFailuresThrowAndLeaveNothing) {
  const fs::path regular = file("file.txt", "keep");
  auto expect_fails = [&](const fs::path& target, const std::string& phrase) {
    try {
      write_file_atomic(target.string(), "data");
      ADD_FAILURE() << "writing " << target << " succeeded";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("cannot write " + target.string() + ": ", 0), 0u) << msg;
      EXPECT_NE(msg.find(phrase), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos);
    }
  };
  expect_fails(regular / "x.pcd", "Not a directory");
  expect_fails(dir_ / "missing" / "x.pcd", "No such file or directory");
  // The temporary file is written before the rename fails here: it must be removed.
  fs::create_directory(dir_ / "occupied");
  spit(dir_ / "occupied" / "inside", "");
  expect_fails(dir_ / "occupied", "Is a directory");
  EXPECT_EQ(listing(dir_), (std::vector<std::string>{"file.txt", "occupied"}));
  EXPECT_EQ(slurp(regular), "keep");
}

}  // namespace
}  // namespace groovetrace
