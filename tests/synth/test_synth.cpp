// The synthetic scan renderer against analytic geometry, the D415 noise formula, and itself
// (determinism, truth files).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>
#include <limits>
#include <string>
#include <vector>

#include "synth/internal.hpp"

namespace gt = groovetrace;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Workpiece dimensions the tests rely on (synth.hpp: the plate is 300 x 200 mm on the table,
// the seam along x through the origin).
constexpr double kPlateHalfX = 0.15, kPlateHalfY = 0.10;

gt::SynthParams quiet(gt::Shape shape, int width = 848, int height = 480) {
  gt::SynthParams p;
  p.shape = shape;
  p.width = width;
  p.height = height;
  p.noise = false;
  return p;
}

// Pixel ray in the workpiece frame: origin and the direction scaled so that the camera-frame
// depth equals the ray parameter.
struct WorkpieceRay {
  Eigen::Vector3d origin, dir;
};
WorkpieceRay workpiece_ray(const gt::SynthTruth& t, int u, int v) {
  return {t.T_workpiece_camera.translation(), t.T_workpiece_camera.linear() * t.camera.ray(u, v)};
}

// Depth (camera z) where a ray meets the plane n . p = c, or inf.
double plane_depth(const WorkpieceRay& r, const Eigen::Vector3d& n, double c) {
  const double den = n.dot(r.dir);
  if (std::abs(den) < 1e-15) return kInf;
  const double z = (c - n.dot(r.origin)) / den;
  return z > 0 ? z : kInf;
}

// The straight groove's surface (top, two walls, two gap walls, gap floor = table) seen by a
// ray that stays inside the plate's footprint: the nearest valid plane hit, analytically.
double straight_groove_depth(const gt::SynthTruth& t, const WorkpieceRay& r) {
  const gt::GrooveGeometry& g = t.groove;
  const double top = g.thickness, root = g.thickness - g.depth;
  const double hw = 0.5 * g.top_width, hg = 0.5 * g.root_gap;
  const double k = (hw - hg) / g.depth;  // wall run per unit depth
  double best = kInf;
  const auto consider = [&](double z, bool ok) {
    if (ok) best = std::min(best, z);
  };
  const auto at = [&](double z) { return Eigen::Vector3d(r.origin + z * r.dir); };
  double z = plane_depth(r, Eigen::Vector3d::UnitZ(), top);
  consider(z, std::isfinite(z) && std::abs(at(z).y()) >= hw);
  for (const double side : {1.0, -1.0}) {
    // Wall: side * y - k z = hg - k * root, for side * y in [hg, hw].
    const Eigen::Vector3d n(0, side, -k);
    z = plane_depth(r, n, hg - k * root);
    if (std::isfinite(z)) {
      const double s = side * at(z).y();
      consider(z, s >= hg && s <= hw);
    }
    z = plane_depth(r, Eigen::Vector3d(0, 1, 0), side * hg);
    if (std::isfinite(z)) consider(z, at(z).z() >= 0 && at(z).z() <= root);
  }
  z = plane_depth(r, Eigen::Vector3d::UnitZ(), 0.0);
  consider(z, std::isfinite(z) && std::abs(at(z).y()) <= hg);
  return best;
}

bool inside_footprint(const Eigen::Vector3d& p, double margin) {
  return std::abs(p.x()) < kPlateHalfX - margin && std::abs(p.y()) < kPlateHalfY - margin;
}

std::string temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("gt-synth-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

}  // namespace

TEST(SynthCamera, D415Intrinsics) {
  const gt::CameraModel c = gt::d415_camera(1280, 720);
  EXPECT_NEAR(c.fx, 640.0 / std::tan(32.5 * kPi / 180.0), 1e-9);
  EXPECT_NEAR(c.fx, 1004.6, 0.1);  // docs/design.md: about 1005 px
  EXPECT_NEAR(c.fy, 360.0 / std::tan(20.0 * kPi / 180.0), 1e-9);
  EXPECT_DOUBLE_EQ(c.cx, 639.5);
  EXPECT_DOUBLE_EQ(c.cy, 359.5);
  // 4:3 keeps the native vertical focal length of the 16:9 frame at that width.
  const gt::CameraModel v = gt::d415_camera(640, 480);
  EXPECT_NEAR(v.fy, 180.0 / std::tan(20.0 * kPi / 180.0), 1e-9);
}

TEST(SynthRender, NoiseFreeHitsAnalyticPlaneAndV) {
  gt::SynthParams p = quiet(gt::Shape::kStraight);
  p.tilt_deg = 15;
  p.roll_deg = 10;
  p.root_gap = 0.001;
  const gt::SynthScan s = gt::render(p);
  ASSERT_EQ(s.cloud.width, 848u);
  ASSERT_EQ(s.cloud.height, 480u);
  const gt::SynthTruth& t = s.truth;
  std::size_t tested = 0, walls = 0, table = 0;
  double worst = 0.0;
  const double top = t.groove.thickness;
  for (int v = 0; v < p.height; ++v) {
    for (int u = 0; u < p.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * p.width + u;
      ASSERT_TRUE(s.cloud.valid(i)) << "noise-free scans have a return everywhere";
      const WorkpieceRay r = workpiece_ray(t, u, v);
      // Where the ray crosses the top plane and the table; x, y are linear along the ray.
      const Eigen::Vector3d a = r.origin + plane_depth(r, Eigen::Vector3d::UnitZ(), top) * r.dir;
      const Eigen::Vector3d b = r.origin + plane_depth(r, Eigen::Vector3d::UnitZ(), 0.0) * r.dir;
      double expected = kInf;
      if (inside_footprint(a, 0.002) && inside_footprint(b, 0.002)) {
        expected = straight_groove_depth(t, r);
      } else {
        // Table pixels: the ray's path from above the plate down to the table never crosses
        // the (slightly enlarged) plate.
        bool clear = true;
        const Eigen::Vector3d high =
            r.origin + plane_depth(r, Eigen::Vector3d::UnitZ(), top + 0.001) * r.dir;
        for (int k = 0; k <= 200 && clear; ++k) {
          const Eigen::Vector3d q = high + (b - high) * (k / 200.0);
          clear = std::abs(q.x()) > kPlateHalfX + 0.002 || std::abs(q.y()) > kPlateHalfY + 0.002;
        }
        if (!clear) continue;
        expected = (b - r.origin).dot(r.dir) / r.dir.squaredNorm();
        ++table;
      }
      ASSERT_TRUE(std::isfinite(expected));
      const double err = std::abs(s.cloud.z[i] - expected);
      worst = std::max(worst, err);
      EXPECT_LT(err, 1e-5) << "pixel " << u << "," << v;
      // x and y lie on the pixel's ray.
      EXPECT_NEAR(s.cloud.x[i], t.camera.ray(u, v).x() * s.cloud.z[i], 1e-6);
      EXPECT_NEAR(s.cloud.y[i], t.camera.ray(u, v).y() * s.cloud.z[i], 1e-6);
      ++tested;
      walls += t.label[i];
    }
  }
  EXPECT_GT(tested, 200000u);
  EXPECT_GT(walls, 2000u) << "the V's walls were part of the check";
  EXPECT_GT(table, 20000u) << "the table was part of the check";
  std::printf("analytic check: %zu pixels (%zu groove, %zu table), worst depth error %.3g m\n",
              tested, walls, table, worst);
}

TEST(SynthRender, NoiseFreeHitsAnalyticPipe) {
  gt::SynthParams p = quiet(gt::Shape::kPipeLong);
  p.tilt_deg = -10;
  const gt::SynthScan s = gt::render(p);
  const gt::SynthTruth& t = s.truth;
  const double R = 0.05, hw = 0.5 * t.groove.top_width;
  std::size_t tested = 0;
  for (int v = 0; v < p.height; ++v) {
    for (int u = 0; u < p.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * p.width + u;
      const WorkpieceRay r = workpiece_ray(t, u, v);
      // Ray against the infinite cylinder y^2 + (z - R)^2 = R^2 (axis along x at height R).
      const Eigen::Vector3d o(0, r.origin.y(), r.origin.z() - R), d(0, r.dir.y(), r.dir.z());
      const double A = d.squaredNorm(), B = 2 * o.dot(d), C = o.squaredNorm() - R * R;
      const double disc = B * B - 4 * A * C;
      if (disc <= 0) continue;
      const double z = (-B - std::sqrt(disc)) / (2 * A);
      const Eigen::Vector3d q = r.origin + z * r.dir;
      // Only the outer surface away from the groove's opening and the pipe's ends.
      if (std::abs(q.x()) > 0.13 || std::abs(q.y()) < hw + 0.002 || q.z() < R) continue;
      EXPECT_NEAR(s.cloud.z[i], z, 1e-5) << "pixel " << u << "," << v;
      EXPECT_EQ(t.label[i], 0);
      ++tested;
    }
  }
  EXPECT_GT(tested, 20000u);
}

TEST(SynthRender, LabelsMatchAnalyticGroove) {
  for (const double tilt : {0.0, 20.0}) {
    gt::SynthParams p = quiet(gt::Shape::kStraight);
    p.tilt_deg = tilt;
    const gt::SynthScan s = gt::render(p);
    const gt::SynthTruth& t = s.truth;
    const Eigen::Isometry3d& T = t.T_workpiece_camera;
    const double hw = 0.5 * t.groove.top_width;
    std::size_t inside = 0, outside = 0;
    for (std::size_t i = 0; i < s.cloud.size(); ++i) {
      const Eigen::Vector3d q = T * s.cloud.point(i).cast<double>();
      if (!inside_footprint(q, 0.001)) continue;
      // 10 um off the edges: float coordinates are good to about 1e-7 m here.
      if (std::abs(q.y()) < hw - 1e-5) {
        EXPECT_EQ(t.label[i], 1) << "point " << i << " between the groove edges";
        ++inside;
      } else if (std::abs(q.y()) > hw + 1e-5) {
        EXPECT_EQ(t.label[i], 0) << "point " << i << " outside the groove edges";
        ++outside;
      }
    }
    EXPECT_GT(inside, 3000u);
    EXPECT_GT(outside, 100000u);
  }
}

TEST(SynthRender, CurveLabelsFollowTheSCurve) {
  const gt::SynthParams p = quiet(gt::Shape::kCurve);
  const gt::SynthScan s = gt::render(p);
  const gt::SynthTruth& t = s.truth;
  // The S built independently: lead-in at y = -rise, a 60 deg left arc of radius 60 mm to
  // the origin, its mirror image to y = +rise, lead-out; sampled every 10 um.
  const double r = 0.06, sweep = kPi / 3, run = r * std::sin(sweep),
               rise = r * (1 - std::cos(sweep));
  std::vector<Eigen::Vector2d> path;
  for (double x = -0.2; x < -run; x += 1e-5) path.emplace_back(x, -rise);
  for (double a = 0; a < sweep; a += 1e-5 / r)
    path.emplace_back(-run + r * std::sin(a), -rise + r * (1 - std::cos(a)));
  const std::size_t half = path.size();
  for (std::size_t k = 0; k < half; ++k) path.push_back(-path[half - 1 - k]);
  const auto distance = [&path](const Eigen::Vector2d& q) {
    double d = kInf;
    for (const Eigen::Vector2d& a : path) d = std::min(d, (q - a).squaredNorm());
    return std::sqrt(d);
  };
  const double hw = 0.5 * t.groove.top_width;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < s.cloud.size(); i += 7) {  // a subsample keeps this quick
    const Eigen::Vector3d q = t.T_workpiece_camera * s.cloud.point(i).cast<double>();
    if (!inside_footprint(q, 0.001) || std::abs(q.y()) > 0.05) continue;
    const double d = distance(q.head<2>());
    if (d < hw - 2e-5) {
      EXPECT_EQ(t.label[i], 1) << "point " << i << " at " << d << " m from the S";
      ++checked;
    } else if (d > hw + 2e-5) {
      EXPECT_EQ(t.label[i], 0) << "point " << i << " at " << d << " m from the S";
    }
  }
  EXPECT_GT(checked, 300u);
}

