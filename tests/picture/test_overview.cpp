// overview.png on analytic scenes with known geometry: the shading and tint, where seams land
// in a pinhole and in a top view, the caption, thumbnails, and degenerate inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <groovetrace/frames.hpp>

#include "picture/overview.hpp"
#include "picture/view.hpp"
#include "support/png_reader.hpp"
#include "support/scenes.hpp"

namespace groovetrace::picture {
namespace {

test::VGrooveScene tilted_scene() {
  test::VGrooveScene s;  // 640x480 at 0.4 m, 10 mm wide, 4 mm deep groove
  s.tilt_deg = 12;
  s.yaw_deg = 8;
  return s;
}

// Waypoints every 4 mm on the true root line, +-40 mm around the scene's root point; the
// torch along the plate normal.
Trajectory root_trajectory(const test::RenderedScene& sc) {
  Trajectory t;
  t.direction = sc.groove_dir_camera;
  t.length = 0.08;
  for (int i = 0; i <= 20; ++i) {
    Waypoint w;
    w.position = sc.root_point_camera + (-0.04 + 0.004 * i) * sc.groove_dir_camera;
    w.orientation = tool_orientation(sc.up_camera, sc.groove_dir_camera);
    t.waypoints.push_back(w);
  }
  return t;
}

// Where the scene's camera puts p_camera (m): pixel u has its centre at u + 0.5.
Eigen::Vector2d known_pixel(const test::VGrooveScene& s, const Eigen::Vector3d& p) {
  const double f = 0.5 * s.width / std::tan(32.5 * M_PI / 180.0);
  return {f * p.x() / p.z() + 0.5 * s.width + 0.5, f * p.y() / p.z() + 0.5 * s.height + 0.5};
}

bool near_colour(Rgb a, Rgb b, int tol) {
  return std::abs(a.r - b.r) <= tol && std::abs(a.g - b.g) <= tol && std::abs(a.b - b.b) <= tol;
}

// Whether a pixel of colour c lies within `radius` pixels of p.
bool colour_near(const Raster& r, const Eigen::Vector2d& p, Rgb c, int radius) {
  const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y()));
  for (int y = y0 - radius; y <= y0 + radius; ++y) {
    for (int x = x0 - radius; x <= x0 + radius; ++x) {
      if (r.inside(x, y) && near_colour(r.at(x, y), c, 30)) return true;
    }
  }
  return false;
}

Cloud unorganized(const Cloud& organized) {
  Cloud c;
  for (std::size_t i = 0; i < organized.size(); ++i) {
    if (!organized.valid(i)) continue;
    c.x.push_back(organized.x[i]);
    c.y.push_back(organized.y[i]);
    c.z.push_back(organized.z[i]);
  }
  c.width = static_cast<std::uint32_t>(c.size());
  return c;
}

TEST(Overview, GroovePixelsAreTintedAndFlatOnesGrey) {
  const test::RenderedScene sc = test::render_vgroove(test::VGrooveScene{});
  const std::vector<Trajectory> none;
  const Raster r = render_overview(OverviewInput(sc.cloud, sc.label, none));
  ASSERT_EQ(r.width(), 640);  // the frame's own size, the caption bar below
  ASSERT_GT(r.height(), 480);
  const int row = 240;
  int groove_col = -1;
  for (int c = 0; c < 640 && groove_col < 0; ++c) {
    if (sc.label[row * 640 + c]) groove_col = c + 2;  // inside the wall, off its edge
  }
  ASSERT_GE(groove_col, 0);
  ASSERT_TRUE(sc.label[row * 640 + groove_col]);
  const Rgb g = r.at(groove_col, row);
  EXPECT_GT(g.r, g.b + 80) << int(g.r) << " " << int(g.g) << " " << int(g.b);
  const Rgb flat = r.at(groove_col + 80, row);
  ASSERT_FALSE(sc.label[row * 640 + groove_col + 80]);
  EXPECT_EQ(flat.r, flat.g);
  EXPECT_EQ(flat.g, flat.b);
  EXPECT_GT(flat.r, 100);  // lit: the plate faces the camera
}

