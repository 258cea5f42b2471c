// `groovetrace run` writes overview.png: a PNG of the scan's size with the seam drawn where
// the scan shows it, whether the trajectories stay in the camera frame or go to the base.
#include <gtest/gtest.h>

#include <groovetrace/cloud_io.hpp>

#include "support/cli_runner.hpp"
#include "support/png_reader.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

TEST(CliOverview, RunWritesOverviewPngInTheScansFrame) {
  const fs::path dir = test::fresh_dir("CliOverview");
  test::VGrooveScene s = test::repeated_run_scene();  // 640x480 at 0.4 m (small: 320x240)
  s.tilt_deg = 12;
  s.yaw_deg = 8;
  s.noise_sigma = 0.0002;
  const fs::path scan = dir / "scan.pcd";
  write_file_atomic(scan.string(), pcd_bytes(test::render_vgroove(s).cloud));
  // A hand-eye and a flange pose far from identity: the base frame is not the camera's.
  write_file_atomic((dir / "he.yaml").string(),
                    "translation: [0.03, 0.0, 0.12]\nrotation: [0.0, 0.0, 0.7071068, 0.7071068]\n");
  write_file_atomic((dir / "fl.yaml").string(),
                    "translation: [0.412, -0.137, 0.305]\nrotation: [1.0, 0.0, 0.0, 0.0]\n");
  const std::string common = "run " + scan.string() + " --backend cpu -o ";
  // Identity calibration: the same frame, but no camera-frame warning in the caption.
  const auto camera = test::run_cli(
      common + (dir / "camera").string() + " " + test::identity_calibration(dir), dir);
  ASSERT_EQ(camera.exit_code, 0) << camera.err;
  EXPECT_NE(camera.out.find("overview.png"), std::string::npos) << camera.out;
  const auto base =
      test::run_cli(common + (dir / "base").string() + " --hand-eye " + (dir / "he.yaml").string() +
                        " --flange-pose " + (dir / "fl.yaml").string(),
                    dir);
  ASSERT_EQ(base.exit_code, 0) << base.err;

  const test::DecodedPng a = test::decode_png(test::read_text(dir / "camera" / "overview.png"));
  const test::DecodedPng b = test::decode_png(test::read_text(dir / "base" / "overview.png"));
  ASSERT_TRUE(a.ok);
  ASSERT_TRUE(b.ok);
  EXPECT_EQ(a.width, static_cast<std::uint32_t>(s.width));  // the scan's own size, a caption below
  EXPECT_GT(a.height, static_cast<std::uint32_t>(s.height));
  EXPECT_EQ(a.colour_type, PNG_COLOR_TYPE_RGB);
  // The seam is drawn in the scan's frame either way: the pictures agree.
  ASSERT_EQ(a.height, b.height);
  int differ = 0;
  for (std::size_t y = 0; y < a.rows.size(); ++y) {
    for (std::size_t x = 0; x < a.rows[y].size(); ++x) {
      differ += std::abs(int(a.rows[y][x]) - int(b.rows[y][x])) > 2 ? 1 : 0;
    }
  }
  EXPECT_EQ(differ, 0);
}

}  // namespace
}  // namespace groovetrace