TEST(SynthRender, SeamsAreTheRootLine) {
  gt::SynthParams p = quiet(gt::Shape::kStraight);
  p.tilt_deg = 10;
  const gt::SynthScan s = gt::render(p);
  const gt::SynthTruth& t = s.truth;
  ASSERT_EQ(t.seams.size(), 1u);
  const gt::Seam& seam = t.seams[0];
  EXPECT_NEAR(seam.length(), 2 * kPlateHalfX, 1e-9);
  EXPECT_NEAR(seam.length_in_view(), seam.length(), 1e-9);
  const Eigen::Isometry3d& T = t.T_workpiece_camera;
  for (std::size_t k = 0; k < seam.root.size(); ++k) {
    const Eigen::Vector3d q = T * seam.root[k];
    EXPECT_NEAR(q.y(), 0.0, 1e-12);
    EXPECT_NEAR(q.z(), t.groove.thickness - t.groove.depth, 1e-12);
    EXPECT_NEAR((T.linear() * seam.normal[k] - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
    EXPECT_GT(seam.normal[k].dot(-seam.root[k]), 0.0) << "normals face the camera";
    if (k > 0) {
      EXPECT_LE((seam.root[k] - seam.root[k - 1]).norm(), 0.001 + 1e-9);
    }
  }
}

TEST(SynthRender, HiddenRootIsNotInView) {
  const gt::SynthScan s = gt::render(quiet(gt::Shape::kCylinder));
  ASSERT_EQ(s.truth.seams.size(), 1u);
  const gt::Seam& seam = s.truth.seams[0];
  EXPECT_TRUE(seam.closed);
  EXPECT_NEAR(seam.root.front().x(), seam.root.back().x(), 1e-12);
  // The underside of the pipe cannot be seen; the top half can.
  EXPECT_GT(seam.length_in_view(), 0.3 * seam.length());
  EXPECT_LT(seam.length_in_view(), 0.6 * seam.length());
  for (std::size_t k = 0; k < seam.root.size(); ++k) {
    if (seam.in_view[k]) {
      EXPECT_GT(seam.normal[k].dot(-seam.root[k]), 0.0);
    }
  }
}

// With the sensor model on, a root vertex whose surface the camera sees beyond the grazing
// limit (no return at all there) is not in view: a ring round a pipe runs from square-on to
// edge-on, so both kinds occur.
TEST(SynthRender, RootBeyondTheGrazingLimitIsNotInView) {
  gt::SynthParams p;
  p.shape = gt::Shape::kCylinder;
  p.width = 640;
  p.height = 480;
  const gt::SynthScan with = gt::render(p);
  p.effects.grazing_dropout = false;
  const gt::SynthScan without = gt::render(p);
  const double limit = std::cos(p.sensor.grazing_full_deg * M_PI / 180.0);
  const gt::Seam& a = with.truth.seams.at(0);
  const gt::Seam& b = without.truth.seams.at(0);
  int beyond = 0;
  for (std::size_t k = 0; k < a.root.size(); ++k) {
    const double c = a.normal[k].normalized().dot(-a.root[k].normalized());
    if (a.in_view[k]) {
      EXPECT_GE(c, limit) << "vertex " << k;
    }
    if (b.in_view[k] && c < limit) ++beyond;
    if (c >= limit) {
      EXPECT_EQ(a.in_view[k], b.in_view[k]) << "vertex " << k;
    }
  }
  EXPECT_GT(beyond, 0) << "the scene has no root beyond the limit: the test proves nothing";
}

TEST(SynthRender, EveryShapeRendersWithGroove) {
  for (const std::string& name : gt::shape_names()) {
    gt::SynthParams p;
    p.shape = gt::parse_shape(name);
    p.width = 640;
    p.height = 480;
    const gt::SynthScan s = gt::render(p);
    std::size_t groove = 0;
    for (std::size_t i = 0; i < s.cloud.size(); ++i) groove += s.truth.label[i] && s.truth.valid[i];
    EXPECT_GT(s.cloud.count_valid(), s.cloud.size() * 7 / 10) << name;
    EXPECT_GT(groove, 500u) << name;
    EXPECT_FALSE(s.truth.seams.empty()) << name;
    EXPECT_EQ(s.truth.seams.size(), name == "multi" ? 2u : 1u) << name;
  }
}

TEST(SynthSensor, DepthNoiseMatchesD415Formula) {
  for (const double distance : {0.35, 0.55}) {
    gt::SynthParams p = quiet(gt::Shape::kStraight, 1280, 720);
    p.distance = distance;
    const gt::SynthScan clean = gt::render(p);
    p.noise = true;
    p.effects = gt::parse_effects("depth");
    const gt::SynthScan noisy = gt::render(p);
    const double fx = clean.truth.camera.fx;
    double sum2 = 0, expected2 = 0, mean = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < clean.cloud.size(); ++i) {
      if (!noisy.cloud.valid(i) || clean.truth.label[i]) continue;  // the flats
      const double z = clean.cloud.z[i], r = noisy.cloud.z[i] - z;
      const double sigma = z * z * 0.08 / (fx * 0.055);  // docs/design.md
      sum2 += r * r;
      mean += r;
      expected2 += sigma * sigma;
      ++n;
    }
    ASSERT_GT(n, 500000u);
    const double rms = std::sqrt(sum2 / n), expected = std::sqrt(expected2 / n);
    std::printf("depth noise at %.2f m: RMS %.4f mm, formula %.4f mm\n", distance, rms * 1e3,
                expected * 1e3);
    EXPECT_NEAR(rms / expected, 1.0, 0.10);
    EXPECT_LT(std::abs(mean / n), 0.05 * expected) << "unbiased";
  }
}

TEST(SynthSensor, DepthNoiseIsCorrelatedOverTheMatchingWindow) {
  for (const bool correlated : {true, false}) {
    gt::SynthParams p = quiet(gt::Shape::kStraight, 1280, 720);
    const gt::SynthScan clean = gt::render(p);
    p.noise = true;
    p.effects = gt::parse_effects("depth");
    p.sensor.correlate_noise = correlated;
    const gt::SynthScan noisy = gt::render(p);
    double sum2 = 0, lag1 = 0, lag6 = 0, expected2 = 0;
    const double fx = clean.truth.camera.fx;
    for (std::size_t i = 0; i + 6 < clean.cloud.size(); ++i) {
      const auto r = [&](std::size_t k) { return noisy.cloud.z[k] - clean.cloud.z[k]; };
      const double z = clean.cloud.z[i], sigma = z * z * 0.08 / (fx * 0.055);
      sum2 += r(i) * r(i);
      lag1 += r(i) * r(i + 1);
      lag6 += r(i) * r(i + 6);
      expected2 += sigma * sigma;
    }
    EXPECT_NEAR(std::sqrt(sum2 / expected2), 1.0, 0.10) << "per-pixel RMS either way";
    // A 5x5 binomial window (radius 2 at 1280 columns): neighbours correlate by
    // sum(a_i a_i+1) / sum(a_i^2) = 0.8, pixels 6 apart (beyond the window's reach) not at all.
    if (correlated) {
      EXPECT_NEAR(lag1 / sum2, 0.80, 0.03);
    } else {
      EXPECT_NEAR(lag1 / sum2, 0.0, 0.02);
    }
    EXPECT_NEAR(lag6 / sum2, 0.0, 0.02);
  }
}

TEST(SynthSensor, UndulationIsCorrelatedAndSized) {
  gt::SynthParams p = quiet(gt::Shape::kStraight, 1280, 720);
  p.distance = 0.5;
  const gt::SynthScan clean = gt::render(p);
  p.noise = true;
  p.effects = gt::parse_effects("undulation");
  const gt::SynthScan wavy = gt::render(p);
  double sum2 = 0, lag = 0, far = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i + 200 < clean.cloud.size(); ++i) {
    if (clean.truth.label[i] || clean.truth.label[i + 1]) continue;
    const double r = wavy.cloud.z[i] - clean.cloud.z[i];
    const double r1 = wavy.cloud.z[i + 1] - clean.cloud.z[i + 1];
    const double r200 = wavy.cloud.z[i + 200] - clean.cloud.z[i + 200];  // ~100 mm away
    sum2 += r * r;
    lag += r * r1;
    far += r * r200;
    ++n;
  }
  const double std_mm = std::sqrt(sum2 / n) * 1e3;
  std::printf("undulation at 0.5 m: std %.3f mm, neighbour correlation %.3f, at 200 px %.3f\n",
              std_mm, lag / sum2, far / sum2);
  // docs/design.md: about 0.45 mm std on flats of a real D415 scan.
  EXPECT_NEAR(std_mm, 0.45, 0.07);
  EXPECT_GT(lag / sum2, 0.95);
  EXPECT_LT(std::abs(far / sum2), 0.3);
}

