// CPU reference backend: normals, MLS and the GFH descriptor on analytic geometry.
#include <gtest/gtest.h>

#include <groovetrace/features.hpp>
#include <random>

#include "support/scenes.hpp"

namespace groovetrace {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Angle between two directions; atan2 keeps precision near zero, where acos of a float
// normal's dot product (|n| = 1 +- 6e-8) alone would read 3e-4 rad.
double angle_between(const Eigen::Vector3f& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ad = a.cast<double>();
  return std::atan2(ad.cross(b).norm(), ad.dot(b));
}

Cloud random_plane(const Eigen::Vector3d& normal, const Eigen::Vector3d& origin, int n,
                   double half_extent, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-half_extent, half_extent);
  std::normal_distribution<double> g(0, 1);
  const Eigen::Vector3d a = normal.unitOrthogonal(), b = normal.cross(a);
  Cloud c;
  c.width = n;
  c.resize(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p = origin + u(rng) * a + u(rng) * b + noise * g(rng) * normal;
    c.x[i] = p.x();
    c.y[i] = p.y();
    c.z[i] = p.z();
  }
  return c;
}

TEST(Normals, PlanesAtSeveralPosesPointToViewpoint) {
  auto backend = make_cpu_backend();
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  for (int t = 0; t < 6; ++t) {
    const Eigen::Vector3d n = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Vector3d origin(0.01 * g(rng), 0.01 * g(rng), 0.4);
    Cloud c = random_plane(n, origin, 4000, 0.02, 0.0, t);
    c.viewpoint = Eigen::Vector3f::Zero();
    const Normals normals = backend->normals(c, 0.003f, 5);
    // The expected normal is the plane normal on the viewpoint's side.
    const Eigen::Vector3d expected = n.dot(-origin) > 0 ? n : -n;
    int checked = 0;
    for (std::size_t i = 0; i < c.size(); ++i) {
      ASSERT_TRUE(normals.valid(i)) << i;
      const double angle = angle_between(normals.normal(i), expected);
      EXPECT_LT(angle, 0.01 * kDeg) << "pose " << t << " point " << i;
      ++checked;
    }
    EXPECT_EQ(checked, 4000);
  }
}

TEST(Normals, TooFewNeighboursGiveNoNormal) {
  auto backend = make_cpu_backend();
  Cloud c = random_plane(Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, 0, 0.5), 2000, 0.01, 0, 1);
  // An isolated point far from the plate, and a NaN point.
  c.x.push_back(0.2f), c.y.push_back(0.2f), c.z.push_back(0.5f);
  c.x.push_back(NAN), c.y.push_back(NAN), c.z.push_back(NAN);
  c.width = c.size();
  const Normals normals = backend->normals(c, 0.003f, 5);
  EXPECT_FALSE(normals.valid(c.size() - 2));
  EXPECT_FALSE(normals.valid(c.size() - 1));
  EXPECT_TRUE(normals.valid(0));
  const Eigen::Vector3f ub = benchmark_normal(normals);
  const std::vector<float> d = backend->descriptor(c, normals, 0.003f, ub);
  EXPECT_TRUE(std::isnan(d[c.size() - 2]));
  EXPECT_TRUE(std::isnan(d[c.size() - 1]));
}

// Normals on a rendered V at several camera poses: flats give the plate normal, walls the
// analytic wall normal, away from creases by more than the radius.
TEST(Normals, AnalyticVGrooveAtSeveralPoses) {
  auto backend = make_cpu_backend();
  const double r = 0.003;
  for (double tilt : {0.0, 15.0, 25.0}) {
    for (double yaw : {0.0, 40.0}) {
      test::VGrooveScene s;
      s.tilt_deg = tilt;
      s.yaw_deg = yaw;
      s.top_width = 0.020;  // wide enough for wall points farther than r from both creases
      s.depth = 0.008;
      const auto scene = test::render_vgroove(s);
      const Normals normals = backend->normals(scene.cloud, r, 5);
      const Eigen::Isometry3d T_world_camera = scene.T_world_camera;
      const Eigen::Matrix3d R_camera_world = T_world_camera.linear().transpose();
      const double half = s.top_width / 2, slope = s.depth / half;
      const Eigen::Vector3d n_flat = R_camera_world * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d n_left = R_camera_world * Eigen::Vector3d(slope, 0, 1).normalized();
      const Eigen::Vector3d n_right = R_camera_world * Eigen::Vector3d(-slope, 0, 1).normalized();
      int flats = 0, walls = 0;
      for (std::size_t i = 0; i < scene.cloud.size(); ++i) {
        if (!scene.cloud.valid(i)) continue;
        const Eigen::Vector3d p_world = T_world_camera * scene.cloud.point(i).cast<double>();
        const double x = p_world.x();
        Eigen::Vector3d expected;
        // Distance from every crease (edges at +-half, root at 0) measured across the seam;
        // walls are steep, so keep a margin of r in 3-D (r * |slope| more across).
        if (std::abs(x) > half + r) {
          expected = n_flat;
          ++flats;
        } else if (x < -r && x > -half + r) {
          expected = n_left;
          ++walls;
        } else if (x > r && x < half - r) {
          expected = n_right;
          ++walls;
        } else {
          continue;
        }
        ASSERT_TRUE(normals.valid(i));
        const double angle = angle_between(normals.normal(i), expected);
        ASSERT_LT(angle, 0.05 * kDeg) << "tilt " << tilt << " yaw " << yaw << " x " << x;
      }
      EXPECT_GT(flats, 100000);
      EXPECT_GT(walls, 100);
    }
  }
}

