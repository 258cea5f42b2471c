// What a shop adds to a workpiece (issue 12): tack welds in the joint, clamps on the plates
// beside it, loose bars on the table. They are placed where the camera looks, so after the
// pose is known (docs/synthetic-scans.md, "Conditions").

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/stats.hpp"
#include "synth/scene_impl.hpp"

namespace groovetrace {

using namespace synth_detail;

namespace {

// Xor'ed into the seed: the extras draw from a stream of their own.
constexpr std::uint64_t kExtrasStream = 0x6578747261735f31ULL;

constexpr double kTackMinLength = 0.008, kTackMaxLength = 0.015;  // m
constexpr double kTackEndMargin = 0.010;  // no tack centre closer to the seen part's ends (m)
const Eigen::Vector3d kClampHalf(0.015, 0.010, 0.0125);  // 30 along, 20 across, 25 high (m)
const Eigen::Vector3d kBarHalf(0.075, 0.010, 0.010);     // 150 x 20 x 20 mm

// Uniform in [lo, hi) from 53 random bits (std distributions differ between libraries).
double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1.0p-53);
}

std::vector<double> arc_lengths(const Seam& seam) {
  std::vector<double> arc(seam.root.size(), 0.0);
  for (std::size_t k = 1; k < arc.size(); ++k)
    arc[k] = arc[k - 1] + (seam.root[k] - seam.root[k - 1]).norm();
  return arc;
}

// The longest run of root vertices that project inside the image (5% margin) and face the
// camera, as an arc-length interval; for a closed seam `to` may exceed the length (wraps).
struct SeenPart {
  bool any = false;
  double from = 0.0, to = 0.0;
};

SeenPart seen_part(const Seam& seam, const std::vector<double>& arc, const CameraModel& camera,
                   const Eigen::Isometry3d& T_workpiece_camera) {
  const Eigen::Isometry3d T_camera_workpiece = T_workpiece_camera.inverse();
  const Eigen::Vector3d eye = T_workpiece_camera.translation();
  const double mu = 0.05 * camera.width, mv = 0.05 * camera.height;
  const std::size_t n = seam.closed ? seam.root.size() - 1 : seam.root.size();
  std::vector<std::uint8_t> seen(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d c = T_camera_workpiece * seam.root[k];
    if (c.z() <= 0.0 || seam.normal[k].dot(eye - seam.root[k]) <= 0.0) continue;
    const double u = camera.fx * c.x() / c.z() + camera.cx;
    const double v = camera.fy * c.y() / c.z() + camera.cy;
    seen[k] = u >= mu && u <= camera.width - 1 - mu && v >= mv && v <= camera.height - 1 - mv;
  }
  // Longest run; a closed seam's may wrap past its end.
  const std::size_t span = seam.closed ? 2 * n : n;
  std::size_t best_start = 0, best_length = 0, start = 0, length = 0;
  for (std::size_t i = 0; i < span; ++i) {
    if (seen[i % n] && length < n) {
      if (length == 0) start = i;
      if (++length > best_length) {
        best_length = length;
        best_start = start;
      }
    } else {
      length = 0;
    }
  }
  SeenPart part;
  if (best_length < 2) return part;
  const double total = arc.back();
  const auto at = [&](std::size_t i) { return arc[i % n] + (i >= n ? total : 0.0); };
  part.any = true;
  part.from = at(best_start);
  part.to = at(best_start + best_length - 1);
  return part;
}

// The root point, unit tangent and unit normal at an arc length (wrapped for closed seams).
struct SeamPoint {
  Eigen::Vector3d point, tangent, normal;
};

SeamPoint seam_point(const Seam& seam, const std::vector<double>& arc, double at) {
  const double total = arc.back();
  if (seam.closed) at -= total * std::floor(at / total);
  at = std::clamp(at, 0.0, total);
  std::size_t k =
      static_cast<std::size_t>(std::upper_bound(arc.begin(), arc.end(), at) - arc.begin());
  k = std::clamp<std::size_t>(k, 1, arc.size() - 1) - 1;
  const double f = arc[k + 1] > arc[k] ? (at - arc[k]) / (arc[k + 1] - arc[k]) : 0.0;
  SeamPoint p;
  p.point = seam.root[k] + f * (seam.root[k + 1] - seam.root[k]);
  p.tangent = (seam.root[k + 1] - seam.root[k]).normalized();
  p.normal = ((1.0 - f) * seam.normal[k] + f * seam.normal[k + 1]).normalized();
  return p;
}

}  // namespace

double SynthScene::Impl::tack_sdf(const TackShape& t, const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = p - t.centre;
  // The ellipse's bound scaled by its smaller semi-axis is 1-Lipschitz.
  const double e = (std::hypot(q.dot(t.u) / t.a, q.dot(t.v) / t.b) - 1.0) * std::min(t.a, t.b);
  if (t.corner) return std::max({e, -q.dot(t.base), q.dot(t.left)});
  return std::max(e, joint_cut_sdf(p));
}