TEST(SynthSensor, QuantisesDepth) {
  for (const double unit : {0.001, 0.0001}) {
    gt::SynthParams p = quiet(gt::Shape::kBox, 640, 480);
    p.noise = true;
    p.effects = gt::parse_effects("depth,quantize");
    p.depth_unit = unit;
    const gt::SynthScan s = gt::render(p);
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.cloud.size(); ++i) {
      if (!s.cloud.valid(i)) continue;
      const double steps = s.cloud.z[i] / unit;
      ASSERT_NEAR(steps, std::round(steps), 1e-7 / unit) << "z " << s.cloud.z[i];
      ++n;
    }
    EXPECT_EQ(n, s.cloud.size());
  }
}

TEST(SynthSensor, LeftBandShadowAndGrazingDropouts) {
  // Left band: nothing in the columns the right imager does not see.
  {
    gt::SynthParams p = quiet(gt::Shape::kStraight, 1280, 720);
    p.noise = true;
    p.effects = gt::parse_effects("band");
    const gt::SynthScan s = gt::render(p);
    const double fx = s.truth.camera.fx;
    for (int v = 0; v < p.height; v += 10) {
      for (int u = 0; u < 200; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * p.width + u;
        if (s.cloud.valid(i)) {
          EXPECT_GE(u, fx * 0.055 / s.cloud.z[i] - 1e-9);
        }
      }
      // Beyond the widest band (the nearest depth) everything returns.
      const std::size_t i = static_cast<std::size_t>(v) * p.width + 150;
      EXPECT_TRUE(s.cloud.valid(i));
    }
    EXPECT_FALSE(s.cloud.valid(0));
  }
  // Stereo shadow: the table beside the raised block loses points, nothing else does.
  {
    gt::SynthParams p = quiet(gt::Shape::kBox, 848, 480);
    p.noise = true;
    p.effects = gt::parse_effects("shadow");
    const gt::SynthScan s = gt::render(p);
    const gt::SynthScan clean = gt::render(quiet(gt::Shape::kBox, 848, 480));
    std::size_t dropped = 0;
    for (std::size_t i = 0; i < s.cloud.size(); ++i) {
      if (s.cloud.valid(i)) continue;
      ++dropped;
      EXPECT_GT(clean.cloud.z[i], p.distance + 0.05) << "shadow at " << i;  // on the table
    }
    EXPECT_GT(dropped, 500u);
  }
  // Grazing: tilted 25 deg across a 60 deg groove, one wall is seen at ~85 deg and vanishes;
  // the other (~35 deg) and the flats (~25 deg) return.
  {
    gt::SynthParams p = quiet(gt::Shape::kStraight, 848, 480);
    p.tilt_deg = 25;
    p.noise = true;
    p.effects = gt::parse_effects("grazing");
    const gt::SynthScene scene(p);
    const gt::CameraModel camera = gt::d415_camera(p.width, p.height);
    const gt::IdealFrame ideal = gt::render_ideal(scene, camera, gt::camera_pose(p, scene), p);
    const gt::Cloud cloud = gt::simulate_sensor(ideal, camera, p);
    std::size_t steep = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const double incidence = std::acos(ideal.cos_incidence[i]) * 180.0 / kPi;
      if (incidence > 82.0) {
        EXPECT_FALSE(cloud.valid(i)) << "incidence " << incidence;
        steep += ideal.label[i];
      } else if (incidence < 75.0) {
        EXPECT_TRUE(cloud.valid(i)) << "incidence " << incidence;
      }
    }
    EXPECT_GT(steep, 300u) << "the far wall is steep";
  }
}

