// Torch angles, weaving, and the passes a program welds (docs/robot.md).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <groovetrace/error.hpp>
#include <groovetrace/weld.hpp>

#include "core/stats.hpp"

namespace groovetrace {
namespace {

// A path read at any arc length: positions interpolated linearly, orientations by slerp.
class PathReader {
 public:
  explicit PathReader(const Trajectory& path) : w_(path.waypoints), s_(w_.size(), 0.0) {
    for (std::size_t k = 1; k < w_.size(); ++k) {
      s_[k] = s_[k - 1] + (w_[k].position - w_[k - 1].position).norm();
    }
  }
  double length() const { return s_.empty() ? 0.0 : s_.back(); }
  // The waypoint at or before arc length s, and the fraction to the next.
  std::pair<std::size_t, double> locate(double s) const {
    const auto it = std::upper_bound(s_.begin(), s_.end(), s);
    std::size_t k = it == s_.begin() ? 0 : static_cast<std::size_t>(it - s_.begin()) - 1;
    k = std::min(k, w_.size() - 1);
    if (k + 1 >= w_.size()) return {k, 0.0};
    const double span = s_[k + 1] - s_[k];
    return {k, span > 0 ? std::clamp((s - s_[k]) / span, 0.0, 1.0) : 0.0};
  }
  Waypoint at(double s) const {
    const auto [k, f] = locate(s);
    Waypoint p = w_[k];
    if (f > 0) {
      p.position = (1 - f) * w_[k].position + f * w_[k + 1].position;
      p.orientation = w_[k].orientation.slerp(f, w_[k + 1].orientation).normalized();
    }
    return p;
  }
  std::size_t nearest(double s) const {
    const auto [k, f] = locate(s);
    return f > 0.5 ? k + 1 : k;
  }

