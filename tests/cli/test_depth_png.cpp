// `run` and `batch` on depth PNGs: a synthetic D415 scan's depth written as a 16-bit PNG with
// the renderer's intrinsics (here, independently of the reader) is the same scan, and the
// groove is found where the ground truth has it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/synth.hpp>
#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"
#include "support/depth_png_writer.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 640, kH = 480;
constexpr double kScale = 0.0001;  // 0.1 mm per unit, a D415 option

// Renders a straight V with `groovetrace synth` and stores its depth as `png` with the
// intrinsics of the renderer's camera in `json`. Returns the scan's PCD path.
fs::path synth_depth_png(const fs::path& dir, const fs::path& png, const fs::path& json) {
  const fs::path pcd = dir / "scan.pcd";
  const auto r = test::run_cli(
      "synth --shape straight --seed 4 --width 640 --height 480 -o " + pcd.string(), dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const Cloud cloud = read_cloud(pcd.string());
  const CameraModel cam = d415_camera(kW, kH);
  std::vector<std::uint16_t> depth(cloud.size(), 0);
  double worst = 0;  // the renderer's points lie on these intrinsics' rays
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    depth[i] = static_cast<std::uint16_t>(std::lround(cloud.z[i] / kScale));
    const double col = static_cast<double>(i % kW), row = static_cast<double>(i / kW);
    worst = std::max(worst, std::abs(cloud.x[i] - (col - cam.cx) * cloud.z[i] / cam.fx));
    worst = std::max(worst, std::abs(cloud.y[i] - (row - cam.cy) * cloud.z[i] / cam.fy));
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_TRUE(test::write_depth_png(png, kW, kH, depth));
  nlohmann::json k = {{"width", kW},
                      {"height", kH},
                      {"fx", cam.fx},
                      {"fy", cam.fy},
                      {"ppx", cam.cx},
                      {"ppy", cam.cy},
                      {"depth_scale", kScale},
                      {"model", "distortion.brown_conrady"},
                      {"coeffs", {0, 0, 0, 0, 0}}};
  std::ofstream(json) << k.dump(2) << "\n";
  return pcd;
}

TEST(CliDepthPng, RunFindsTheGrooveOfASynthScanStoredAsADepthPng) {
  const fs::path dir = test::fresh_dir("depth_png_run");
  const fs::path png = dir / "capture" / "depth.png";
  fs::create_directories(png.parent_path());
  const fs::path pcd = synth_depth_png(dir, png, dir / "camera.json");

  // Without intrinsics: exit 3, report.json alone says why.
  const auto missing = test::run_cli("run " + png.string() + " -o " + (dir / "out").string(), dir);
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_NE(missing.err.find("--intrinsics"), std::string::npos) << missing.err;
  test::expect_failure_report(dir / "out", 3, missing.err);

  const auto r =
      test::run_cli("run " + png.string() + " --intrinsics " + (dir / "camera.json").string() +
                        " --backend cpu -q -o " + (dir / "out").string(),
                    dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(dir / "out" / "report.json"));
  EXPECT_EQ(report["status"], "ok");
  // The truth files beside scan.pcd score the PNG run: same pixels, same geometry.
  const auto e =
      test::run_cli("eval --truth " + pcd.string() + " --result " + (dir / "out").string(), dir);
  ASSERT_EQ(e.exit_code, 0) << e.err;
  const auto m = nlohmann::json::parse(test::read_text(dir / "out" / "metrics.json"));
  EXPECT_GT(m["detection"]["iou_percent"].get<double>(), 50.0) << m.dump();
  EXPECT_LT(m["trajectory"]["distance_mean_m"].get<double>(), 0.001) << m.dump();
  EXPECT_GT(m["trajectory"]["coverage_percent"].get<double>(), 90.0) << m.dump();
  fs::remove_all(dir);
}

TEST(CliDepthPng, BatchTakesDepthPngsWithIntrinsicsAndNotItsOwnPictures) {
  const fs::path dir = test::fresh_dir("depth_png_batch");
  const fs::path in = dir / "in";
  fs::create_directories(in / "photos");
  synth_depth_png(dir, in / "depth.png", in / "depth.json");
  // A photo without intrinsics is no scan.
  ASSERT_TRUE(test::write_png(in / "photos" / "plate.png", {8, 8, 8, PNG_COLOR_TYPE_RGB, false},
                              std::vector<std::uint16_t>(8 * 8 * 3, 128)));
  const fs::path out = in / "night";  // OUTDIR inside INPUT: its pictures are no scans
  for (int pass = 0; pass < 2; ++pass) {
    SCOPED_TRACE(pass);
    const auto r = test::run_cli(
        "batch " + in.string() + " -o " + out.string() + " --backend cpu --jobs 1 --progress none",
        dir);
    EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
    const std::string csv = test::read_text(out / "summary.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 2) << csv;  // header + depth.png
    EXPECT_NE(csv.find("depth.png"), std::string::npos) << csv;
  }
  EXPECT_TRUE(fs::exists(out / "depth" / "overview.png"));
  // With --intrinsics every PNG found is a depth scan: the photo is a row, not 16-bit depth.
  const auto r =
      test::run_cli("batch " + in.string() + " -o " + out.string() + " --intrinsics " +
                        (in / "depth.json").string() + " --backend cpu --jobs 1 --progress none",
                    dir);
  EXPECT_EQ(r.exit_code, 6) << r.err << r.out;
  const std::string csv = test::read_text(out / "summary.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
  EXPECT_NE(csv.find("photos/plate.png"), std::string::npos) << csv;
  EXPECT_NE(csv.find("not a 16-bit grey depth image"), std::string::npos) << csv;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace groovetrace