TEST(SynthSensor, AllEffectsLookLikeAD415) {
  gt::SynthParams p;
  p.shape = gt::Shape::kStraight;
  const gt::SynthScan s = gt::render(p);
  const double valid = static_cast<double>(s.cloud.count_valid()) / s.cloud.size();
  // The left band alone is ~11% of the columns at 0.40-0.41 m; dropouts add a little.
  EXPECT_GT(valid, 0.84);
  EXPECT_LT(valid, 0.89);
}

TEST(SynthRender, SameSeedSameBytes) {
  gt::SynthParams p;
  p.shape = gt::Shape::kCurve;
  p.width = 640;
  p.height = 480;
  p.tilt_deg = 12;
  p.seed = 7;
  const gt::SynthScan a = gt::render(p), b = gt::render(p);
  const auto same = [](const gt::Cloud& x, const gt::Cloud& y) {
    return x.size() == y.size() &&
           std::memcmp(x.x.data(), y.x.data(), x.size() * sizeof(float)) == 0 &&
           std::memcmp(x.y.data(), y.y.data(), x.size() * sizeof(float)) == 0 &&
           std::memcmp(x.z.data(), y.z.data(), x.size() * sizeof(float)) == 0;
  };
  EXPECT_TRUE(same(a.cloud, b.cloud));
  EXPECT_EQ(a.truth.label, b.truth.label);
  EXPECT_EQ(gt::labels_pcd_bytes(a.truth), gt::labels_pcd_bytes(b.truth));
  EXPECT_EQ(gt::truth_json(a.truth, "s.pcd", "s.labels.pcd"),
            gt::truth_json(b.truth, "s.pcd", "s.labels.pcd"));
  p.seed = 8;
  const gt::SynthScan c = gt::render(p);
  EXPECT_FALSE(same(a.cloud, c.cloud));
  EXPECT_EQ(a.truth.label, c.truth.label) << "the seed changes the noise, not the workpiece";
}