TEST(Overview, PinholeViewRecoversTheSceneCamera) {
  const test::VGrooveScene s = tilted_scene();
  const test::RenderedScene sc = test::render_vgroove(s);
  const View v = pinhole_view(sc.cloud, 0);
  ASSERT_EQ(v.kind, View::Kind::pinhole);
  EXPECT_EQ(v.width, 640);
  EXPECT_EQ(v.height, 480);
  for (const Waypoint& w : root_trajectory(sc).waypoints) {
    EXPECT_LT((v.project(w.position) - known_pixel(s, w.position)).norm(), 0.5);
  }
  // A frame mirrored left-right is no pinhole image of its own points: no pinhole view.
  Cloud mirrored = sc.cloud;
  for (float& x : mirrored.x) x = -x;
  EXPECT_EQ(pinhole_view(mirrored, 0).width, 0);
  EXPECT_EQ(pinhole_view(unorganized(sc.cloud), 0).width, 0);
}

TEST(Overview, WaypointsLandOnTheRootsProjection) {
  const test::VGrooveScene s = tilted_scene();
  const test::RenderedScene sc = test::render_vgroove(s);
  const std::vector<Trajectory> seams = {root_trajectory(sc)};
  const Raster r = render_overview(OverviewInput(sc.cloud, sc.label, seams));
  for (const Waypoint& w : seams[0].waypoints) {
    EXPECT_TRUE(colour_near(r, known_pixel(s, w.position), seam_colour(0), 2))
        << w.position.transpose();
  }
}

TEST(Overview, TrajectoriesInTheBaseFrameAreDrawnInTheCloudsFrame) {
  const test::RenderedScene sc = test::render_vgroove(tilted_scene());
  const std::vector<Trajectory> camera = {root_trajectory(sc)};
  Eigen::Isometry3d T_base_camera = Eigen::Isometry3d::Identity();
  T_base_camera.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  T_base_camera.pretranslate(Eigen::Vector3d(0.4, -0.1, 0.3));
  std::vector<Trajectory> base = camera;
  transform_trajectory(base[0], T_base_camera);
  const Raster a = render_overview(OverviewInput(sc.cloud, sc.label, camera));
  OverviewInput in(sc.cloud, sc.label, base);
  in.T_cloud_trajectory = T_base_camera.inverse();
  const Raster b = render_overview(in);
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  int differ = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) differ += near_colour(a.at(x, y), b.at(x, y), 2) ? 0 : 1;
  }
  EXPECT_EQ(differ, 0);
}

TEST(Overview, TopViewOfAnUnorganizedCloudDrawsThePathInside) {
  const test::RenderedScene sc = test::render_vgroove(tilted_scene());
  const Cloud cloud = unorganized(sc.cloud);  // viewpoint: the camera at the origin
  const std::vector<std::uint8_t> no_labels;
  const std::vector<Trajectory> seams = {root_trajectory(sc)};
  const Raster r = render_overview(OverviewInput(cloud, no_labels, seams));
  const View v = top_view(cloud, cloud.viewpoint, 0);
  EXPECT_EQ(std::max(v.width, v.height), 800);
  EXPECT_EQ(r.width(), v.width);
  for (const Waypoint& w : seams[0].waypoints) {
    const Eigen::Vector2d p = v.project(w.position);
    ASSERT_TRUE(p.x() >= 0 && p.y() >= 0 && p.x() < v.width && p.y() < v.height) << p;
    EXPECT_TRUE(colour_near(r, p, seam_colour(0), 2)) << p.transpose();
  }
  // Seen from the camera, not mirrored: camera x goes right and camera y down.
  const Eigen::Vector3d c = sc.root_point_camera;
  EXPECT_GT(v.project(c + Eigen::Vector3d(0.01, 0, 0)).x(), v.project(c).x() + 5);
  EXPECT_GT(v.project(c + Eigen::Vector3d(0, 0.01, 0)).y(), v.project(c).y() + 5);
}

