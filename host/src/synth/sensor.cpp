// The RealSense D415 model: what the stereo pipeline makes of an ideal depth frame.
//
// Most effects act on disparity (px), because that is what stereo matching measures: depth
// RMS = Z^2 * subpixel / (fx * baseline) is a constant disparity error seen through
// Z = fx * baseline / disparity. Randomness: one std::mt19937_64 seeded with the seed draws,
// in a fixed order, the undulation waves and one seed per row of each random stage (noise
// field, flying pixels, dropouts); each row then has its own mt19937_64 and draws a fixed
// number of variates per pixel. So the result does not depend on the thread count, and
// switching one effect off does not change the random numbers of the others.

#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/stats.hpp"
#include "synth/internal.hpp"

namespace groovetrace {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Plane waves summed into the undulation field; enough for a near-Gaussian field.
constexpr int kUndulationModes = 32;

enum Stage { kFlyingStage = 0, kDropoutStage = 1, kStages = 2 };

// Variates from mt19937_64 bits by explicit formulas: std::*_distribution differ between
// standard libraries, and the same seed must give the same bytes everywhere.
struct Variates {
  std::mt19937_64 engine;
  explicit Variates(std::uint64_t seed) : engine(seed) {}
  double uniform() { return static_cast<double>(engine() >> 11) * 0x1.0p-53; }  // [0, 1)
  double normal() {                     // Box-Muller, one value per call
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }
};

struct EffectName {
  const char* name;
  bool SensorEffects::*flag;
};
const EffectName kEffectNames[] = {
    {"depth", &SensorEffects::depth_noise},
    {"undulation", &SensorEffects::undulation},
    {"blur", &SensorEffects::blur},
    {"flying", &SensorEffects::flying_pixels},
    {"grazing", &SensorEffects::grazing_dropout},
    {"shadow", &SensorEffects::stereo_shadow},
    {"band", &SensorEffects::left_band},
    {"dropout", &SensorEffects::random_dropout},
    {"minz", &SensorEffects::min_z},
    {"quantize", &SensorEffects::quantize},
};

// Binomial weights of a window of half-width r (a smooth stand-in for the matching window).
std::vector<double> binomial(int r) {
  std::vector<double> w(2 * r + 1, 1.0);
  for (int k = 1; k <= 2 * r; ++k) w[k] = w[k - 1] * (2 * r - k + 1) / k;
  return w;
}

}  // namespace

SensorEffects SensorEffects::none() {
  SensorEffects e;
  for (const EffectName& n : kEffectNames) e.*(n.flag) = false;
  return e;
}

bool SensorEffects::any() const {
  for (const EffectName& n : kEffectNames)
    if (this->*(n.flag)) return true;
  return false;
}

SensorEffects parse_effects(const std::string& list) {
  if (list == "all") return SensorEffects::all();
  SensorEffects e = SensorEffects::none();
  if (list == "none") return e;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    bool found = false;
    for (const EffectName& n : kEffectNames) {
      if (item == n.name) {
        e.*(n.flag) = true;
        found = true;
      }
    }
    if (!found) {
      std::string known;
      for (const EffectName& n : kEffectNames)
        known += std::string(known.empty() ? "" : ",") + n.name;
      throw UsageError("unknown sensor effect '" + item + "' (expected all, none or a list of " +
                       known + ")");
    }
  }
  return e;
}

std::string effects_string(const SensorEffects& effects) {
  std::string s;
  for (const EffectName& n : kEffectNames)
    if (effects.*(n.flag)) s += std::string(s.empty() ? "" : ",") + n.name;
  return s.empty() ? "none" : s;
}

CameraModel d415_camera(int width, int height, const SensorModel& sensor) {
  CameraModel c;
  c.width = width;
  c.height = height;
  c.fx = 0.5 * width / std::tan(deg_to_rad(0.5 * sensor.hfov_deg));
  c.fy = 0.5 * (width * 9.0 / 16.0) / std::tan(deg_to_rad(0.5 * sensor.vfov_deg));
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  return c;
}

