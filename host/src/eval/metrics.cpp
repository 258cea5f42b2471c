// Metrics of a detection and trajectory against synthetic ground truth
// (docs/synthetic-scans.md, "`groovetrace eval`").

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <groovetrace/error.hpp>
#include <groovetrace/eval.hpp>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/stats.hpp"

namespace groovetrace {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  // atan2 of |cross| and dot stays accurate near 0 and 180 deg, where acos loses digits.
  return rad_to_deg(std::atan2(a.cross(b).norm(), a.dot(b)));
}

// The nearest point on the true root lines to a query, with the truth's frame there.
struct RootPoint {
  double distance = std::numeric_limits<double>::infinity();
  Eigen::Vector3d point, normal, bisector, tangent;
};

RootPoint nearest_root(const std::vector<Seam>& seams, const Eigen::Vector3d& q) {
  RootPoint best;
  for (const Seam& s : seams) {
    for (std::size_t k = 0; k + 1 < s.root.size(); ++k) {
      const Eigen::Vector3d a = s.root[k], ab = s.root[k + 1] - a;
      const double l2 = ab.squaredNorm();
      if (l2 <= 0.0) continue;
      const double t = std::clamp((q - a).dot(ab) / l2, 0.0, 1.0);
      const Eigen::Vector3d p = a + t * ab;
      const double d = (q - p).norm();
      if (d < best.distance) {
        best.distance = d;
        best.point = p;
        best.normal = ((1 - t) * s.normal[k] + t * s.normal[k + 1]).normalized();
        best.bisector = ((1 - t) * s.bisector[k] + t * s.bisector[k + 1]).normalized();
        best.tangent = ab / std::sqrt(l2);
      }
    }
  }
  return best;
}

