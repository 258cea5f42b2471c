// The OpenCL backend against the CPU reference, on organized and unorganized scans with and
// without noise, and on the edge cases of the neighbour search. Skipped when no OpenCL device
// exists. Tolerances (per point, over the points valid in either backend):
// - normals: within 0.5 deg for at least 99.9% of points (NaN must match NaN);
// - descriptor, from the same normals: |D_cl - D_cpu| <= 1e-3 |D_cpu| + 1e-6 deg^2 for at least
//   99.9% of points (the floor covers exact zeros on noiseless planes);
// - smoothing: the same point within 1 um for at least 99.9% of points;
// - groove labels (D > 4.5 after each backend's own smoothing, normals and descriptor):
//   identical for at least 99.9% of points.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <groovetrace/features.hpp>
#include <groovetrace/opencl.hpp>
#include <groovetrace/pipeline.hpp>
#include <numeric>
#include <random>

#include "support/opencl_support.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

constexpr float kRadius = 0.003f;
constexpr double kShare = 0.999;

// Share of points whose normals agree (both NaN, or both set and within max_deg).
double normals_agree(const Normals& ref, const Normals& got, double max_deg) {
  EXPECT_EQ(ref.size(), got.size());
  std::size_t good = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (ref.valid(i) != got.valid(i)) continue;
    if (!ref.valid(i) || test::angle_deg(ref.normal(i), got.normal(i)) <= max_deg) ++good;
  }
  return ref.size() ? static_cast<double>(good) / ref.size() : 1.0;
}

double descriptors_agree(const std::vector<float>& ref, const std::vector<float>& got) {
  EXPECT_EQ(ref.size(), got.size());
  std::size_t good = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const bool rn = std::isnan(ref[i]), gn = std::isnan(got[i]);
    if (rn || gn) {
      good += rn == gn ? 1 : 0;
      continue;
    }
    good += std::abs(got[i] - ref[i]) <= 1e-3 * std::abs(ref[i]) + 1e-6 ? 1 : 0;
  }
  return ref.size() ? static_cast<double>(good) / ref.size() : 1.0;
}

double clouds_agree(const Cloud& ref, const Cloud& got, double max_m) {
  EXPECT_EQ(ref.size(), got.size());
  std::size_t good = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (ref.valid(i) != got.valid(i)) continue;
    if (!ref.valid(i) || (ref.point(i) - got.point(i)).norm() <= max_m) ++good;
  }
  return ref.size() ? static_cast<double>(good) / ref.size() : 1.0;
}

// The rendered V-groove with D415-like depth noise and holes: 2% single NaN pixels and a
// 40x30 pixel stereo shadow.
Cloud noisy_frame() {
  test::VGrooveScene s;
  s.tilt_deg = 12;
  s.yaw_deg = 30;
  const double fx = 0.5 * s.width / std::tan(32.5 * M_PI / 180);
  s.noise_sigma = 0.4 * 0.4 * 0.08 / (fx * 0.055);
  s.seed = 7;
  Cloud c = test::render_vgroove(s).cloud;
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::size_t> pick(0, c.size() - 1);
  for (std::size_t k = 0; k < c.size() / 50; ++k) {
    const std::size_t i = pick(rng);
    c.x[i] = c.y[i] = c.z[i] = NAN;
  }
  for (int v = 200; v < 230; ++v) {
    for (int u = 300; u < 340; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * c.width + u;
      c.x[i] = c.y[i] = c.z[i] = NAN;
    }
  }
  return c;
}

Cloud random_patch(int n, double half_extent, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-half_extent, half_extent);
  std::normal_distribution<double> g(0, noise);
  Cloud c;
  c.resize(n);
  for (int i = 0; i < n; ++i) {
    const double x = u(rng), y = u(rng);
    c.x[i] = static_cast<float>(x);
    c.y[i] = static_cast<float>(y);
    c.z[i] = static_cast<float>(0.45 + 0.3 * x - 0.2 * y + 20 * x * x + g(rng));
  }
  c.width = n;
  return c;
}

// Normals and descriptor of both backends on one cloud, each descriptor from the CPU normals.
void expect_feature_parity(FeatureBackend& cl, const Cloud& cloud, float radius,
                           const std::string& what) {
  auto cpu = make_cpu_backend();
  const Normals ref = cpu->normals(cloud, radius, 5);
  const Normals got = cl.normals(cloud, radius, 5);
  EXPECT_GE(normals_agree(ref, got, 0.5), kShare) << what;
  const Eigen::Vector3f ub = benchmark_normal(ref);
  if (!ub.allFinite()) return;
  const std::vector<float> d_ref = cpu->descriptor(cloud, ref, radius, ub);
  const std::vector<float> d_got = cl.descriptor(cloud, ref, radius, ub);
  EXPECT_GE(descriptors_agree(d_ref, d_got), kShare) << what;
}