TEST(SynthFiles, TruthRoundTrip) {
  gt::SynthParams p;
  p.shape = gt::Shape::kLShape;
  p.width = 640;
  p.height = 480;
  p.seed = 42;
  p.tilt_deg = 8;
  p.depth_unit = 0.0001;
  p.effects = gt::parse_effects("depth,blur,band");
  const gt::SynthScan s = gt::render(p);
  const std::string dir = temp_dir("truth");
  const gt::SynthFiles f = gt::write_synth_scan(s, dir + "/scan.pcd");
  EXPECT_EQ(f.truth, dir + "/scan.truth.json");
  EXPECT_EQ(f.labels, dir + "/scan.labels.pcd");
  EXPECT_TRUE(std::filesystem::exists(f.scan));
  const gt::SynthTruth t = gt::read_synth_truth(f.scan);
  EXPECT_EQ(t.label, s.truth.label);
  EXPECT_EQ(t.valid, s.truth.valid);
  EXPECT_EQ(t.params.seed, 42u);
  EXPECT_EQ(t.params.shape, gt::Shape::kLShape);
  EXPECT_EQ(gt::effects_string(t.params.effects), "depth,blur,band");
  EXPECT_DOUBLE_EQ(t.params.depth_unit, 0.0001);
  EXPECT_DOUBLE_EQ(t.camera.fx, s.truth.camera.fx);
  EXPECT_TRUE(t.T_workpiece_camera.isApprox(s.truth.T_workpiece_camera, 1e-15));
  ASSERT_EQ(t.seams.size(), s.truth.seams.size());
  for (std::size_t k = 0; k < t.seams.size(); ++k) {
    EXPECT_EQ(t.seams[k].root, s.truth.seams[k].root);
    EXPECT_EQ(t.seams[k].normal, s.truth.seams[k].normal);
    EXPECT_EQ(t.seams[k].in_view, s.truth.seams[k].in_view);
  }
  // Re-writing the read truth gives the same JSON.
  EXPECT_EQ(gt::truth_json(t, "scan.pcd", "scan.labels.pcd"),
            gt::truth_json(s.truth, "scan.pcd", "scan.labels.pcd"));
  EXPECT_THROW(gt::read_synth_truth(dir + "/missing.pcd"), gt::InputError);
  std::filesystem::remove_all(dir);
}

