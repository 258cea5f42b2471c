// Depth PNG scans (io/depth_png.cpp through read_cloud): 16-bit grey images written with
// libpng here from known depth maps, checked point by point against the pinhole model computed
// here; where the intrinsics are found; and every refusal (one line, InputError).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>

#include "../fuzz/depth_png_seed.hpp"
#include "support/cli_runner.hpp"
#include "support/depth_png_writer.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 64, kH = 48;

struct Pinhole {
  double fx = 60.0, fy = 55.0, ppx = 31.3, ppy = 24.1, scale = 0.0005;
};

std::string json_of(const Pinhole& k, const std::string& extra = "") {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "{\"fx\": %.17g, \"fy\": %.17g, \"ppx\": %.17g, \"ppy\": %.17g, "
                "\"depth_scale\": %.17g",
                k.fx, k.fy, k.ppx, k.ppy, k.scale);
  return std::string(buf) + extra + "}\n";
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// A plane tilted in depth: d = 1000 + col + 3 row units, with zeros at a few pixels.
std::vector<std::uint16_t> plane_depth() {
  std::vector<std::uint16_t> d(kW * kH);
  for (int r = 0; r < kH; ++r) {
    for (int c = 0; c < kW; ++c) d[r * kW + c] = static_cast<std::uint16_t>(1000 + c + 3 * r);
  }
  for (int i : {0, 5, kW * 10 + 7, kW * kH - 1}) d[i] = 0;
  return d;
}

// Every point against x = (col - ppx) z / fx, y = (row - ppy) z / fy, z = d * scale.
void expect_pinhole(const Cloud& cloud, const std::vector<std::uint16_t>& d, const Pinhole& k) {
  ASSERT_EQ(cloud.width, static_cast<std::uint32_t>(kW));
  ASSERT_EQ(cloud.height, static_cast<std::uint32_t>(kH));
  ASSERT_EQ(cloud.size(), d.size());
  EXPECT_EQ(cloud.viewpoint, Eigen::Vector3f::Zero());
  for (int r = 0; r < kH; ++r) {
    for (int c = 0; c < kW; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * kW + c;
      if (d[i] == 0) {
        EXPECT_TRUE(std::isnan(cloud.x[i]) && std::isnan(cloud.y[i]) && std::isnan(cloud.z[i]));
        continue;
      }
      const double z = d[i] * k.scale;
      ASSERT_NEAR(cloud.z[i], z, 1e-6) << r << "," << c;
      ASSERT_NEAR(cloud.x[i], (c - k.ppx) * z / k.fx, 1e-6) << r << "," << c;
      ASSERT_NEAR(cloud.y[i], (r - k.ppy) * z / k.fy, 1e-6) << r << "," << c;
    }
  }
}