// Groove labels after each backend's own pipeline: smoothing, normals, u_b, descriptor.
std::vector<std::uint8_t> labels(FeatureBackend& b, const Cloud& cloud) {
  const Cloud smoothed = b.smooth(cloud, SmoothParams{});
  const FeatureSet f = b.features(smoothed, kRadius, 5);
  std::vector<std::uint8_t> out(cloud.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = f.descriptor[i] > 4.5f ? 1 : 0;
  return out;
}

void expect_label_parity(FeatureBackend& cl, const Cloud& cloud, const std::string& what) {
  auto cpu = make_cpu_backend();
  const auto ref = labels(*cpu, cloud), got = labels(cl, cloud);
  std::size_t same = 0, groove = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    same += ref[i] == got[i] ? 1 : 0;
    groove += ref[i];
  }
  EXPECT_GT(groove, 1000u) << what;  // the scene has a groove to find
  EXPECT_GE(static_cast<double>(same) / ref.size(), kShare) << what;
}

TEST(OpenClParity, OrganizedNoisyFrame) {
  REQUIRE_OPENCL(cl);
  expect_feature_parity(*cl, noisy_frame(), kRadius, "organized noisy");
}

TEST(OpenClParity, OrganizedNoiselessFrameAtSteepTilt) {
  REQUIRE_OPENCL(cl);
  test::VGrooveScene s;
  s.tilt_deg = 25;
  s.yaw_deg = 40;
  expect_feature_parity(*cl, test::render_vgroove(s).cloud, kRadius, "organized noiseless");
}

TEST(OpenClParity, UnorganizedShuffledNoisyScan) {
  REQUIRE_OPENCL(cl);
  expect_feature_parity(*cl, test::shuffled(noisy_frame(), 11), kRadius, "unorganized noisy");
}

TEST(OpenClParity, SmoothingOrganizedAndUnorganized) {
  REQUIRE_OPENCL(cl);
  auto cpu = make_cpu_backend();
  const Cloud frame = noisy_frame();
  for (int order : {1, 2}) {
    SmoothParams sp;
    sp.order = order;
    for (const Cloud& c : {frame, test::shuffled(frame, 5)}) {
      const Cloud ref = cpu->smooth(c, sp), got = cl->smooth(c, sp);
      EXPECT_GE(clouds_agree(ref, got, 1e-6), kShare)
          << "order " << order << (c.organized() ? " organized" : " unorganized");
      // Invalid points stay exactly as they came.
      for (std::size_t i = 0; i < c.size(); ++i) {
        if (!c.valid(i)) {
          ASSERT_FALSE(got.valid(i)) << i;
        }
      }
    }
  }
}

TEST(OpenClParity, FusedFeaturesMatchSeparateCalls) {
  REQUIRE_OPENCL(cl);
  auto cpu = make_cpu_backend();
  const Cloud frame = noisy_frame();
  for (const Cloud& c : {frame, test::shuffled(frame, 9)}) {
    const FeatureSet f = cl->features(c, kRadius, 5);
    const Normals n = cl->normals(c, kRadius, 5);
    EXPECT_EQ(normals_agree(n, f.normals, 0.0), 1.0);
    const Eigen::Vector3f ub = benchmark_normal(cpu->normals(c, kRadius, 5));
    EXPECT_LT(test::angle_deg(ub, f.benchmark_normal), 1e-4);
    EXPECT_GE(descriptors_agree(cl->descriptor(c, n, kRadius, f.benchmark_normal), f.descriptor),
              1.0);
  }
}

TEST(OpenClParity, GrooveLabelsOrganizedAndUnorganized) {
  REQUIRE_OPENCL(cl);
  const Cloud frame = noisy_frame();
  expect_label_parity(*cl, frame, "organized");
  expect_label_parity(*cl, test::shuffled(frame, 13), "unorganized");
}

// The paper pipeline end to end on each backend: the same waypoints within 0.1 mm.
TEST(OpenClParity, PaperTrajectoriesAgree) {
  REQUIRE_OPENCL(cl);
  auto cpu = make_cpu_backend();
  Params params;
  params.method = Method::paper;
  const Cloud frame = noisy_frame();
  const RunResult ref = run_pipeline(frame, params, *cpu);
  const RunResult got = run_pipeline(frame, params, *cl);
  ASSERT_EQ(ref.trajectories.front().waypoints.size(), got.trajectories.front().waypoints.size());
  ASSERT_GE(ref.trajectories.front().waypoints.size(), 10u);
  for (std::size_t k = 0; k < ref.trajectories.front().waypoints.size(); ++k) {
    EXPECT_LT((ref.trajectories.front().waypoints[k].position -
               got.trajectories.front().waypoints[k].position)
                  .norm(),
              1e-4)
        << "waypoint " << k;
  }
}