double distance_to_polyline(const std::vector<ToolPose>& poses, const Eigen::Vector3d& q) {
  if (poses.size() == 1) return (q - poses[0].position).norm();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < poses.size(); ++k) {
    const Eigen::Vector3d a = poses[k].position, ab = poses[k + 1].position - a;
    const double l2 = ab.squaredNorm();
    const double t = l2 > 0.0 ? std::clamp((q - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
    best = std::min(best, (q - (a + t * ab)).norm());
  }
  return best;
}

double percent(std::size_t num, std::size_t den) {
  return den == 0 ? kNaN : 100.0 * static_cast<double>(num) / static_cast<double>(den);
}

// The detection against the labels, over the points where the scan has a return.
void score_detection(const SynthTruth& truth, const std::vector<std::uint8_t>& detected,
                     EvalMetrics& m) {
  m.points = truth.label.size();
  for (std::size_t i = 0; i < m.points; ++i) {
    if (!truth.valid[i]) continue;
    ++m.valid_points;
    const bool t = truth.label[i] != 0, d = detected[i] != 0;
    m.truth_points += t;
    m.detected_points += d;
    m.overlap_points += t && d;
  }
  m.iou_percent = percent(m.overlap_points, m.detected_points + m.truth_points - m.overlap_points);
  m.precision_percent = percent(m.overlap_points, m.detected_points);
  m.recall_percent = percent(m.overlap_points, m.truth_points);
}

// One waypoint against the nearest root point, camera frame (m, deg).
struct WaypointError {
  double distance, lateral, depth;  // depth signed, + along the surface normal
  double tool_deg, travel_deg;
};

WaypointError waypoint_error(const std::vector<Seam>& seams, const std::vector<ToolPose>& poses,
                             std::size_t k) {
  const Eigen::Vector3d& p = poses[k].position;
  const RootPoint r = nearest_root(seams, p);
  const Eigen::Vector3d e = p - r.point;
  const Eigen::Vector3d across = r.tangent.cross(r.normal).normalized();
  WaypointError w{r.distance, std::abs(e.dot(across)), e.dot(r.normal), 0, 0};
  const Eigen::Matrix3d R = poses[k].orientation.normalized().toRotationMatrix();
  w.tool_deg = angle_deg(R.col(2), -r.bisector);
  // The direction of travel here, from the neighbouring waypoints.
  const Eigen::Vector3d ahead =
      poses[std::min(k + 1, poses.size() - 1)].position - poses[k == 0 ? 0 : k - 1].position;
  Eigen::Vector3d tangent = r.tangent;
  if (ahead.norm() > 0.0) {
    if (tangent.dot(ahead) < 0) tangent = -tangent;
    w.travel_deg = angle_deg(R.col(0), tangent);
  } else {  // a single waypoint has no travel direction: either sense of the seam
    w.travel_deg = std::min(angle_deg(R.col(0), tangent), angle_deg(R.col(0), -tangent));
  }
  return w;
}

// Waypoints against the root lines: means and maxima (NaN without waypoints or root line).
void score_waypoints(const std::vector<Seam>& seams, const std::vector<ToolPose>& poses,
                     EvalMetrics& m) {
  m.waypoints = poses.size();
  m.distance_mean = m.distance_max = m.lateral_mean = m.lateral_max = kNaN;
  m.depth_mean = m.depth_max = m.depth_bias = kNaN;
  m.tool_axis_mean_deg = m.tool_axis_max_deg = kNaN;
  m.travel_axis_mean_deg = m.travel_axis_max_deg = kNaN;
  bool any_root = false;
  for (const Seam& s : seams) any_root = any_root || s.root.size() >= 2;
  if (poses.empty() || !any_root) return;
  double dist = 0, lat = 0, dep = 0, bias = 0, tool = 0, travel = 0;
  m.distance_max = m.lateral_max = m.depth_max = 0;
  m.tool_axis_max_deg = m.travel_axis_max_deg = 0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const WaypointError w = waypoint_error(seams, poses, k);
    dist += w.distance;
    lat += w.lateral;
    dep += std::abs(w.depth);
    bias += w.depth;
    m.distance_max = std::max(m.distance_max, w.distance);
    m.lateral_max = std::max(m.lateral_max, w.lateral);
    m.depth_max = std::max(m.depth_max, std::abs(w.depth));
    tool += w.tool_deg;
    travel += w.travel_deg;
    m.tool_axis_max_deg = std::max(m.tool_axis_max_deg, w.tool_deg);
    m.travel_axis_max_deg = std::max(m.travel_axis_max_deg, w.travel_deg);
  }
  const double count = static_cast<double>(poses.size());
  m.distance_mean = dist / count;
  m.lateral_mean = lat / count;
  m.depth_mean = dep / count;
  m.depth_bias = bias / count;
  m.tool_axis_mean_deg = tool / count;
  m.travel_axis_mean_deg = travel / count;
}

// Coverage: the in-view root length whose points lie within the radius of the path.
void score_coverage(const std::vector<Seam>& seams, const std::vector<ToolPose>& poses,
                    const EvalOptions& options, EvalMetrics& m) {
  m.coverage_radius = options.coverage_radius;
  double total = 0.0, covered = 0.0;
  for (const Seam& s : seams) {
    for (std::size_t k = 0; k + 1 < s.root.size(); ++k) {
      if (!s.in_view[k] || !s.in_view[k + 1]) continue;
      const Eigen::Vector3d a = s.root[k], ab = s.root[k + 1] - a;
      const double length = ab.norm();
      const int pieces = std::max(1, static_cast<int>(std::ceil(length / options.coverage_step)));
      for (int j = 0; j < pieces; ++j) {
        // Each piece is represented by its midpoint.
        const Eigen::Vector3d q = a + ab * ((j + 0.5) / pieces);
        total += length / pieces;
        if (!poses.empty() && distance_to_polyline(poses, q) <= options.coverage_radius)
          covered += length / pieces;
      }
    }
  }
  m.seam_length_in_view = total;
  m.coverage_percent = total > 0.0 ? 100.0 * covered / total : kNaN;
}