 private:
  const std::vector<Waypoint>& w_;
  std::vector<double> s_;
};

// The weave's offset across the path (units of the amplitude) at each of its corner or sample
// points, as (arc length, offset) over one run of `length`.
std::vector<std::pair<double, double>> weave_pattern(const std::string& pattern, double length,
                                                     double wavelength) {
  std::vector<std::pair<double, double>> out = {{0.0, 0.0}};
  if (pattern == "zigzag") {
    for (double s = 0.25 * wavelength; s < length; s += 0.5 * wavelength) {
      out.emplace_back(s, std::lround((s / wavelength - 0.25) * 2.0) % 2 == 0 ? 1.0 : -1.0);
    }
  } else if (pattern == "sine") {
    const double ds = wavelength / 16.0;
    for (double s = ds; s < length; s += ds)
      out.emplace_back(s, std::sin(2 * M_PI * s / wavelength));
  } else if (pattern == "triangle") {
    for (double s = 0.0; s < length; s += wavelength) {
      if (s > 0) out.emplace_back(s, 1.0);
      out.emplace_back(s, -1.0);
    }
  } else {
    throw UsageError("weave: expected none, zigzag, sine or triangle, got '" + pattern + "'");
  }
  out.emplace_back(length, 0.0);
  return out;
}

void set_length(Trajectory& path) {
  path.length = 0.0;
  for (std::size_t k = 1; k < path.waypoints.size(); ++k) {
    path.length += (path.waypoints[k].position - path.waypoints[k - 1].position).norm();
  }
}

}  // namespace

void apply_torch_angles(Trajectory& path, double travel_deg, double work_deg) {
  if (travel_deg == 0.0 && work_deg == 0.0) return;
  const Eigen::Quaterniond tilt(
      Eigen::AngleAxisd(deg_to_rad(travel_deg), Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(deg_to_rad(work_deg), Eigen::Vector3d::UnitX()));
  for (Waypoint& w : path.waypoints) w.orientation = (w.orientation * tilt).normalized();
  fill_rotation_representations(path);
}

Trajectory weave_path(const Trajectory& path, const std::string& pattern, double amplitude,
                      double wavelength, const std::vector<double>& max_amplitude) {
  if (pattern == "none" || path.waypoints.size() < 2) return path;
  if (!(wavelength > 0)) throw UsageError("weave_wavelength: must be positive");
  const PathReader reader(path);
  Trajectory out = path;
  out.waypoints.clear();
  for (const auto& [s, offset] : weave_pattern(pattern, reader.length(), wavelength)) {
    Waypoint w = reader.at(s);
    double a = amplitude;
    if (!max_amplitude.empty()) a = std::min(a, max_amplitude[reader.nearest(s)]);
    w.position += offset * a * (w.orientation * Eigen::Vector3d::UnitY());
    out.waypoints.push_back(w);
  }
  fill_rotation_representations(out);
  set_length(out);
  return out;
}

namespace {

SectionShape median_shape(const std::vector<SectionShape>& shapes) {
  std::vector<double> depth, pos, neg;
  for (const SectionShape& s : shapes) {
    depth.push_back(s.depth);
    pos.push_back(s.run_pos_y);
    neg.push_back(s.run_neg_y);
  }
  return {upper_median(depth), upper_median(pos), upper_median(neg)};
}

// One planned bead along the path: at each waypoint its height and lateral, scaled from the
// planned section to the waypoint's own (the same fraction of the depth, the same fraction of
// the half-width on its side).
Trajectory bead_path(const Trajectory& path, const std::vector<SectionShape>& shapes,
                     const SectionShape& planned, const Bead& bead) {
  Trajectory out = path;
  const double eta = bead.height / planned.depth, eta_mid = bead.mid_height / planned.depth;
  const double run = bead.lateral >= 0 ? planned.run_pos_y : planned.run_neg_y;
  const double xi = run > 0 ? bead.lateral / (run * bead.mid_height) : 0.0;
  for (std::size_t i = 0; i < out.waypoints.size(); ++i) {
    Waypoint& w = out.waypoints[i];
    const SectionShape& s = shapes[i];
    const double local_run = bead.lateral >= 0 ? s.run_pos_y : s.run_neg_y;
    const Eigen::Vector3d y = w.orientation * Eigen::Vector3d::UnitY();
    const Eigen::Vector3d z = w.orientation * Eigen::Vector3d::UnitZ();
    w.position += xi * local_run * eta_mid * s.depth * y - eta * s.depth * z;
  }
  set_length(out);
  return out;
}

// Half the fitted opening at each waypoint (m): how far a weave may reach either side.
std::vector<double> half_openings(const std::vector<SectionShape>& shapes) {
  std::vector<double> half;
  for (const SectionShape& s : shapes) half.push_back(0.5 * s.width_at(s.depth));
  return half;
}

// Weaves every pass, bounded by half the fitted opening at each waypoint, and says where that
// cuts the amplitude.
void weave_passes(std::vector<WeldPass>& passes, const std::vector<SectionShape>& shapes,
                  const WeldParams& weld, std::vector<std::string>& warnings) {
  const std::vector<double> bound = half_openings(shapes);
  if (bound.empty()) {
    warnings.push_back("weave: no fitted opening along this seam bounds the amplitude");
  } else if (const double narrowest = *std::min_element(bound.begin(), bound.end());
             weld.weave_amplitude > narrowest) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "weave: the amplitude is cut to half the fitted opening where that is less "
                  "(%.1f mm at the narrowest)",
                  1000 * narrowest);
    warnings.push_back(buf);
  }
  for (WeldPass& p : passes) {
    p.path = weave_path(p.path, weld.weave, weld.weave_amplitude, weld.weave_wavelength, bound);
  }
}

}  // namespace

std::vector<WeldPass> weld_passes(const Trajectory& path, const std::vector<SectionShape>& shapes,
                                  const WeldParams& weld, const ProgramParams& program,
                                  std::vector<std::string>& warnings) {
  std::vector<WeldPass> passes;
  if (weld.multi_pass && shapes.size() == path.waypoints.size() && !shapes.empty()) {
    const SectionShape planned = median_shape(shapes);
    for (const Bead& b : plan_passes(planned, bead_area(weld, program)).beads) {
      WeldPass p{b.name, bead_path(path, shapes, planned, b)};
      apply_torch_angles(p.path, 0.0, b.work_angle);
      passes.push_back(std::move(p));
    }
  } else {
    if (weld.multi_pass) {
      warnings.push_back("multi_pass: no fitted V section along this seam; one pass is written");
    }
    passes.push_back({"seam", path});
  }
  if (weld.weave != "none") weave_passes(passes, shapes, weld, warnings);
  for (WeldPass& p : passes) apply_torch_angles(p.path, weld.travel_angle, weld.work_angle);
  return passes;
}

}  // namespace groovetrace