namespace {

// Every random number of a scan, drawn first and in a fixed order from the seed.
struct RandomDraws {
  struct Mode {
    double kx, ky, phase;  // wave vector (rad/m at the look-at distance), phase (rad)
  };
  std::vector<Mode> modes;                // the undulation's plane waves
  std::vector<std::uint64_t> noise_seed;  // one per row of the noise field (with margin)
  std::vector<std::uint64_t> row_seed;    // [stage * H + row]: flying pixels, dropouts
};

RandomDraws draw_random(const SensorModel& m, std::uint64_t seed, int noise_rows, int H) {
  std::mt19937_64 master(seed);
  const auto draw = [&master] { return static_cast<double>(master() >> 11) * 0x1.0p-53; };
  RandomDraws r;
  r.modes.resize(kUndulationModes);
  for (RandomDraws::Mode& mode : r.modes) {
    const double lambda = m.undulation_min_wavelength +
                          draw() * (m.undulation_max_wavelength - m.undulation_min_wavelength);
    const double heading = 2.0 * kPi * draw();
    mode.kx = 2.0 * kPi / lambda * std::cos(heading);
    mode.ky = 2.0 * kPi / lambda * std::sin(heading);
    mode.phase = 2.0 * kPi * draw();
  }
  r.noise_seed.resize(noise_rows);
  for (auto& s : r.noise_seed) s = master();
  r.row_seed.resize(static_cast<std::size_t>(kStages) * H);
  for (auto& s : r.row_seed) s = master();
  return r;
}

// Stereo matching averages disparity over its window: creases round off, but a window
// never mixes the two sides of a depth jump (those become flying pixels below).
std::vector<double> blur_disparity(const std::vector<double>& d0, int W, int H, int r,
                                   double jump_disparity) {
  std::vector<double> d1 = d0;
  const std::vector<double> w = binomial(r);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      if (!std::isfinite(d0[i])) continue;
      double sum = 0.0, weight = 0.0;
      for (int dv = -r; dv <= r; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= H) continue;
        for (int du = -r; du <= r; ++du) {
          const int uu = u + du;
          if (uu < 0 || uu >= W) continue;
          const double q = d0[static_cast<std::size_t>(vv) * W + uu];
          if (!std::isfinite(q) || std::abs(q - d0[i]) > jump_disparity) continue;
          const double wq = w[dv + r] * w[du + r];
          sum += wq * q;
          weight += wq;
        }
      }
      d1[i] = sum / weight;
    }
  }
  return d1;
}

// Correlated undulation: plane waves over the image, with wavelengths in metres on a
// fronto-parallel plane at the look-at distance, i.e. tied to the image like the projector
// pattern and matching errors that cause it. Separable: sin(A + B) = sinA cosB + cosA sinB,
// so a pixel's value is a sum over the modes of its column's and its row's terms.
struct Undulation {
  // Layout [pixel column or row][mode], so the per-pixel sum runs over contiguous memory.
  std::vector<double> col_sin, col_cos, row_sin, row_cos;
  double amplitude = 0.0;

  double at(int u, int v) const {
    const double* cs = &col_sin[static_cast<std::size_t>(u) * kUndulationModes];
    const double* cc = &col_cos[static_cast<std::size_t>(u) * kUndulationModes];
    const double* rs = &row_sin[static_cast<std::size_t>(v) * kUndulationModes];
    const double* rc = &row_cos[static_cast<std::size_t>(v) * kUndulationModes];
    double sum = 0.0;
    for (int k = 0; k < kUndulationModes; ++k) sum += cs[k] * rc[k] + cc[k] * rs[k];
    return amplitude * sum;
  }
};

Undulation undulation_table(const std::vector<RandomDraws::Mode>& modes, const CameraModel& camera,
                            double distance, double disparity_std) {
  const int W = camera.width, H = camera.height;
  Undulation t;
  t.amplitude = disparity_std * std::sqrt(2.0 / kUndulationModes);
  t.col_sin.resize(static_cast<std::size_t>(kUndulationModes) * W);
  t.col_cos.resize(t.col_sin.size());
  t.row_sin.resize(static_cast<std::size_t>(kUndulationModes) * H);
  t.row_cos.resize(t.row_sin.size());
  for (int k = 0; k < kUndulationModes; ++k) {
    for (int u = 0; u < W; ++u) {
      const double a = modes[k].kx * (u - camera.cx) / camera.fx * distance + modes[k].phase;
      t.col_sin[static_cast<std::size_t>(u) * kUndulationModes + k] = std::sin(a);
      t.col_cos[static_cast<std::size_t>(u) * kUndulationModes + k] = std::cos(a);
    }
    for (int v = 0; v < H; ++v) {
      const double b = modes[k].ky * (v - camera.cy) / camera.fy * distance;
      t.row_sin[static_cast<std::size_t>(v) * kUndulationModes + k] = std::sin(b);
      t.row_cos[static_cast<std::size_t>(v) * kUndulationModes + k] = std::cos(b);
    }
  }
  return t;
}