TEST(Overview, CaptionTextIsDrawnInTheBar) {
  const test::RenderedScene sc = test::render_vgroove(test::VGrooveScene{});
  const std::vector<Trajectory> none;
  OverviewInput in(sc.cloud, sc.label, none);
  const Raster blank = render_overview(in);
  in.caption = caption_line("scan.pcd", "robust", none, "ok");
  const Raster text = render_overview(in);
  ASSERT_EQ(blank.height(), text.height());
  const Rgb bar = blank.at(0, blank.height() - 1);
  int ink = 0;
  for (int y = 480; y < blank.height(); ++y) {
    for (int x = 0; x < blank.width(); ++x) {
      ASSERT_EQ(blank.at(x, y), bar);  // an empty caption leaves the bar plain
      ink += text.at(x, y) != bar ? 1 : 0;
    }
  }
  EXPECT_GT(ink, 200);
  // A caption too long for the picture keeps its end (the status).
  in.caption = std::string(300, 'x') + " ok";
  EXPECT_NO_THROW(render_overview(in, kThumbnailSide));
}

TEST(Overview, CaptionLineNamesFileMethodSeamsLengthsAndStatus) {
  Trajectory a, b;
  a.length = 0.0984;
  b.length = 0.041;
  EXPECT_EQ(caption_line("scan.pcd", "robust", {a}, "ok"), "scan.pcd  robust  1 seam  98.4 mm  ok");
  EXPECT_EQ(caption_line("s.ply", "paper", {a, b}, "1 warning"),
            "s.ply  paper  2 seams  98.4 + 41.0 mm  1 warning");
  EXPECT_EQ(caption_line("s.pcd", "robust", {a, b, a, b}, "ok"),
            "s.pcd  robust  4 seams  278.8 total mm  ok");
  EXPECT_EQ(caption_line("s.pcd", "robust", {}, "no groove"), "s.pcd  robust  0 seams  no groove");
}

TEST(Overview, ThumbnailsHaveTheirLongSide) {
  const test::RenderedScene sc = test::render_vgroove(tilted_scene());
  const std::vector<Trajectory> seams = {root_trajectory(sc)};
  OverviewInput in(sc.cloud, sc.label, seams);
  in.caption = "scan.pcd  robust  1 seam  80.0 mm  ok";
  const test::DecodedPng organized = test::decode_png(overview_png(in, kThumbnailSide));
  ASSERT_TRUE(organized.ok);
  EXPECT_EQ(organized.width, 240u);
  EXPECT_GT(organized.height, 180u);  // 180 rows of picture and the caption bar
  EXPECT_LT(organized.height, 200u);
  const Cloud cloud = unorganized(sc.cloud);
  const std::vector<std::uint8_t> no_labels;
  const Raster top = render_overview(OverviewInput(cloud, no_labels, seams), kThumbnailSide);
  EXPECT_EQ(top.width(), 240);  // the scan is wider than high
}

TEST(Overview, EmptyAndDegenerateInputsGiveAPicture) {
  const std::vector<Trajectory> none;
  const std::vector<std::uint8_t> no_labels;
  Cloud empty;
  Cloud all_nan;
  all_nan.width = 64;
  all_nan.height = 48;
  all_nan.resize(64 * 48);
  std::fill(all_nan.x.begin(), all_nan.x.end(), NAN);
  Cloud one;
  one.x = {0.1f};
  one.y = {0.2f};
  one.z = {0.5f};
  one.width = 1;
  Trajectory no_waypoints, one_waypoint;
  one_waypoint.waypoints.resize(1);
  one_waypoint.waypoints[0].position = Eigen::Vector3d(0.1, 0.2, 0.5);
  const std::vector<Trajectory> odd = {no_waypoints, one_waypoint};
  for (const Cloud* c : {&empty, &all_nan, &one}) {
    for (const auto* t : {&none, &odd}) {
      const test::DecodedPng png =
          test::decode_png(overview_png(OverviewInput(*c, no_labels, *t), 0));
      EXPECT_TRUE(png.ok);
      EXPECT_GT(png.width, 0u);
    }
  }
  const test::RenderedScene sc = test::render_vgroove(test::VGrooveScene{});
  EXPECT_TRUE(test::decode_png(overview_png(OverviewInput(sc.cloud, sc.label, none))).ok);
}

}  // namespace
}  // namespace groovetrace::picture