TEST(SynthFiles, LabelsAreReadWithThePcdChecks) {
  // The labels file goes through the scan reader's checks: a cut file or one of another
  // size is an InputError naming it.
  gt::SynthParams p;
  p.width = 64;
  p.height = 48;
  p.noise = false;
  const std::string dir = temp_dir("labels");
  const gt::SynthScan s = gt::render(p);
  const gt::SynthFiles f = gt::write_synth_scan(s, dir + "/scan.pcd");
  const std::string labels = gt::labels_pcd_bytes(s.truth);
  const auto expect_rejected = [&](const std::string& bytes, const std::string& reason) {
    std::ofstream(f.labels, std::ios::binary) << bytes;
    try {
      gt::read_synth_truth(f.scan);
      ADD_FAILURE() << "accepted; expected '" << reason << "'";
    } catch (const gt::InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("scan.labels.pcd"), std::string::npos) << msg;
      EXPECT_NE(msg.find(reason), std::string::npos) << msg;
    }
  };
  expect_rejected(labels.substr(0, labels.size() - 1), "truncated PCD data");
  gt::SynthTruth other = s.truth;
  other.camera.height = 32;
  other.label.resize(64 * 32);
  other.valid.resize(64 * 32);
  expect_rejected(gt::labels_pcd_bytes(other), "is not a labels file for a 64x48 scan");
  std::filesystem::remove_all(dir);
}

