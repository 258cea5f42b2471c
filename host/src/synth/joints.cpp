// The joints beyond the symmetric V (issue 12) and the high-low between the parts: the solid,
// the labels and the root frames (docs/synthetic-scans.md, "Joints").
//
// In the cross-section of each path, s is the signed distance (> 0 on the seam's left, +y
// for a seam along +x) and z' the height above the top surface:
// - bevel: the cut is the wedge between the vertical wall s = -gap/2 and the inclined wall
//   s = gap/2 + tan(angle) (z' + D), united with the root gap as for the V;
// - high-low: the part on the +s side is raised: the body united with (the body grown up by
//   the misalignment) on s >= 0; the V's or bevel's cut then extends that side's wall up;
// - fillet: a web s in [0, 10 mm], 50 mm high, stands on the top surface; no cut;
// - lap: a second plate of the same thickness lies on the top surface over s >= 0; no cut.

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/stats.hpp"
#include "synth/scene_impl.hpp"

namespace groovetrace {

using namespace synth_detail;

namespace {

constexpr double kWebThickness = 0.010;  // fillet: the web plate (m)
constexpr double kWebHeight = 0.050;     // fillet: its height above the base plate (m)
// A surface point belongs to a fillet's or lap's joint region within this of its border (m):
// hits are bisected to 1e-8 m.
constexpr double kRegionTolerance = 1e-6;

}  // namespace

double SynthScene::Impl::signed_across(const Eigen::Vector3d& p, int path) const {
  switch (profile) {
    case Profile::kPath:
      return path_signed_distance(paths[static_cast<std::size_t>(path)], p.head<2>());
    case Profile::kCircumferential:
      return p.x();
    case Profile::kAxial:
      return p.y();
  }
  return 0.0;
}

double SynthScene::Impl::section_height(const Eigen::Vector3d& p) const {
  switch (profile) {
    case Profile::kPath:
      return p.z() - top_z;
    case Profile::kCircumferential:
      return pipe_rho(p) - pipe_radius;
    case Profile::kAxial:
      return p.z() - (pipe_axis_z + pipe_radius);
  }
  return 0.0;
}

// The body united with its raised part on the +s side (high-low, web, lap plate).
double SynthScene::Impl::raised_body_sdf(const Eigen::Vector3d& p) const {
  const double base = body_sdf(p);
  if (rise <= 0.0) return base;
  double grown = 0.0;
  if (body == Body::kBox) {
    const Eigen::Vector3d lo = box_min, hi = box_max + Eigen::Vector3d(0.0, 0.0, rise);
    const Eigen::Vector3d q = (p - 0.5 * (lo + hi)).cwiseAbs() - 0.5 * (hi - lo);
    grown = q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  } else {
    const double rho = pipe_rho(p);
    grown = std::max(
        {rho - (pipe_radius + rise), pipe_inner - rho, std::abs(p.x()) - pipe_half_length});
  }
  double side = kInf;
  for (int i = 0; i < path_count(); ++i) {
    const double s = signed_across(p, i);
    side = std::min(side, web > 0.0 ? std::abs(s - 0.5 * web) - 0.5 * web : -s);
  }
  return std::min(base, std::max(grown, side));
}

double SynthScene::Impl::bevel_cut_sdf(const Eigen::Vector3d& p) const {
  const double zr = section_height(p);
  double cut = kInf;
  for (int i = 0; i < path_count(); ++i) {
    const double s = signed_across(p, i);
    const double slot = std::abs(s) - half_gap;
    const double wedge =
        std::max(-(s + half_gap), (s - half_gap - k * (zr + groove.depth)) * wall_norm);
    cut = std::min(cut, std::max(std::min(slot, wedge), -groove.thickness - zr));
  }
  return cut;
}

double SynthScene::Impl::joint_solid_sdf(const Eigen::Vector3d& p) const {
  const double solid = raised_body_sdf(p);
  if (joint == JointType::kFillet || joint == JointType::kLap) return solid;
  return std::max(solid, -joint_cut_sdf(p));
}

std::uint8_t SynthScene::Impl::joint_label(const Eigen::Vector3d& p) const {
  if (joint == JointType::kV || joint == JointType::kBevel)
    return -joint_cut_sdf(p) >= raised_body_sdf(p) ? 1 : 0;
  // Fillet and lap: the two faces within a leg of the corner (s in [-leg, 0] on the top
  // surface, z' in [0, leg] on the web's or upper plate's face).
  const double zr = section_height(p);
  if (zr < -kRegionTolerance || zr > leg + kRegionTolerance) return 0;
  for (int i = 0; i < path_count(); ++i) {
    const double s = signed_across(p, i);
    if (s >= -leg - kRegionTolerance && s <= kRegionTolerance) return 1;
  }
  return 0;
}

void SynthScene::Impl::setup_joint(const SynthParams& params) {
  joint = params.joint;
  plain = params.joint == JointType::kV && params.misalignment == 0.0;
  rise = params.misalignment;
  switch (params.joint) {
    case JointType::kV:
      break;
    case JointType::kBevel:
      k = (groove.top_width - groove.root_gap) / groove.depth;
      wall_norm = 1.0 / std::sqrt(1.0 + k * k);
      bisector_angle = 0.5 * deg_to_rad(groove.included_angle_deg);
      break;
    case JointType::kFillet:
      rise = kWebHeight;
      web = kWebThickness;
      leg = groove.top_width / std::sqrt(2.0);
      bisector_angle = -0.25 * kPi;
      gap_to_table = false;
      break;
    case JointType::kLap:
      rise = groove.thickness;
      leg = groove.top_width / std::sqrt(2.0);
      bisector_angle = -0.25 * kPi;
      gap_to_table = false;
      break;
  }
  if (rise > 0.0) {
    // A box grows up; a pipe's radius grows, in y and z.
    const Eigen::Vector3d grow(0.0, body == Body::kBox ? 0.0 : rise, rise);
    include_in_bounds(box_min - (body == Body::kBox ? Eigen::Vector3d::Zero() : grow),
                      box_max + grow);
  }
}

// Root frame of a joint: the bisector turned from the normal towards the seam's left (bevel,
// towards the inclined wall) or right (fillet and lap, away from the web or upper plate).
// Fillet and lap roots are corners: their normal is the bisector.
void SynthScene::Impl::orient_seam(Seam& seam, const std::vector<Eigen::Vector3d>& left) const {
  const double c = std::cos(bisector_angle), s = std::sin(bisector_angle);
  const bool corner = joint == JointType::kFillet || joint == JointType::kLap;
  for (std::size_t k = 0; k < seam.root.size(); ++k) {
    seam.bisector[k] = (c * seam.normal[k] + s * left[k]).normalized();
    if (corner) seam.normal[k] = seam.bisector[k];
  }
}

}  // namespace groovetrace