class DepthPng : public ::testing::Test {
 protected:
  // A directory per test: ctest runs them in parallel.
  void SetUp() override {
    dir_ = test::fresh_dir(std::string("depth_png_") +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir_); }
  // scan.png with `depth`, its intrinsics in scan.json unless `sidecar` is empty.
  fs::path scan(const std::vector<std::uint16_t>& depth, const std::string& sidecar) {
    const fs::path png = dir_ / "scan.png";
    EXPECT_TRUE(test::write_depth_png(png, kW, kH, depth));
    if (!sidecar.empty()) write_text(dir_ / "scan.json", sidecar);
    return png;
  }
  // The one-line message read_cloud throws as InputError ("" when it does not).
  std::string refusal(const fs::path& png, const std::string& intrinsics = "") {
    ReadOptions ro;
    ro.intrinsics_path = intrinsics;
    ro.min_valid_points = 10;
    try {
      read_cloud(png.string(), ro);
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(DepthPng, APlaneIsDeprojectedPixelByPixel) {
  const Pinhole k;
  const auto depth = plane_depth();
  const fs::path png = scan(depth, json_of(k, ", \"width\": 64, \"height\": 48"));
  ReadOptions ro;
  ro.min_valid_points = 10;
  ro.units_scale = 0.001;  // does not apply to depth images: depth_scale gives metres
  const Cloud cloud = read_cloud(png.string(), ro);
  expect_pinhole(cloud, depth, k);
  EXPECT_EQ(cloud.count_valid(), depth.size() - 4);
}

TEST_F(DepthPng, AnInterlacedImageGivesTheSamePoints) {
  const Pinhole k;
  const auto depth = plane_depth();
  ASSERT_TRUE(test::write_depth_png(dir_ / "scan.PNG", kW, kH, depth, /*interlaced=*/true));
  write_text(dir_ / "scan.json", json_of(k));
  ReadOptions ro;
  ro.min_valid_points = 10;
  expect_pinhole(read_cloud((dir_ / "scan.PNG").string(), ro), depth, k);
}

TEST_F(DepthPng, RealSenseDistortionFieldsWithZeroCoefficientsAreAccepted) {
  const Pinhole k;
  const auto depth = plane_depth();
  for (const std::string model :
       {"\"Brown Conrady\"", "\"distortion.brown_conrady\"", "\"RS2_DISTORTION_NONE\"", "4"}) {
    SCOPED_TRACE(model);
    const fs::path png =
        scan(depth, json_of(k, ", \"model\": " + model + ", \"coeffs\": [0, 0, 0.0, 0, 0]"));
    ReadOptions ro;
    ro.min_valid_points = 10;
    expect_pinhole(read_cloud(png.string(), ro), depth, k);
  }
}

TEST_F(DepthPng, IntrinsicsAreTheFlagsThenTheScansThenTheFolders) {
  const auto depth = plane_depth();
  Pinhole given, stem, folder;
  given.fx = 70;
  stem.fx = 80;
  folder.fx = 90;
  const fs::path png = scan(depth, "");
  ReadOptions ro;
  ro.min_valid_points = 10;
  EXPECT_NE(refusal(png).find("--intrinsics"), std::string::npos) << refusal(png);
  write_text(dir_ / "intrinsics.json", json_of(folder));
  expect_pinhole(read_cloud(png.string(), ro), depth, folder);
  write_text(dir_ / "scan.json", json_of(stem));
  expect_pinhole(read_cloud(png.string(), ro), depth, stem);
  write_text(dir_ / "elsewhere.json", json_of(given));
  ro.intrinsics_path = (dir_ / "elsewhere.json").string();
  expect_pinhole(read_cloud(png.string(), ro), depth, given);
}

TEST_F(DepthPng, BadIntrinsicsAreRefused) {
  const auto depth = plane_depth();
  const Pinhole k;
  const std::map<std::string, std::string> cases = {
      {"not json", "fx: 1"},
      {"a list", "[1, 2]"},
      {"no fx", "{\"fy\": 1, \"ppx\": 1, \"ppy\": 1, \"depth_scale\": 0.001}"},
      {"fx zero", json_of({0.0, 55, 31, 24, 0.001})},
      {"fy negative", json_of({60, -55, 31, 24, 0.001})},
      {"depth_scale zero", json_of({60, 55, 31, 24, 0.0})},
      {"depth_scale text",
       "{\"fx\": 1, \"fy\": 1, \"ppx\": 1, \"ppy\": 1, \"depth_scale\": \"1\"}"},
      {"width wrong", json_of(k, ", \"width\": 640, \"height\": 48")},
      {"height wrong", json_of(k, ", \"height\": 480")},
      {"width zero", json_of(k, ", \"width\": 0")},
      {"distortion", json_of(k, ", \"model\": \"brown_conrady\", \"coeffs\": [0.1, 0, 0, 0, 0]")},
      {"ftheta", json_of(k, ", \"model\": \"ftheta\", \"coeffs\": [0, 0, 0, 0, 0]")},
      {"model 3", json_of(k, ", \"model\": 3")},
      {"deep", std::string(100, '[')},
  };
  for (const auto& [name, text] : cases) {
    SCOPED_TRACE(name);
    const std::string why = refusal(scan(depth, text));
    EXPECT_NE(why.find("scan"), std::string::npos) << why;  // names the file at fault
  }
  EXPECT_NE(refusal(scan(depth, ""), (dir_ / "missing.json").string()).find("missing.json"),
            std::string::npos);
}

TEST_F(DepthPng, ImagesThatAreNoDepthAreRefused) {
  const Pinhole k;
  write_text(dir_ / "scan.json", json_of(k));
  const fs::path png = dir_ / "scan.png";
  std::vector<std::uint16_t> grey8(kW * kH, 100), rgb(kW * kH * 3, 100);
  ASSERT_TRUE(test::write_png(png, {kW, kH, 8, PNG_COLOR_TYPE_GRAY, false}, grey8));
  EXPECT_NE(refusal(png).find("8-bit grey PNG, not a 16-bit grey"), std::string::npos);
  ASSERT_TRUE(test::write_png(png, {kW, kH, 8, PNG_COLOR_TYPE_RGB, false}, rgb));
  EXPECT_NE(refusal(png).find("8-bit colour"), std::string::npos) << refusal(png);
  ASSERT_TRUE(test::write_png(png, {kW, kH, 16, PNG_COLOR_TYPE_RGB, false}, rgb));
  EXPECT_NE(refusal(png).find("16-bit colour"), std::string::npos) << refusal(png);
  write_text(png, "P5\n64 48\n65535\n");
  EXPECT_NE(refusal(png).find("not a PNG"), std::string::npos) << refusal(png);
  ASSERT_TRUE(test::write_depth_png(png, kW, kH, std::vector<std::uint16_t>(kW * kH, 0)));
  EXPECT_NE(refusal(png).find("only 0 pixels with depth"), std::string::npos) << refusal(png);
  write_text(dir_ / "scan.json", json_of({60, 55, 31, 24, 10.0}));  // 10 m per unit
  ASSERT_TRUE(test::write_depth_png(png, kW, kH, plane_depth()));
  EXPECT_NE(refusal(png).find("beyond 1000 m"), std::string::npos) << refusal(png);
}

TEST_F(DepthPng, TruncatedDataIsRefused) {
  const fs::path png = scan(plane_depth(), json_of(Pinhole{}));
  const std::string whole = test::read_text(png);
  // Cut inside the image data, and just before the final IEND chunk (12 bytes).
  for (std::size_t keep : {whole.size() / 2, whole.size() - 12, std::size_t{40}}) {
    SCOPED_TRACE(keep);
    write_text(png, whole.substr(0, keep));
    EXPECT_NE(refusal(png).find("truncated or corrupt"), std::string::npos) << refusal(png);
  }
}

std::uint32_t crc32_of(const std::string& bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void put_be32(std::string& s, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) s[at + k] = static_cast<char>(v >> (24 - 8 * k));
}

TEST_F(DepthPng, AHeaderClaimingAHugeImageIsRefusedBeforeDecoding) {
  const fs::path png = scan(plane_depth(), json_of(Pinhole{}));
  const std::string whole = test::read_text(png);
  // The same file with another size in its header and a valid header CRC, so that only the
  // size check can refuse it before libpng would allocate rows for it.
  auto with_size = [&](std::uint32_t w, std::uint32_t h) {
    std::string s = whole;
    put_be32(s, 16, w);
    put_be32(s, 20, h);
    put_be32(s, 29, crc32_of(s.substr(12, 17)));
    write_text(png, s);
    return refusal(png);
  };
  EXPECT_NE(with_size(16384, 16384).find("more than its"), std::string::npos);
  EXPECT_NE(with_size(4000, 3000).find("more than its"), std::string::npos);
  EXPECT_NE(with_size(20000, 10).find("at most 16384"), std::string::npos);
  EXPECT_NE(with_size(0, 10).find("at most 16384"), std::string::npos);
  // A size the file could hold but does not: libpng finds the data short.
  EXPECT_NE(with_size(kW, kH + 8).find("truncated or corrupt"), std::string::npos);
  // Intrinsics for another size refuse it before the pixels are decoded.
  write_text(dir_ / "scan.json", json_of(Pinhole{}, ", \"width\": 64, \"height\": 48"));
  EXPECT_NE(with_size(kW, kH + 8).find("is 64x56 but its intrinsics"), std::string::npos);
}

TEST_F(DepthPng, AFileBuiltWithoutLibpngReadsBack) {
  // The fuzzers' seed, built byte by byte (a zlib stored block, no libpng): an independent
  // encoder of an 8x6 image of depth 1000.
  write_text(dir_ / "seed.png", fuzz::small_depth_png());
  write_text(dir_ / "intrinsics.json", json_of({60, 55, 3.5, 2.5, 0.001}));
  ReadOptions ro;
  ro.min_valid_points = 48;
  const Cloud cloud = read_cloud((dir_ / "seed.png").string(), ro);
  ASSERT_EQ(cloud.size(), 48u);
  ASSERT_EQ(cloud.width, 8u);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_NEAR(cloud.z[i], 1.0, 1e-6);
    EXPECT_NEAR(cloud.x[i], (static_cast<double>(i % 8) - 3.5) / 60.0, 1e-6);
    EXPECT_NEAR(cloud.y[i], (static_cast<double>(i / 8) - 2.5) / 55.0, 1e-6);
  }
}

}  // namespace
}  // namespace groovetrace