TEST(SynthParams, RejectsBadValues) {
  const auto bad = [](auto change) {
    gt::SynthParams p;
    change(p);
    EXPECT_THROW(gt::validate(p), gt::UsageError);
  };
  bad([](gt::SynthParams& p) { p.distance = 0.1; });
  bad([](gt::SynthParams& p) { p.distance = NAN; });
  bad([](gt::SynthParams& p) { p.width = 8; });
  bad([](gt::SynthParams& p) { p.root_gap = 0.02; });
  bad([](gt::SynthParams& p) { p.groove_angle_deg = 5; });
  bad([](gt::SynthParams& p) { p.depth_unit = 0; });
  bad([](gt::SynthParams& p) { p.tilt_deg = 60; });
  EXPECT_NO_THROW(gt::validate(gt::SynthParams{}));
  EXPECT_THROW(gt::parse_shape("sphere"), gt::UsageError);
  EXPECT_THROW(gt::parse_effects("depth,sparkles"), gt::UsageError);
  EXPECT_THROW(gt::synth_files("scan.ply"), gt::UsageError);
  EXPECT_EQ(gt::effects_string(gt::parse_effects("none")), "none");
  EXPECT_TRUE(gt::parse_effects("all").any());
  EXPECT_FALSE(gt::SensorEffects::none().any());
}