// The point at arc length `s` (m) along the poses' polyline, clamped to its ends.
Eigen::Vector3d point_at_arc(const std::vector<ToolPose>& poses, double s) {
  for (std::size_t k = 0; k + 1 < poses.size(); ++k) {
    const Eigen::Vector3d a = poses[k].position, ab = poses[k + 1].position - a;
    const double l = ab.norm();
    if (s <= l && l > 0.0) return a + std::max(s, 0.0) / l * ab;
    s -= l;
  }
  return poses.back().position;
}

// The arc length (m) along `seam`'s root of its point nearest to q, and that distance.
double arc_on_seam(const Seam& seam, const Eigen::Vector3d& q, double& distance) {
  double arc = 0.0, best_arc = 0.0;
  distance = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < seam.root.size(); ++k) {
    const Eigen::Vector3d a = seam.root[k], ab = seam.root[k + 1] - a;
    const double l2 = ab.squaredNorm();
    const double t = l2 > 0.0 ? std::clamp((q - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
    const double d = (q - (a + t * ab)).norm();
    if (d < distance) {
      distance = d;
      best_arc = arc + t * std::sqrt(l2);
    }
    arc += std::sqrt(l2);
  }
  return best_arc;
}

// A possible pairing of reported tack `r` with true tack `t` of seam `seam`, `apart` (m) along
// the root.
struct TackPair {
  double apart;
  std::size_t r, seam, t;
};

std::vector<TackPair> tack_pairs(const SynthTruth& truth, const std::vector<ToolPose>& poses,
                                 const std::vector<ReportedTack>& reported, double radius) {
  std::vector<TackPair> pairs;
  for (std::size_t r = 0; r < reported.size() && !poses.empty(); ++r) {
    const Eigen::Vector3d q = point_at_arc(poses, reported[r].position);
    for (std::size_t j = 0; j < truth.seams.size(); ++j) {
      const Seam& seam = truth.seams[j];
      double distance = 0.0;
      const double s = arc_on_seam(seam, q, distance);
      if (distance > radius) continue;
      for (std::size_t t = 0; t < seam.tacks.size(); ++t) {
        double apart = std::abs(s - seam.tacks[t].position);
        if (seam.closed) apart = std::min(apart, seam.length() - apart);
        if (apart <= 0.5 * (reported[r].length + seam.tacks[t].length))
          pairs.push_back({apart, r, j, t});
      }
    }
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const TackPair& a, const TackPair& b) { return a.apart < b.apart; });
  return pairs;
}

}  // namespace

TackScore score_tacks(const SynthTruth& truth, const std::vector<ToolPose>& poses,
                      const std::vector<ReportedTack>& reported, const EvalOptions& options) {
  TackScore score;
  std::vector<std::vector<bool>> taken;
  for (const Seam& seam : truth.seams) {
    score.expected += seam.tacks.size();
    taken.emplace_back(seam.tacks.size(), false);
  }
  std::vector<bool> used(reported.size(), false);
  double sum = 0.0, max = 0.0, bias = 0.0;
  for (const TackPair& p : tack_pairs(truth, poses, reported, options.coverage_radius)) {
    if (used[p.r] || taken[p.seam][p.t]) continue;
    used[p.r] = taken[p.seam][p.t] = true;
    ++score.found;
    sum += p.apart;
    max = std::max(max, p.apart);
    bias += reported[p.r].length - truth.seams[p.seam].tacks[p.t].length;
  }
  score.extra = reported.size() - score.found;
  const double n = static_cast<double>(score.found);
  score.position_mean = score.found > 0 ? sum / n : kNaN;
  score.position_max = score.found > 0 ? max : kNaN;
  score.length_bias = score.found > 0 ? bias / n : kNaN;
  return score;
}

EvalMetrics evaluate(const SynthTruth& truth, const std::vector<std::uint8_t>& detected,
                     const std::vector<ToolPose>& poses, const EvalOptions& options) {
  const std::size_t n = truth.label.size();
  if (detected.size() != n || truth.valid.size() != n)
    throw InputError("eval: the detection has " + std::to_string(detected.size()) +
                     " points, the truth " + std::to_string(n));
  EvalMetrics m;
  score_detection(truth, detected, m);
  score_waypoints(truth.seams, poses, m);
  score_coverage(truth.seams, poses, options, m);
  m.runtime_ms = kNaN;
  m.points_per_second = kNaN;
  m.joint_expected = joint_name(truth.seams.empty() ? truth.params.joint : truth.seams[0].joint);
  return m;
}