// Smoothing moves points off their pixel rays (by about a pixel here): the organized search
// widens its windows by that slack and stays exact.
TEST(OpenClParity, OrganizedFrameAfterSmoothing) {
  REQUIRE_OPENCL(cl);
  const Cloud smoothed = make_cpu_backend()->smooth(noisy_frame(), SmoothParams{});
  expect_feature_parity(*cl, smoothed, kRadius, "organized, smoothed");
}

// One query per work-item (VW = 1), the kernels' form for GPUs, on the same device.
TEST(OpenClParity, OneLanePerWorkItemAsOnGpus) {
  if (!test::opencl_backend()) GTEST_SKIP() << "no OpenCL device on this machine";
  auto scalar = test::one_lane_opencl_backend();
  ASSERT_TRUE(scalar);
  test::VGrooveScene s;
  s.width = 320;
  s.height = 240;
  s.tilt_deg = 15;
  s.noise_sigma = 0.0003;
  const Cloud c = test::render_vgroove(s).cloud;
  expect_feature_parity(*scalar, c, kRadius, "VW=1 organized");
  expect_feature_parity(*scalar, test::shuffled(c, 3), kRadius, "VW=1 unorganized");
  auto cpu = make_cpu_backend();
  EXPECT_GE(clouds_agree(cpu->smooth(c, SmoothParams{}), scalar->smooth(c, SmoothParams{}), 1e-6),
            kShare);
}

// An organized cloud that is no pinhole image (moved out of the camera frame) falls back to
// the grid search and still matches.
TEST(OpenClParity, OrganizedCloudOutsideItsCameraFrame) {
  REQUIRE_OPENCL(cl);
  Cloud c = noisy_frame();
  const Eigen::Matrix3f R =
      Eigen::AngleAxisf(0.7f, Eigen::Vector3f(0.3f, -1.0f, 0.2f).normalized()).toRotationMatrix();
  for (std::size_t i = 0; i < c.size(); ++i) {
    const Eigen::Vector3f p = R * c.point(i) + Eigen::Vector3f(0.5f, -0.2f, 1.0f);
    c.x[i] = p.x();
    c.y[i] = p.y();
    c.z[i] = p.z();
  }
  c.viewpoint = Eigen::Vector3f(0.5f, -0.2f, 1.0f);
  expect_feature_parity(*cl, c, kRadius, "organized, base frame");
}

// Patches far apart in all three axes: the cloud's bounding box holds far more cells than
// points, so the grid is a hash table instead of a dense box of cells.
TEST(OpenClParity, UnorganizedCloudSpreadOverAKilometre) {
  REQUIRE_OPENCL(cl);
  Cloud c;
  for (int k = 0; k < 4; ++k) {
    const Cloud patch = random_patch(2000, 0.01, 0.0002, 20 + k);
    for (std::size_t i = 0; i < patch.size(); ++i) {
      c.x.push_back(patch.x[i] + 300.0f * k);
      c.y.push_back(patch.y[i] - 250.0f * k);
      c.z.push_back(patch.z[i] + 200.0f * (k % 2));
    }
  }
  c.width = static_cast<std::uint32_t>(c.size());
  c.viewpoint = Eigen::Vector3f(0, 0, -1);
  expect_feature_parity(*cl, c, kRadius, "spread over a kilometre");
}

TEST(OpenClEdgeCases, EmptyCloud) {
  REQUIRE_OPENCL(cl);
  const Cloud empty;
  EXPECT_EQ(cl->normals(empty, kRadius, 5).size(), 0u);
  EXPECT_EQ(cl->smooth(empty, SmoothParams{}).size(), 0u);
  EXPECT_EQ(cl->descriptor(empty, Normals{}, kRadius, Eigen::Vector3f::UnitZ()).size(), 0u);
  const FeatureSet f = cl->features(empty, kRadius, 5);
  EXPECT_EQ(f.descriptor.size(), 0u);
  EXPECT_FALSE(f.benchmark_normal.allFinite());
}

TEST(OpenClEdgeCases, OnePoint) {
  REQUIRE_OPENCL(cl);
  Cloud c;
  c.x = {0.01f};
  c.y = {-0.02f};
  c.z = {0.4f};
  c.width = 1;
  const Normals n = cl->normals(c, kRadius, 1);
  ASSERT_EQ(n.size(), 1u);
  EXPECT_FALSE(n.valid(0));  // a covariance needs 3 points whatever min_neighbors says
  Normals given;
  given.resize(1);
  given.x[0] = given.y[0] = 0.0f;
  given.z[0] = -1.0f;
  const std::vector<float> d = cl->descriptor(c, given, kRadius, Eigen::Vector3f(0, 0, -1));
  EXPECT_TRUE(std::isnan(d[0]));  // no neighbour other than itself
  const Cloud s = cl->smooth(c, SmoothParams{});
  EXPECT_EQ(s.point(0), c.point(0));
}