TEST(SynthParams, GrooveGeometry) {
  gt::SynthParams p;
  p.groove_width = 0.010;
  p.root_gap = 0.0;
  p.groove_angle_deg = 90.0;
  gt::GrooveGeometry g = gt::groove_geometry(p);
  EXPECT_NEAR(g.depth, 0.005, 1e-12);
  EXPECT_NEAR(g.thickness, 0.010, 1e-12);
  p.groove_depth = 0.004;
  p.root_gap = 0.002;
  g = gt::groove_geometry(p);
  EXPECT_NEAR(g.depth, 0.004, 1e-12);
  EXPECT_NEAR(g.included_angle_deg, 90.0, 1e-9);  // run 4 mm over depth 4 mm
}

#ifdef GT_CLI_PATH
TEST(SynthCli, WritesScanAndTruth) {
  const std::string dir = temp_dir("cli");
  const std::string cmd = std::string(GT_CLI_PATH) +
                          " synth --shape box --seed 3 --resolution 640x480 --tilt 5 -o " + dir +
                          "/box.pcd > " + dir + "/out.txt 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(std::filesystem::exists(dir + "/box.pcd"));
  const gt::SynthTruth t = gt::read_synth_truth(dir + "/box.pcd");
  EXPECT_EQ(t.params.seed, 3u);
  EXPECT_EQ(t.camera.width, 640);
  EXPECT_EQ(t.params.shape, gt::Shape::kBox);
  std::filesystem::remove_all(dir);
}

TEST(SynthCli, BadFlagsExitTwo) {
  const std::string dir = temp_dir("clibad");
  for (const std::string& args :
       {"--shape sphere -o " + dir + "/a.pcd", "--shape box --distance far -o " + dir + "/a.pcd",
        "--shape box --resolution 640 -o " + dir + "/a.pcd", "--shape box -o " + dir + "/a.ply",
        "--shape box --noise maybe -o " + dir + "/a.pcd"}) {
    const std::string cmd = std::string(GT_CLI_PATH) + " synth " + args + " 2>/dev/null";
    const int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << args;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/a.pcd"));
  std::filesystem::remove_all(dir);
}
#endif
