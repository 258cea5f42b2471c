// Stage 2 of the robust method in 3-D: the profile across a seam taken from the cloud and
// fitted with the V model (v_profile.cpp), or, where the walls are hidden, a gap of the
// groove's width in the top surface.

#include <algorithm>
#include <cmath>

#include "core/stats.hpp"
#include "robust/stages.hpp"
#include "robust/vmodel.hpp"

namespace groovetrace {
namespace {

using robust_detail::fit_poly;
using robust_detail::top_at;

// The section's frame (t along, n up, a = n x t across) and its profile points.
struct Profile {
  Eigen::Vector3d t, n, a;
  std::vector<Eigen::Vector2d> uv;
  std::vector<std::uint32_t> index;  // each uv's point in the cloud
  bool ok = false;
  Eigen::Vector3d at(const Eigen::Vector3d& origin, double u, double v) const {
    return origin + u * a + v * n;
  }
};

Profile profile_of(const Cloud& cloud, const std::vector<std::uint32_t>& candidates,
                   const Eigen::Vector3d& origin, const Eigen::Vector3d& tangent,
                   const Eigen::Vector3d& normal_hint, double slab) {
  Profile pr;
  pr.t = tangent.normalized();
  pr.n = normal_hint - normal_hint.dot(pr.t) * pr.t;
  if (!(pr.n.norm() > 1e-9) || !pr.t.allFinite()) return pr;
  pr.n.normalize();
  pr.a = pr.n.cross(pr.t);
  pr.uv.reserve(candidates.size());
  pr.index.reserve(candidates.size());
  for (std::uint32_t j : candidates) {
    const Eigen::Vector3d d = cloud.point(j).cast<double>() - origin;
    if (std::abs(d.dot(pr.t)) > slab) continue;
    pr.uv.emplace_back(d.dot(pr.a), d.dot(pr.n));
    pr.index.push_back(j);
  }
  pr.ok = true;
  return pr;
}

// About kMaxProfile points at most: a 1280x720 frame at 0.3 m puts ~1500 in a slab, far more
// than a V needs, and the fit's cost grows with them; the seam's smoothing averages the
// sections anyway. Which points stay is decided per point, by a hash of its index in the
// cloud against the share to keep. Every k-th point of the slab's list was a different subset
// whenever one point entered or left the slab (a station 50 um to the side, a micrometre of
// depth): the root moved by up to 0.5 mm and fits flipped between passing and failing.
constexpr std::size_t kMaxProfile = 500;

// A 32-bit mix of a point index (the finaliser of MurmurHash3): uniform, so any share of the
// points it keeps is spread evenly over the profile.
std::uint32_t mix(std::uint32_t h) {
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return h;
}

std::vector<Eigen::Vector2d> thinned(const Profile& pr) {
  if (pr.uv.size() <= kMaxProfile) return pr.uv;
  const double keep = static_cast<double>(kMaxProfile) / static_cast<double>(pr.uv.size());
  const auto limit = static_cast<std::uint64_t>(keep * 4294967296.0);
  std::vector<Eigen::Vector2d> out;
  out.reserve(kMaxProfile + kMaxProfile / 8);
  for (std::size_t k = 0; k < pr.uv.size(); ++k) {
    if (mix(pr.index[k]) < limit) out.push_back(pr.uv[k]);
  }
  return out;
}

// Of the gaps between neighbouring values of the sorted `u` (m) that are 0.6-1.6 times `width`
// (m) wide, the one whose centre is nearest u = 0: its ends `lo`, `hi` and its centre's |u|
// (m; infinity when there is none).
double central_gap(const std::vector<double>& u, double width, double& lo, double& hi) {
  double best_off = INFINITY;
  for (std::size_t k = 1; k < u.size(); ++k) {
    const double a = u[k - 1], b = u[k];
    if (b - a < 0.6 * width || b - a > 1.6 * width) continue;
    const double off = std::abs(0.5 * (a + b));
    if (off < best_off) {
      best_off = off;
      lo = a;
      hi = b;
    }
  }
  return best_off;
}

// A groove of `width` and `depth` (m) in the gap centred at u = c under the top line `q` of
// profile `pr` (at `origin`): root `depth` below the gap's centre along the top normal, edges
// width / 2 to either side along the top, bisector = top normal.
void place_in_gap(const Profile& pr, const Eigen::Vector3d& origin, const Eigen::Vector3d& q,
                  double c, double width, double depth, GrooveSection& sec) {
  const Eigen::Vector2d top_n = Eigen::Vector2d(-q[1], 1).normalized();
  const Eigen::Vector2d centre(c, top_at(q, c));
  const Eigen::Vector2d root = centre - depth * top_n;
  const Eigen::Vector2d along_top(top_n.y(), -top_n.x());
  sec.tangent = pr.t;
  sec.root = pr.at(origin, root.x(), root.y());
  const Eigen::Vector2d el = centre - 0.5 * width * along_top;
  const Eigen::Vector2d er = centre + 0.5 * width * along_top;
  sec.edge_left = pr.at(origin, el.x(), el.y());
  sec.edge_right = pr.at(origin, er.x(), er.y());
  sec.normal = (top_n.x() * pr.a + top_n.y() * pr.n).normalized();
  sec.bisector = sec.normal;
  sec.width = width;
  sec.depth = depth;
  sec.inferred = true;
  sec.why = "inferred from a gap in the top surface";
}

// The profile's fit; the view towards the sensor from the cloud's viewpoint.
VProfile fit_profile(const Cloud& cloud, const Profile& pr, const Eigen::Vector3d& origin,
                     double half_window, VFit mode) {
  const Eigen::Vector3d to_sensor = cloud.viewpoint.cast<double>() - origin;
  const Eigen::Vector2d view(to_sensor.dot(pr.a), to_sensor.dot(pr.n));
  return fit_v_profile(
      thinned(pr), half_window, mode,
      view.norm() > 0 ? Eigen::Vector2d(view.normalized()) : Eigen::Vector2d(0, 1));
}

// A bevel seam's profile tilted by more than kLevelDeg (and less than kMaxLevelDeg) against
// its own fitted top is fitted again level.
constexpr double kLevelDeg = 1.0;
constexpr double kMaxLevelDeg = 30.0;

// `pr` turned about its tangent so that the unit `up` (in its (u, v)) becomes its v axis.
Profile levelled(const Profile& pr, const Eigen::Vector2d& up) {
  Profile out = pr;
  const Eigen::Vector2d across(up.y(), -up.x());
  out.n = (up.x() * pr.a + up.y() * pr.n).normalized();
  out.a = out.n.cross(out.t);
  for (auto& p : out.uv) p = Eigen::Vector2d(p.dot(across), p.dot(up));
  return out;
}

}  // namespace

GrooveSection fit_section(const Cloud& cloud, const std::vector<std::uint32_t>& candidates,
                          const Eigen::Vector3d& origin, const Eigen::Vector3d& tangent,
                          const Eigen::Vector3d& normal_hint, double slab, double half_window,
                          VFit mode) {
  GrooveSection sec;
  Profile pr = profile_of(cloud, candidates, origin, tangent, normal_hint, slab);
  if (!pr.ok) {
    sec.why = "degenerate frame";
    return sec;
  }
  sec.support = static_cast<int>(pr.uv.size());
  VProfile f = fit_profile(cloud, pr, origin, half_window, mode);
  // The hint is the crease stage's plane normal, which a single bevel's inclined wall (on one
  // side of the ball) tilts by up to 20 deg; a bevel seam's sections hold their square wall
  // straight down in the profile's frame, so they are fitted again in the frame of their own
  // top - not beyond kMaxLevelDeg, where the "top" is a face standing across the window (a web
  // seen from its side at a 40 mm scale).
  const double tilt = f.top[1] + 2 * f.top[2] * f.root.x();  // the top's slope at the root
  if (mode.square != 0 && std::abs(tilt) > std::tan(deg_to_rad(kLevelDeg)) &&
      std::abs(tilt) < std::tan(deg_to_rad(kMaxLevelDeg))) {
    const Profile level = levelled(pr, Eigen::Vector2d(-tilt, 1).normalized());
    VProfile g = fit_profile(cloud, level, origin, half_window, mode);
    if (g.ok || !f.ok) {
      pr = level;
      f = g;
    }
  }
  auto to3 = [&](const Eigen::Vector2d& p) { return pr.at(origin, p.x(), p.y()); };
  sec.tangent = pr.t;
  sec.ok = f.ok;
  sec.why = f.why;
  sec.root = to3(f.root);
  sec.edge_left = to3(f.edge_left);
  sec.edge_right = to3(f.edge_right);
  // The top surface's normal above the root, from the fitted top's slope there.
  const double slope = f.top[1] + 2 * f.top[2] * f.root.x();
  const Eigen::Vector2d top_n = Eigen::Vector2d(-slope, 1).normalized();
  sec.normal = (top_n.x() * pr.a + top_n.y() * pr.n).normalized();
  sec.bisector = (f.bisector.x() * pr.a + f.bisector.y() * pr.n).normalized();
  sec.width = f.width;
  sec.depth = f.depth;
  sec.opening_deg = f.opening_deg;
  sec.rms = f.rms;
  sec.noise = f.noise;
  sec.one_wall = f.one_wall;
  sec.square_side = f.square_side;
  sec.wall_left_deg = f.wall_left_deg;
  sec.wall_right_deg = f.wall_right_deg;
  sec.misalignment = f.misalignment;
  sec.top_bend = f.top_bend;
  sec.outer_step = f.outer_step;
  sec.gap = f.gap;
  sec.inside = f.inside;
  sec.corner = f.corner;
  sec.short_face = f.short_face;
  return sec;
}

GrooveSection fit_gap_section(const Cloud& cloud, const std::vector<std::uint32_t>& candidates,
                              const Eigen::Vector3d& origin, const Eigen::Vector3d& tangent,
                              const Eigen::Vector3d& normal_hint, double slab, double half_window,
                              double width, double depth) {
  GrooveSection sec;
  sec.why = "no gap of the groove's width";
  const Profile pr = profile_of(cloud, candidates, origin, tangent, normal_hint, slab);
  if (!pr.ok || !(width > 0)) return sec;
  sec.support = static_cast<int>(pr.uv.size());
  const double W = half_window;
  std::vector<Eigen::Vector2d> outer, inside;
  for (const auto& p : pr.uv) {
    if (std::abs(p.x()) > W) continue;
    inside.push_back(p);
    if (std::abs(p.x()) >= 0.5 * W) outer.push_back(p);
  }
  int left = 0, right = 0;
  for (const auto& p : outer) (p.x() < 0 ? left : right) += 1;
  if (left < 3 || right < 3) return sec;
  const auto [q, sigma] = fit_poly(outer, 1);
  const double tau = std::max(3.0 * sigma, 0.02 * W);
  // Sorted u of the points on the top; the gaps between them.
  std::vector<double> u;
  for (const auto& p : inside) {
    if (std::abs(p.y() - top_at(q, p.x())) <= tau) u.push_back(p.x());
  }
  std::sort(u.begin(), u.end());
  double best_lo = 0, best_hi = 0;
  if (!(central_gap(u, width, best_lo, best_hi) < 0.5 * W)) return sec;
  // Nothing may stand above the top inside the gap (that would be a rib, not a groove).
  for (const auto& p : inside) {
    if (p.x() > best_lo && p.x() < best_hi && p.y() > top_at(q, p.x()) + tau) return sec;
  }
  place_in_gap(pr, origin, q, 0.5 * (best_lo + best_hi), width, depth, sec);
  sec.noise = sigma;
  return sec;
}

}  // namespace groovetrace