std::vector<EvalMetrics::SeamScore> score_seams(
    const SynthTruth& truth,
    const std::vector<std::pair<std::string, std::vector<ToolPose>>>& trajectories,
    const EvalOptions& options) {
  std::vector<EvalMetrics::SeamScore> out;
  for (const auto& [file, poses] : trajectories) {
    for (std::size_t j = 0; j < truth.seams.size(); ++j) {
      EvalMetrics one;
      score_waypoints({truth.seams[j]}, poses, one);
      score_coverage({truth.seams[j]}, poses, options, one);
      out.push_back({file, j, one.waypoints, one.distance_mean, one.lateral_mean, one.depth_mean,
                     one.tool_axis_mean_deg, one.coverage_percent});
    }
  }
  return out;
}

namespace {

nlohmann::json seam_scores_json(const std::vector<EvalMetrics::SeamScore>& scores) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& s : scores) {
    out.push_back({{"file", s.file},
                   {"truth_seam", s.truth_seam},
                   {"waypoints", s.waypoints},
                   {"distance_mean_m", s.distance_mean},
                   {"lateral_mean_m", s.lateral_mean},
                   {"depth_mean_m", s.depth_mean},
                   {"tool_axis_mean_deg", s.tool_axis_mean_deg},
                   {"coverage_percent", s.coverage_percent}});
  }
  return out;
}

// Without tacks in the run's report (a method or version without them) only the expected count.
nlohmann::json tacks_json(const TackScore& t) {
  if (!t.reported) return {{"expected", t.expected}, {"reported", false}};
  return {{"expected", t.expected},
          {"reported", true},
          {"found", t.found},
          {"extra", t.extra},
          {"position_error_mean_m", t.position_mean},
          {"position_error_max_m", t.position_max},
          {"length_bias_m", t.length_bias}};
}

}  // namespace