// Per-pixel disparity noise of unit variance, W x H. Neighbouring pixels share most of their
// matching window, so their errors are alike: white noise (drawn with a margin of r on every
// side, so that every pixel's window is full) is smoothed with the window and scaled back to
// unit variance, which keeps the per-pixel RMS of the D415 formula. r = 0: white noise.
std::vector<double> noise_field(const std::vector<std::uint64_t>& row_seeds, int W, int H, int r) {
  const int NW = W + 2 * r, NH = H + 2 * r;
  std::vector<double> white(static_cast<std::size_t>(NW) * NH);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < NH; ++v) {
    Variates rng(row_seeds[v]);
    for (int u = 0; u < NW; ++u) white[static_cast<std::size_t>(v) * NW + u] = rng.normal();
  }
  if (r == 0) return white;
  // Separable: rows, then columns; unit-sum weights a give variance (sum a^2)^2.
  std::vector<double> a = binomial(r);
  double sum = 0.0, sum2 = 0.0;
  for (double x : a) sum += x;
  for (double& x : a) x /= sum;
  for (double x : a) sum2 += x * x;
  std::vector<double> rows(static_cast<std::size_t>(W) * NH);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < NH; ++v)
    for (int u = 0; u < W; ++u) {
      double acc = 0.0;
      for (int k = 0; k <= 2 * r; ++k)
        acc += a[k] * white[static_cast<std::size_t>(v) * NW + u + k];
      rows[static_cast<std::size_t>(v) * W + u] = acc;
    }
  std::vector<double> noise(static_cast<std::size_t>(W) * H, 0.0);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      double acc = 0.0;
      for (int k = 0; k <= 2 * r; ++k) acc += a[k] * rows[static_cast<std::size_t>(v + k) * W + u];
      noise[static_cast<std::size_t>(v) * W + u] = acc / sum2;
    }
  return noise;
}

// Flying pixels: at a depth jump, matching may lock onto a mix of both sides.
std::vector<double> fly_pixels(const std::vector<double>& d0, const std::vector<double>& d2,
                               const std::uint64_t* row_seeds, int W, int H, const SensorModel& m) {
  std::vector<double> d3 = d2;
#pragma omp parallel for schedule(static)
  for (int v = 0; v < H; ++v) {
    Variates rng(row_seeds[v]);
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      const double chance = rng.uniform(), mix = rng.uniform();
      if (!std::isfinite(d0[i])) continue;
      double other = kNaN, jump = m.jump_disparity;
      const int du[] = {-1, 1, 0, 0}, dv[] = {0, 0, -1, 1};
      for (int k = 0; k < 4; ++k) {
        const int uu = u + du[k], vv = v + dv[k];
        if (uu < 0 || uu >= W || vv < 0 || vv >= H) continue;
        const double q = d0[static_cast<std::size_t>(vv) * W + uu];
        if (std::isfinite(q) && std::abs(q - d0[i]) > jump) {
          jump = std::abs(q - d0[i]);
          other = q;
        }
      }
      if (std::isfinite(other) && chance < m.flying_probability)
        d3[i] = d2[i] + mix * (other - d0[i]);
    }
  }
  return d3;
}