TEST(Descriptor, HighAtTheCreaseNearZeroOnFlats) {
  auto backend = make_cpu_backend();
  test::VGrooveScene s;
  s.tilt_deg = 10;
  const auto scene = test::render_vgroove(s);
  const float r = 0.003f;
  const Normals normals = backend->normals(scene.cloud, r, 5);
  const Eigen::Vector3f ub = benchmark_normal(normals);
  // Most of the frame is the plate: the benchmark normal is the plate normal.
  EXPECT_GT(ub.cast<double>().dot(scene.up_camera), std::cos(2 * kDeg));
  const std::vector<float> d = backend->descriptor(scene.cloud, normals, r, ub);
  const double half = s.top_width / 2;
  double max_flat = 0, min_root = 1e9;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (!scene.cloud.valid(i)) continue;
    const double x = (scene.T_world_camera * scene.cloud.point(i).cast<double>()).x();
    if (std::abs(x) > half + 2 * r) max_flat = std::max(max_flat, static_cast<double>(d[i]));
    if (std::abs(x) < 0.5e-3) min_root = std::min(min_root, static_cast<double>(d[i]));
  }
  // Flats: every normal equals u_b, all angles zero up to float rounding.
  EXPECT_LT(max_flat, 0.05);
  // At the root the neighbourhood holds both walls (+-51 deg apart): the variances are large,
  // far above the paper's threshold range 4.5-5.
  EXPECT_GT(min_root, 100.0);
}

TEST(Descriptor, MatchesHandComputedNeighbourhood) {
  // Three collinear points with chosen normals: everything is a neighbour of everything.
  Cloud c;
  c.x = {0, 0.001f, 0.002f};
  c.y = {0, 0, 0};
  c.z = {0.5f, 0.5f, 0.5f};
  c.width = 3;
  Normals n;
  n.resize(3);
  const Eigen::Vector3f ns[3] = {Eigen::Vector3f(0, 0, -1),
                                 Eigen::Vector3f(0, std::sin(0.2f), -std::cos(0.2f)),
                                 Eigen::Vector3f(0, -std::sin(0.4f), -std::cos(0.4f))};
  for (int i = 0; i < 3; ++i) {
    n.x[i] = ns[i].x(), n.y[i] = ns[i].y(), n.z[i] = ns[i].z();
  }
  const Eigen::Vector3f ub(0, 0, -1);
  const std::vector<float> d = make_cpu_backend()->descriptor(c, n, 0.01f, ub);
  auto var = [](std::vector<double> v) {
    double m = 0, s = 0;
    for (double x : v) m += x;
    m /= v.size();
    for (double x : v) s += (x - m) * (x - m);
    return s / v.size();
  };
  const double a1 = 0.2 / kDeg, a2 = 0.4 / kDeg, a12 = 0.6 / kDeg;
  // Point 0: local angles to 1 and 2; global angles of 0, 1, 2 to u_b.
  const double l0 = var({a1, a2}), g = var({0, a1, a2});
  EXPECT_NEAR(d[0], std::sqrt(l0 * l0 + g * g), 1e-2);
  const double l1 = var({a1, a12});
  EXPECT_NEAR(d[1], std::sqrt(l1 * l1 + g * g), 1e-2);
}

TEST(Smoothing, ReducesNoiseOnAPlaneAndKeepsExactPlanes) {
  auto backend = make_cpu_backend();
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.3, 1).normalized();
  const Eigen::Vector3d origin(0, 0, 0.45);
  SmoothParams sp;
  sp.radius = 0.003f;
  for (int order : {1, 2}) {
    sp.order = order;
    const Cloud exact = random_plane(n, origin, 20000, 0.02, 0.0, 2);
    const Cloud smoothed_exact = backend->smooth(exact, sp);
    Cloud noisy = random_plane(n, origin, 20000, 0.02, 0.0005, 2);
    const Cloud smoothed = backend->smooth(noisy, sp);
    double before = 0, after = 0, moved_exact = 0;
    int count = 0;
    for (std::size_t i = 0; i < noisy.size(); ++i) {
      const double di = (noisy.point(i).cast<double>() - origin).dot(n);
      const double ds = (smoothed.point(i).cast<double>() - origin).dot(n);
      // Skip the border strip where the neighbourhood is one-sided.
      const Eigen::Vector3d q = exact.point(i).cast<double>() - origin;
      if (q.cwiseAbs().maxCoeff() > 0.017) continue;
      before += di * di;
      after += ds * ds;
      moved_exact = std::max(moved_exact, (smoothed_exact.point(i) - exact.point(i)).norm() * 1.0);
      ++count;
    }
    EXPECT_LT(std::sqrt(after / count), 0.5 * std::sqrt(before / count)) << "order " << order;
    EXPECT_LT(moved_exact, 2e-6) << "order " << order;
  }
}

TEST(Backend, FactoryNames) {
  EXPECT_EQ(make_backend("cpu")->name(), "cpu");
  EXPECT_THROW(make_backend("gpu"), std::exception);
}

}  // namespace
}  // namespace groovetrace