TEST(OpenClEdgeCases, PointsWithoutNeighboursAndNaNPoints) {
  REQUIRE_OPENCL(cl);
  auto cpu = make_cpu_backend();
  Cloud c = random_patch(3000, 0.01, 0.0002, 4);
  // Isolated points, far from the patch and from each other, and NaN points.
  for (int k = 0; k < 20; ++k) {
    c.x.push_back(0.2f + 0.05f * k);
    c.y.push_back(0.1f);
    c.z.push_back(0.5f);
    c.x.push_back(NAN);
    c.y.push_back(NAN);
    c.z.push_back(NAN);
  }
  c.width = static_cast<std::uint32_t>(c.size());
  const Normals n = cl->normals(c, kRadius, 5);
  for (std::size_t i = 3000; i < c.size(); ++i) EXPECT_FALSE(n.valid(i)) << i;
  expect_feature_parity(*cl, c, kRadius, "isolated points");
  const FeatureSet f = cl->features(c, kRadius, 5);
  for (std::size_t i = 3000; i < c.size(); ++i) EXPECT_TRUE(std::isnan(f.descriptor[i])) << i;
  const Cloud s = cl->smooth(c, SmoothParams{});
  for (std::size_t i = 3000; i < c.size(); i += 2) EXPECT_EQ(s.point(i), c.point(i)) << i;
}

TEST(OpenClEdgeCases, AllPointsInvalid) {
  REQUIRE_OPENCL(cl);
  Cloud c;
  c.resize(100);
  for (std::size_t i = 0; i < c.size(); ++i) c.x[i] = c.y[i] = c.z[i] = NAN;
  c.width = 10;
  c.height = 10;
  for (bool organized : {true, false}) {
    if (!organized) {
      c.width = 100;
      c.height = 1;
    }
    const FeatureSet f = cl->features(c, kRadius, 5);
    EXPECT_FALSE(f.benchmark_normal.allFinite());
    for (std::size_t i = 0; i < c.size(); ++i) {
      EXPECT_FALSE(f.normals.valid(i));
      EXPECT_TRUE(std::isnan(f.descriptor[i]));
    }
  }
}

// More points than one work-group may hold, in a count that is no multiple of any
// work-group or vector size.
TEST(OpenClEdgeCases, CloudLargerThanOneWorkGroup) {
  REQUIRE_OPENCL(cl);
  expect_feature_parity(*cl, random_patch(3 * 4096 + 17, 0.02, 0.0001, 8), kRadius,
                        "3 work-groups + 17");
}

TEST(OpenClEdgeCases, RadiusLargerThanTheCloud) {
  REQUIRE_OPENCL(cl);
  // Unorganized: every point is every point's neighbour.
  expect_feature_parity(*cl, random_patch(400, 0.004, 0.0002, 9), 0.05f, "unorganized r=5cm");
  // Organized: the pixel window covers the whole (small) frame.
  test::VGrooveScene s;
  s.width = 24;
  s.height = 16;
  s.tilt_deg = 10;
  s.noise_sigma = 0.0002;
  const Cloud tiny = test::render_vgroove(s).cloud;
  expect_feature_parity(*cl, tiny, 0.2f, "organized r=20cm");
  auto cpu = make_cpu_backend();
  SmoothParams sp;
  sp.radius = 0.2f;
  EXPECT_GE(clouds_agree(cpu->smooth(tiny, sp), cl->smooth(tiny, sp), 1e-6), kShare);
}

// The memory bound: under 100 bytes per point beyond the input, counting the OpenCL
// buffers at their peak and the host result arrays.
TEST(OpenClMemory, UnderHundredBytesPerPointBeyondTheInput) {
  REQUIRE_OPENCL(cl);
  const Cloud c = random_patch(200000, 0.1, 0.0002, 31);
  const std::uint64_t before = opencl_memory(true).current;
  const FeatureSet f = cl->features(c, kRadius, 5);
  const double n = static_cast<double>(c.size());
  const double features = (opencl_memory().peak - before + 16 * n) / n;
  EXPECT_LT(features, 100.0);
  opencl_memory(true);
  const Cloud s = cl->smooth(c, SmoothParams{});
  const double smoothing = (opencl_memory().peak - before + 12 * n) / n;
  EXPECT_LT(smoothing, 100.0);
  // (No check that the buffers are gone afterwards: drivers may release them asynchronously.)
}

}  // namespace
}  // namespace groovetrace
