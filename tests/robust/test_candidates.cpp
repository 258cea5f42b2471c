// Concave-crease candidates (robust/candidates.cpp): a groove's root is concave, a convex edge
// is not, and the threshold follows the scan's own noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "robust/stages.hpp"
#include "support/robust_scenes.hpp"

namespace groovetrace {
namespace {

// Concavity (m) of the voxel nearest the world point (x, y, z).
double concavity_at(const CreaseMap& m, const test::HeightRender& r, const Eigen::Vector3d& w) {
  const Eigen::Vector3d c = r.to_camera(w);
  double best = INFINITY, value = NAN;
  for (std::size_t v = 0; v < m.points.size(); ++v) {
    const double d = (m.points[v].cast<double>() - c).norm();
    if (d < best) {
      best = d;
      value = m.concavity[v];
    }
  }
  return value;
}

TEST(RobustCandidates, RootIsConcaveConvexEdgeIsNot) {
  test::TopCamera cam;
  cam.noise = 0.0002;
  const test::HeightRender box = test::render_box(cam, true);
  const CreaseMap m = crease_map(box.cloud, RobustParams{});
  ASSERT_FALSE(m.points.empty());
  // The root of the groove on the block's top (6 mm deep): well above the threshold.
  EXPECT_GT(concavity_at(m, box, {0.0, 0.0, 0.024}), m.threshold);
  // The block's convex top edge and a flat: below it.
  EXPECT_LT(concavity_at(m, box, {0.0, 0.04, 0.03}), m.threshold);
  EXPECT_LT(concavity_at(m, box, {0.03, 0.02, 0.03}), m.threshold);
  EXPECT_LT(concavity_at(m, box, {0.06, 0.03, 0.03}), 0.6 * m.threshold);  // convex end edge
  EXPECT_LT(concavity_at(m, box, {0.03, 0.04, 0.03}), 0.6 * m.threshold);  // convex side edge
  // Nodes: the deepest across the seam, most of them on the groove's root line.
  const CreaseNodes nodes = crease_nodes(m, RobustParams{});
  int on_root = 0;
  for (std::int32_t v : nodes.voxel) {
    const Eigen::Vector3d w = box.T_world_camera * m.points[v].cast<double>();
    on_root += std::abs(w.y()) < 0.002 && w.z() > 0.02 ? 1 : 0;
  }
  EXPECT_GT(on_root, 40);  // of a 120 mm root line
}

TEST(RobustCandidates, ThresholdFollowsTheScansNoise) {
  test::TopCamera quiet, loud;
  quiet.noise = 0.0001;
  loud.noise = 0.0006;
  const std::vector<Eigen::Vector2d> line = {{-0.1, 0.0}, {0.1, 0.0}};
  const CreaseMap a = crease_map(test::render_plate_groove(line, false, quiet).cloud, {});
  const CreaseMap b = crease_map(test::render_plate_groove(line, false, loud).cloud, {});
  EXPECT_GT(b.sigma, 2 * a.sigma);
  EXPECT_GT(b.threshold, a.threshold);
  // Relative to the noise the threshold is the same rule: median + k sigma (or the floor).
  const RobustParams p;
  EXPECT_NEAR(b.threshold, b.median + std::max(p.threshold_k * b.sigma, 0.01 * p.scale), 1e-9);
}

TEST(RobustCandidates, DepthOnMillimetreLevelsKeepsItsVoxels) {
  // A camera-frame plane whose depths are quantized to 1 mm (a D415's depth unit): +-0.5 um
  // more depth must leave every voxel as it was (with the voxel grid's planes on the 1 mm
  // levels, float rounding put half the points in the voxel below, and the noise moved them).
  Cloud c, moved;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> tiny(-0.5e-6f, 0.5e-6f);
  for (int row = 0; row < 120; ++row) {
    for (int col = 0; col < 160; ++col) {
      const double x = (col - 80) * 0.0006, y = (row - 60) * 0.0006;
      const float z = static_cast<float>(std::round((0.4 + 0.2 * x + 0.05 * y) * 1000) / 1000);
      c.x.push_back(static_cast<float>(x));
      c.y.push_back(static_cast<float>(y));
      c.z.push_back(z);
      moved.x.push_back(static_cast<float>(x));
      moved.y.push_back(static_cast<float>(y));
      moved.z.push_back(z + tiny(rng));
    }
  }
  c.width = moved.width = static_cast<std::uint32_t>(c.x.size());
  const CreaseMap a = crease_map(c, RobustParams{});
  const CreaseMap b = crease_map(moved, RobustParams{});
  ASSERT_EQ(a.points.size(), b.points.size());
  std::size_t same = 0;
  for (std::size_t i = 0; i < c.size(); ++i) same += a.voxel[i] == b.voxel[i] ? 1 : 0;
  EXPECT_EQ(same, c.size());
}

}  // namespace
}  // namespace groovetrace
