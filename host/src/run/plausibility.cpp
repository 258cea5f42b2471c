#include "run/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/stats.hpp"

namespace groovetrace {
namespace {

double distance_to_path(const std::vector<Waypoint>& w, const Eigen::Vector3d& q) {
  double best = w.empty() ? INFINITY : (q - w.front().position).norm();
  for (std::size_t k = 0; k + 1 < w.size(); ++k) {
    const Eigen::Vector3d a = w[k].position, ab = w[k + 1].position - a;
    const double l2 = ab.squaredNorm();
    const double t = l2 > 0 ? std::clamp((q - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
    best = std::min(best, (q - (a + t * ab)).norm());
  }
  return best;
}

std::string format(const char* fmt, double a, double b) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

// The widest fitted opening among the exported seams (m); 0 for the paper method.
double widest_opening(const RunResult& r) {
  double widest = 0.0;
  for (const SeamCandidate& s : r.robust.seams) {
    if (s.accepted && std::isfinite(s.width)) widest = std::max(widest, s.width);
  }
  return widest;
}

}  // namespace

std::vector<std::string> plausibility_warnings(const Cloud& cloud, const RunResult& r) {
  std::vector<std::string> out;
  std::size_t valid = 0, groove = 0;
  Eigen::AlignedBox3d extent;
  std::vector<std::size_t> groove_points;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    ++valid;
    extent.extend(Eigen::Vector3d(cloud.x[i], cloud.y[i], cloud.z[i]));
    if (r.groove[i]) groove_points.push_back(i);
  }
  groove = groove_points.size();
  if (valid == 0 || r.trajectories.empty()) return out;
  const double share = static_cast<double>(groove) / static_cast<double>(valid);
  if (share > kMaxGrooveShare) {
    out.push_back(
        format("implausible detection: %.0f%% of the valid points are marked groove "
               "(more than %.0f%%); check the scan and the method before welding",
               100 * share, 100 * kMaxGrooveShare));
  }
  // Every k-th groove point is enough for a median (at most about 4000 of them).
  const std::vector<Waypoint>& path = r.trajectories.front().waypoints;
  std::vector<double> d;
  const std::size_t stride = std::max<std::size_t>(1, groove / 4000);
  for (std::size_t j = 0; j < groove; j += stride) {
    const std::size_t i = groove_points[j];
    d.push_back(distance_to_path(path, Eigen::Vector3d(cloud.x[i], cloud.y[i], cloud.z[i])));
  }
  const double spread = upper_median(d), limit = std::max(kMaxGrooveSpread, widest_opening(r));
  if (!d.empty() && spread > limit) {
    out.push_back(
        format("implausible detection: the groove points lie %.1f mm from the path "
               "(median; more than %.1f mm); check the path before welding",
               1000 * spread, 1000 * limit));
  }
  const double diagonal = extent.diagonal().norm();
  if (r.trajectories.front().length > 2 * diagonal) {
    out.push_back(
        format("implausible detection: the path is %.0f mm long in a scan %.0f mm "
               "across; check the path before welding",
               1000 * r.trajectories.front().length, 1000 * diagonal));
  }
  return out;
}

}  // namespace groovetrace