// Dropouts, then back to depth and points: the organized cloud (NaN = no return).
Cloud to_points(const IdealFrame& ideal, const std::vector<double>& d3, const CameraModel& camera,
                const SynthParams& params, const SensorEffects& eff,
                const std::uint64_t* row_seeds) {
  const int W = camera.width, H = camera.height;
  const SensorModel& m = params.sensor;
  const double fb = camera.fx * m.baseline;
  Cloud cloud;
  cloud.width = static_cast<std::uint32_t>(W);
  cloud.height = static_cast<std::uint32_t>(H);
  cloud.resize(static_cast<std::size_t>(W) * H);
  cloud.viewpoint.setZero();
  const double cos_start = std::cos(deg_to_rad(m.grazing_start_deg));
#pragma omp parallel for schedule(static)
  for (int v = 0; v < H; ++v) {
    Variates rng(row_seeds[v]);
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      const double graze_draw = rng.uniform(), drop_draw = rng.uniform();
      double z = ideal.depth[i];
      bool keep = std::isfinite(z) && z > 0.0;
      if (keep && params.noise) {
        const double disparity = d3[i];
        keep = disparity > 0.0;
        if (eff.grazing_dropout && ideal.cos_incidence[i] < cos_start) {
          const double incidence = std::acos(std::clamp<double>(ideal.cos_incidence[i], 0, 1));
          const double p = (incidence * 180.0 / kPi - m.grazing_start_deg) /
                           (m.grazing_full_deg - m.grazing_start_deg);
          if (graze_draw < p) keep = false;
        }
        if (eff.stereo_shadow && ideal.shadowed[i]) keep = false;
        // The right imager sees this pixel's point at column u - disparity.
        if (eff.left_band && u - disparity < 0.0) keep = false;
        if (eff.random_dropout && drop_draw < m.dropout_probability) keep = false;
        if (keep) z = fb / disparity;
        if (eff.min_z && z < m.min_z) keep = false;
        if (eff.quantize) z = params.depth_unit * std::round(z / params.depth_unit);
      }
      if (!keep) {
        cloud.x[i] = cloud.y[i] = cloud.z[i] = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const Eigen::Vector3d p = camera.ray(u, v) * z;
      cloud.x[i] = static_cast<float>(p.x());
      cloud.y[i] = static_cast<float>(p.y());
      cloud.z[i] = static_cast<float>(p.z());
    }
  }
  return cloud;
}

}  // namespace

Cloud simulate_sensor(const IdealFrame& ideal, const CameraModel& camera,
                      const SynthParams& params) {
  const int W = camera.width, H = camera.height;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  if (ideal.depth.size() != N) throw InternalError("simulate_sensor: frame size mismatch");
  const SensorModel& m = params.sensor;
  const SensorEffects eff = params.noise ? params.effects : SensorEffects::none();

  // The matching window's half-width at this resolution; the noise field shares it.
  const int r_window = std::max(1, static_cast<int>(std::lround(m.blur_radius_1280 * W / 1280.0)));
  const int r_noise = m.correlate_noise ? r_window : 0;
  // Random numbers first, all of them, in a fixed order.
  const RandomDraws random = draw_random(m, params.seed, H + 2 * r_noise, H);

  // Ideal disparity (px): disparity times depth is fx * baseline.
  const double fb = camera.fx * m.baseline;
  std::vector<double> d0(N, kNaN);
  for (std::size_t i = 0; i < N; ++i)
    if (std::isfinite(ideal.depth[i]) && ideal.depth[i] > 0.0) d0[i] = fb / ideal.depth[i];
  const std::vector<double> d1 =
      eff.blur ? blur_disparity(d0, W, H, r_window, m.jump_disparity) : d0;

  // Noise and undulation on the disparity.
  std::vector<double> noise;
  if (eff.depth_noise) noise = noise_field(random.noise_seed, W, H, r_noise);
  Undulation undulation;
  if (eff.undulation) {
    undulation = undulation_table(random.modes, camera, params.distance, m.undulation_disparity);
  }
  std::vector<double> d2 = d1;
#pragma omp parallel for schedule(static)
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      if (!std::isfinite(d1[i])) continue;
      if (eff.depth_noise) d2[i] += m.subpixel * noise[i];
      if (eff.undulation) d2[i] += undulation.at(u, v);
    }
  }
  const std::uint64_t* flying_seeds = &random.row_seed[static_cast<std::size_t>(kFlyingStage) * H];
  const std::vector<double> d3 = eff.flying_pixels ? fly_pixels(d0, d2, flying_seeds, W, H, m) : d2;
  return to_points(ideal, d3, camera, params, eff,
                   &random.row_seed[static_cast<std::size_t>(kDropoutStage) * H]);
}

}  // namespace groovetrace