void SynthScene::place_extras(const SynthParams& params, const CameraModel& camera,
                              const Eigen::Isometry3d& T_workpiece_camera) {
  Impl& s = *impl_;
  std::mt19937_64 rng(params.seed ^ kExtrasStream);
  const std::vector<Seam> all = seams();
  const bool corner = s.joint == JointType::kFillet || s.joint == JointType::kLap;
  std::vector<SeenPart> parts;
  s.seam_tacks.assign(all.size(), {});
  for (std::size_t k = 0; k < all.size(); ++k) {
    const Seam& seam = all[k];
    const std::vector<double> arc = arc_lengths(seam);
    parts.push_back(seen_part(seam, arc, camera, T_workpiece_camera));
    const SeenPart& part = parts.back();
    if (!part.any || params.tacks <= 0) continue;
    // Equal slots along the seen part; each tack somewhere in its slot's middle.
    double lo = part.from + kTackEndMargin, hi = part.to - kTackEndMargin;
    if (hi < lo) lo = hi = 0.5 * (part.from + part.to);
    const double slot = (hi - lo) / params.tacks;
    for (int i = 0; i < params.tacks; ++i) {
      const double length = uniform(rng, kTackMinLength, kTackMaxLength);
      const double play = std::max(0.0, slot - length - 0.002);
      const double at = lo + slot * (i + 0.5) + uniform(rng, -0.5, 0.5) * play;
      const SeamPoint sp = seam_point(seam, arc, at);
      TackShape t;
      t.centre = sp.point;
      t.u = sp.tangent;
      t.v = (sp.normal - sp.normal.dot(sp.tangent) * sp.tangent).normalized();
      t.a = 0.5 * length;
      t.b = params.tack_height_fraction * s.groove.depth;
      t.corner = corner;
      t.base = Eigen::Vector3d::UnitZ();
      t.left = t.base.cross(sp.tangent).normalized();
      s.tacks.push_back(t);
      const double total = arc.back();
      s.seam_tacks[k].push_back(
          {seam.closed ? at - total * std::floor(at / total) : at, sp.point, length, t.b});
    }
  }
  if (params.clamps > 0 && !all.empty() && parts[0].any)
    s.place_clamps(params, all[0], parts[0].from, parts[0].to, rng);
  if (params.clutter > 0) s.place_clutter(params, rng);
}

// Height of the first surface straight below a point high above (m; 0 = the table).
double SynthScene::Impl::surface_height(const Eigen::Vector2d& xy) const {
  const Eigen::Vector3d origin(xy.x(), xy.y(), bounds_max.z() + 0.01), down(0.0, 0.0, -1.0);
  double t0 = 0.0, t1 = 0.0;
  if (!clip(origin, down, t0, t1)) return 0.0;
  const double t = march(origin, down, std::max(t0, 0.0), std::min(t1, origin.z()));
  return std::isfinite(t) ? std::max(0.0, origin.z() - t) : 0.0;
}

void SynthScene::Impl::add_block(const BlockShape& block) {
  const Eigen::Vector3d reach = block.R.cwiseAbs() * block.half;
  blocks.push_back(block);
  include_in_bounds(block.centre - reach, block.centre + reach);
}

// Clamps stand on the parts 5-15 mm beside the joint's edges near the ends of the seen part
// of the seam: even ones near its start, odd ones near its end; the first two on the -s side
// (the camera's side when tilted), the next two on the +s side (fillet: all on the -s side,
// the web is on the other).
void SynthScene::Impl::place_clamps(const SynthParams& params, const Seam& seam, double from,
                                    double to, std::mt19937_64& rng) {
  const std::vector<double> arc = arc_lengths(seam);
  const double inset = std::max(0.15 * (to - from), 0.02);
  const double hw = 0.5 * groove.top_width, rise_run = k * groove.misalignment;
  for (int i = 0; i < params.clamps; ++i) {
    const double gap = uniform(rng, 0.005, 0.015);
    const double side = joint == JointType::kFillet || (i / 2) % 2 == 0 ? -1.0 : 1.0;
    double edge = 0.0;  // the joint's edge on that side, from the seam's centre line (m)
    switch (joint) {
      case JointType::kV:
        edge = side < 0 ? hw : hw + rise_run;
        break;
      case JointType::kBevel:
        edge = side < 0 ? half_gap : groove.top_width - half_gap + rise_run;
        break;
      case JointType::kFillet:
      case JointType::kLap:
        edge = side < 0 ? leg : 0.0;
        break;
    }
    const SeamPoint sp = seam_point(seam, arc, i % 2 == 0 ? from + inset : to - inset);
    const Eigen::Vector3d along = Eigen::Vector3d(sp.tangent.x(), sp.tangent.y(), 0).normalized();
    const Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(along);
    BlockShape b;
    b.half = kClampHalf;
    b.R.col(0) = along;
    b.R.col(1) = left;
    b.R.col(2) = Eigen::Vector3d::UnitZ();
    b.centre = sp.point + side * (edge + gap + kClampHalf.y()) * left;
    // Resting on the highest surface under its footprint.
    double base = 0.0;
    for (int a = -1; a <= 1; ++a)
      for (int c = -1; c <= 1; ++c)
        base = std::max(
            base,
            surface_height(
                (b.centre + a * kClampHalf.x() * along + c * kClampHalf.y() * left).head<2>()));
    b.centre.z() = base + kClampHalf.z();
    add_block(b);
  }
}

// Loose bars lie on the table 12-22 mm beside the part (even ones on the -y side), along x
// within 5 deg, their centres within 40 mm of x = 0.
void SynthScene::Impl::place_clutter(const SynthParams& params, std::mt19937_64& rng) {
  for (int i = 0; i < params.clutter; ++i) {
    const double side = i % 2 == 0 ? -1.0 : 1.0;
    const double gap = uniform(rng, 0.012, 0.022);
    const double yaw = deg_to_rad(uniform(rng, -5.0, 5.0));
    const double x = uniform(rng, -0.04, 0.04);
    const double extent = side < 0 ? -box_min.y() : box_max.y();
    BlockShape b;
    b.half = kBarHalf;
    b.R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    b.centre = {x, side * (extent + gap + kBarHalf.y()), kBarHalf.z()};
    add_block(b);
  }
}

}  // namespace groovetrace
