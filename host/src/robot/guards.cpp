// The guards every robot program passes before it is written (docs/robot.md, "Guards").

#include <cmath>
#include <cstdio>
#include <groovetrace/error.hpp>
#include <groovetrace/guards.hpp>

#include "core/stats.hpp"

namespace groovetrace {
namespace {

std::string mm(double m) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f mm", 1000.0 * m);
  return buf;
}

std::string vec_mm(const Eigen::Vector3d& p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.1f, %.1f, %.1f) mm", 1000 * p.x(), 1000 * p.y(), 1000 * p.z());
  return buf;
}

[[noreturn]] void unsafe(const WeldPass& pass, std::size_t k, const std::string& what) {
  throw UnsafeProgramError("unsafe program, no program written: pass '" + pass.name +
                           "', waypoint " + std::to_string(k) + ": " + what);
}

void check_pose(const WeldPass& pass, std::size_t k, const GuardParams& g,
                const Eigen::Vector3d& viewpoint) {
  const Waypoint& w = pass.path.waypoints[k];
  if (!w.position.allFinite() || !w.orientation.coeffs().allFinite()) {
    unsafe(pass, k, "the pose is not finite");
  }
  const Eigen::Vector3d z = w.orientation.normalized() * Eigen::Vector3d::UnitZ();
  if (!(z.dot(w.position - viewpoint) > 0)) {
    unsafe(pass, k,
           "the torch points out of the part, towards the sensor (tool z against the view)");
  }
  if (k == 0) return;
  const Waypoint& before = pass.path.waypoints[k - 1];
  const double step = (w.position - before.position).norm();
  if (step > g.max_step) {
    unsafe(pass, k,
           "a step of " + mm(step) + " from the previous pose (max_step " + mm(g.max_step) + ")");
  }
  const double turn = rad_to_deg(before.orientation.angularDistance(w.orientation));
  if (turn > g.max_step_rotation) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "the torch turns by %.1f deg from the previous pose "
                  "(max_step_rotation %.1f deg)",
                  turn, g.max_step_rotation);
    unsafe(pass, k, buf);
  }
}

void check_inside(const WeldPass& pass, std::size_t k, const Eigen::AlignedBox3d& box,
                  const Eigen::Vector3d& p, const char* which) {
  if (!box.contains(p)) {
    unsafe(pass, k,
           std::string(which) + " " + vec_mm(p) + " lies outside the workspace " +
               vec_mm(box.min()) + " - " + vec_mm(box.max()));
  }
}

}  // namespace

void check_program(const std::vector<WeldPass>& passes, const GuardParams& guards,
                   const ProgramParams& program, const Eigen::Vector3d& viewpoint) {
  for (const WeldPass& pass : passes) {
    const std::vector<Waypoint>& w = pass.path.waypoints;
    for (std::size_t k = 0; k < w.size(); ++k) check_pose(pass, k, guards, viewpoint);
    if (!guards.workspace || w.empty()) continue;
    auto backed_off = [&](const Waypoint& p) -> Eigen::Vector3d {
      return p.position -
             program.approach_offset * (p.orientation.normalized() * Eigen::Vector3d::UnitZ());
    };
    check_inside(pass, 0, *guards.workspace, backed_off(w.front()), "the approach pose");
    for (std::size_t k = 0; k < w.size(); ++k)
      check_inside(pass, k, *guards.workspace, w[k].position, "the pose");
    check_inside(pass, w.size() - 1, *guards.workspace, backed_off(w.back()), "the retreat pose");
  }
}

}  // namespace groovetrace