std::string metrics_json(const EvalMetrics& m, const std::string& truth,
                         const std::string& result) {
  using nlohmann::json;
  json stages = json::object();
  for (const auto& [name, ms] : m.stage_ms) stages[name] = ms;
  const json j = {
      {"truth", truth},
      {"result", result},
      {"units", "m, deg, percent"},
      {"frame", "camera (trajectory assumed in the scan's camera frame)"},
      {"detection",
       {{"points", m.points},
        {"valid_points", m.valid_points},
        {"truth_points", m.truth_points},
        {"detected_points", m.detected_points},
        {"overlap_points", m.overlap_points},
        {"iou_percent", m.iou_percent},
        {"precision_percent", m.precision_percent},
        {"recall_percent", m.recall_percent}}},
      {"trajectory",
       {{"waypoints", m.waypoints},
        {"distance_mean_m", m.distance_mean},
        {"distance_max_m", m.distance_max},
        {"lateral_mean_m", m.lateral_mean},
        {"lateral_max_m", m.lateral_max},
        {"depth_mean_m", m.depth_mean},
        {"depth_max_m", m.depth_max},
        {"depth_bias_m", m.depth_bias},
        {"tool_axis_mean_deg", m.tool_axis_mean_deg},
        {"tool_axis_max_deg", m.tool_axis_max_deg},
        {"travel_axis_mean_deg", m.travel_axis_mean_deg},
        {"travel_axis_max_deg", m.travel_axis_max_deg},
        {"coverage_percent", m.coverage_percent},
        {"coverage_radius_m", m.coverage_radius},
        {"seam_length_in_view_m", m.seam_length_in_view}}},
      {"runtime",
       {{"total_ms", m.runtime_ms},
        {"points_per_second", m.points_per_second},
        {"stages_ms", stages}}},
      {"joint_expected", m.joint_expected},
      {"joint_found", m.joint_found.empty() ? json(nullptr) : json(m.joint_found)},
      {"joint_match",
       m.joint_found.empty() ? json(nullptr) : json(m.joint_found == m.joint_expected)},
      {"seams", seam_scores_json(m.seam_scores)},
      {"tacks", tacks_json(m.tacks)},
      {"notes", m.notes},
  };
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

namespace {

std::string tacks_summary(const TackScore& t) {
  if (!t.reported) return "tacks: " + std::to_string(t.expected) + " expected, none reported\n";
  char buf[256];
  std::snprintf(buf, sizeof buf, "tacks: %zu of %zu found, %zu extra", t.found, t.expected,
                t.extra);
  std::string s = buf;
  if (t.found > 0) {
    std::snprintf(buf, sizeof buf,
                  "; position error mean %.1f mm, max %.1f mm; length bias %+.1f mm",
                  t.position_mean * 1e3, t.position_max * 1e3, t.length_bias * 1e3);
    s += buf;
  }
  return s + "\n";
}

}  // namespace

std::string metrics_summary(const EvalMetrics& m) {
  char buf[512];
  std::string s;
  std::snprintf(buf, sizeof buf,
                "IoU %.2f %% (overlap %zu, detected %zu, truth %zu of %zu valid points; "
                "precision %.2f %%, recall %.2f %%)\n",
                m.iou_percent, m.overlap_points, m.detected_points, m.truth_points, m.valid_points,
                m.precision_percent, m.recall_percent);
  s += buf;
  if (m.waypoints > 0 && std::isfinite(m.distance_mean)) {
    std::snprintf(buf, sizeof buf,
                  "%zu waypoints to the root: distance mean %.2f mm, max %.2f mm; lateral mean "
                  "%.2f, max %.2f mm; depth mean %.2f, max %.2f, bias %+.2f mm\n",
                  m.waypoints, m.distance_mean * 1e3, m.distance_max * 1e3, m.lateral_mean * 1e3,
                  m.lateral_max * 1e3, m.depth_mean * 1e3, m.depth_max * 1e3, m.depth_bias * 1e3);
    s += buf;
    std::snprintf(buf, sizeof buf,
                  "tool axis error mean %.2f deg, max %.2f deg; travel axis error mean %.2f "
                  "deg, max %.2f deg\n",
                  m.tool_axis_mean_deg, m.tool_axis_max_deg, m.travel_axis_mean_deg,
                  m.travel_axis_max_deg);
    s += buf;
  } else {
    s += "no waypoints\n";
  }
  std::snprintf(buf, sizeof buf, "coverage %.1f %% of %.1f mm root line in view (within %.1f mm)\n",
                m.coverage_percent, m.seam_length_in_view * 1e3, m.coverage_radius * 1e3);
  s += buf;
  if (std::isfinite(m.runtime_ms)) {
    std::snprintf(buf, sizeof buf, "runtime %.1f ms (%.0f points/s)\n", m.runtime_ms,
                  m.points_per_second);
    s += buf;
  }
  if (!m.joint_found.empty())
    s += "joint: expected " + m.joint_expected + ", found " + m.joint_found +
         (m.joint_found == m.joint_expected ? " (match)\n" : " (mismatch)\n");
  for (const auto& seam : m.seam_scores) {
    std::snprintf(buf, sizeof buf,
                  "%s against true seam %zu: lateral %.2f mm, depth %.2f mm, tool axis %.2f "
                  "deg, coverage %.1f %%\n",
                  seam.file.c_str(), seam.truth_seam, seam.lateral_mean * 1e3,
                  seam.depth_mean * 1e3, seam.tool_axis_mean_deg, seam.coverage_percent);
    s += buf;
  }
  if (m.tacks.reported || m.tacks.expected > 0) s += tacks_summary(m.tacks);
  for (const std::string& note : m.notes) s += "note: " + note + "\n";
  return s;
}

}  // namespace groovetrace
