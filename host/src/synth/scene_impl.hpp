#pragma once
// The inside of SynthScene (host/src/synth): paths, bodies, the groove's cut, the joints and
// the extra objects, shared by scene.cpp (the workpieces, ray casting, V seams), joints.cpp
// (bevel, fillet, lap, high-low) and extras.cpp (tacks, clamps, loose bars).
//
// Every workpiece is a body (a box or a pipe) minus the groove's cut. The cut is defined in a
// 2-D cross-section (d, z'): d = distance from the seam's centre plane or path (>= 0), z' =
// height relative to the top surface. Because (d, z') is a 1-Lipschitz function of the 3-D
// point, a 1-Lipschitz 2-D bound composed with it is a valid 3-D distance bound, so one cut
// function serves straight, curved, circumferential and axial seams alike. The asymmetric
// joints use the signed distance s (> 0 on the seam's left, +y for a seam along +x) of each
// path instead, which is 1-Lipschitz near the path (the paths run beyond the parts).

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "synth/internal.hpp"

namespace groovetrace {
namespace synth_detail {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Ray marching: steps never shorter than this (m), so grazing rays make progress; a sign
// change within a step is then bisected down to kBisectTolerance.
constexpr double kMinStep = 1e-5;
constexpr double kBisectTolerance = 1e-8;
constexpr int kMaxSteps = 4096;
// Seam vertices are this far apart (m).
constexpr double kSeamStep = 0.001;

// One piece of a seam's path in the table plane (workpiece x, y): a segment or an arc.
struct PathPiece {
  bool arc = false;
  Eigen::Vector2d a{0, 0}, b{0, 0};  // end points (for arcs too)
  Eigen::Vector2d centre{0, 0};      // arc only
  double radius = 0.0;
  double start = 0.0;        // angle of `a` around the centre (rad)
  double sweep = 0.0;        // signed: > 0 counter-clockwise (rad)
  double inv_length2 = 0.0;  // segment only: 1 / |b - a|^2

  static PathPiece segment(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    PathPiece p;
    p.a = from;
    p.b = to;
    p.inv_length2 = 1.0 / (to - from).squaredNorm();
    return p;
  }
  static PathPiece make_arc(const Eigen::Vector2d& centre, double radius, double start,
                            double sweep) {
    PathPiece p;
    p.arc = true;
    p.centre = centre;
    p.radius = radius;
    p.start = start;
    p.sweep = sweep;
    p.a = centre + radius * Eigen::Vector2d(std::cos(start), std::sin(start));
    p.b = centre + radius * Eigen::Vector2d(std::cos(start + sweep), std::sin(start + sweep));
    return p;
  }

  double length() const { return arc ? radius * std::abs(sweep) : (b - a).norm(); }

  Eigen::Vector2d at(double s) const {
    if (!arc) return a + (b - a) * (s / length());
    const double angle = start + std::copysign(s / radius, sweep);
    return centre + radius * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  }

  // p within the arc's angular wedge.
  bool within(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d q = p - centre;
    if (std::abs(sweep) <= kPi) {
      // Inside the arc's wedge: on the sweep side of the start ray and before the end ray
      // (cross products; cheaper than atan2, which this runs millions of times).
      const Eigen::Vector2d s = a - centre, e = b - centre;
      const double sense = sweep > 0 ? 1.0 : -1.0;
      return sense * (s.x() * q.y() - s.y() * q.x()) >= 0.0 &&
             sense * (q.x() * e.y() - q.y() * e.x()) >= 0.0;
    }
    // Angle of p from `start` in the arc's sense of rotation, in [0, 2 pi).
    double rel = std::atan2(q.y(), q.x()) - start;
    if (sweep < 0) rel = -rel;
    rel -= 2.0 * kPi * std::floor(rel / (2.0 * kPi));
    return rel <= std::abs(sweep);
  }

  double distance(const Eigen::Vector2d& p) const {
    if (!arc) {
      const Eigen::Vector2d ab = b - a;
      const double s = std::clamp((p - a).dot(ab) * inv_length2, 0.0, 1.0);
      return (p - (a + s * ab)).norm();
    }
    if (within(p)) return std::abs((p - centre).norm() - radius);
    return std::min((p - a).norm(), (p - b).norm());
  }

  // Unit tangent (direction of travel) at the point of the piece nearest to p.
  Eigen::Vector2d tangent(const Eigen::Vector2d& p) const {
    if (!arc) return (b - a).normalized();
    Eigen::Vector2d q = p - centre;
    if (!within(p)) q = ((p - a).norm() <= (p - b).norm() ? a : b) - centre;
    const Eigen::Vector2d t(-q.y(), q.x());
    return (sweep > 0 ? t : Eigen::Vector2d(-t)).normalized();
  }

  // Distance signed > 0 on the left of the direction of travel.
  double signed_distance(const Eigen::Vector2d& p) const {
    const double d = distance(p);
    Eigen::Vector2d foot = p;
    if (!arc) {
      const Eigen::Vector2d ab = b - a;
      foot = a + std::clamp((p - a).dot(ab) * inv_length2, 0.0, 1.0) * ab;
    } else if (within(p)) {
      const Eigen::Vector2d q = p - centre;
      foot = centre + radius * q.normalized();
    } else {
      foot = (p - a).norm() <= (p - b).norm() ? a : b;
    }
    const Eigen::Vector2d t = tangent(p), r = p - foot;
    return t.x() * r.y() - t.y() * r.x() >= 0.0 ? d : -d;
  }
};

using Path = std::vector<PathPiece>;

// The piece of a path nearest to p.
inline const PathPiece& nearest_path_piece(const Path& path, const Eigen::Vector2d& p) {
  const PathPiece* best = &path.front();
  double d = kInf;
  for (const PathPiece& piece : path) {
    const double di = piece.distance(p);
    if (di < d) {
      d = di;
      best = &piece;
    }
  }
  return *best;
}

// Signed distance to a whole path: that of its nearest piece.
inline double path_signed_distance(const Path& path, const Eigen::Vector2d& p) {
  return nearest_path_piece(path, p).signed_distance(p);
}

inline Eigen::Vector2d path_tangent(const Path& path, const Eigen::Vector2d& p) {
  return nearest_path_piece(path, p).tangent(p);
}

enum class Body { kBox, kPipe };
// How the cross-section coordinates (d, z') are taken from a 3-D point.
enum class Profile {
  kPath,             // d = distance to a path in the table plane, z' = z - top
  kCircumferential,  // d = |x| (groove plane x = 0), z' = radius from the pipe axis - R
  kAxial,            // d = |y| (groove plane y = 0), z' = z - top of the pipe
};

// A tack weld: an ellipse in (along the seam u, along the seam's normal v) about a root point,
// extruded across the seam and kept inside the joint (the V's cut, or a fillet's corner).
struct TackShape {
  Eigen::Vector3d centre{0, 0, 0}, u{1, 0, 0}, v{0, 0, 1};
  double a = 0.0, b = 0.0;  // half length along u, height along v (m)
  bool corner = false;      // fillet or lap: kept in the quadrant above `base` and off `left`
  Eigen::Vector3d base{0, 0, 1}, left{0, 1, 0};
};

// A box at any yaw: clamps and loose bars.
struct BlockShape {
  Eigen::Vector3d centre{0, 0, 0}, half{0, 0, 0};
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // workpiece from block axes

  double sdf(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d q = (R.transpose() * (p - centre)).cwiseAbs() - half;
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  }
};

}  // namespace synth_detail

struct SynthScene::Impl {
  using Path = synth_detail::Path;
  using Body = synth_detail::Body;
  using Profile = synth_detail::Profile;

  GrooveGeometry groove;
  double half_gap = 0.0;
  double k = 0.0;          // V: tan(included angle / 2), bevel: tan(angle): wall run per depth
  double wall_norm = 1.0;  // 1 / sqrt(1 + k^2), makes the wall's distance 1-Lipschitz

  Body body = Body::kBox;
  Eigen::Vector3d box_min{0, 0, 0}, box_max{0, 0, 0};  // also the bounding box of a pipe
  double pipe_radius = 0.0, pipe_inner = 0.0, pipe_half_length = 0.0, pipe_axis_z = 0.0;

  Profile profile = Profile::kPath;
  std::vector<Path> paths;
  double top_z = 0.0;         // height of the top surface at the seam (m)
  bool gap_to_table = false;  // the root gap runs down to the table (plates)

  Eigen::Vector3d look_at{0, 0, 0};

  // Joints and conditions (joints.cpp). `plain`: a V without high-low, the paper's scene,
  // computed exactly as before the joints existed.
  JointType joint = JointType::kV;
  bool plain = true;
  double rise = 0.0;  // the +s side's raised part above the top (m): high-low, web, lap plate
  double web = 0.0;   // fillet web thickness (m); 0: the raised part covers the whole +s side
  double leg = 0.0;   // fillet and lap: the joint region's leg along each face (m)
  double bisector_angle = 0.0;  // rad from the normal towards +s
  std::vector<synth_detail::TackShape> tacks;
  std::vector<synth_detail::BlockShape> blocks;
  std::vector<std::vector<Tack>> seam_tacks;                 // per seam of seams(), workpiece frame
  Eigen::Vector3d bounds_min{0, 0, 0}, bounds_max{0, 0, 0};  // everything: for ray clipping

  double path_distance(const Eigen::Vector2d& p) const {
    double d = synth_detail::kInf;
    for (const Path& path : paths)
      for (const synth_detail::PathPiece& piece : path) d = std::min(d, piece.distance(p));
    return d;
  }

  double pipe_rho(const Eigen::Vector3d& p) const {
    const double dz = p.z() - pipe_axis_z;
    return std::sqrt(p.y() * p.y() + dz * dz);
  }

  // Cross-section coordinates of p.
  void section(const Eigen::Vector3d& p, double& d, double& zr) const {
    switch (profile) {
      case Profile::kPath:
        d = path_distance(p.head<2>());
        zr = p.z() - top_z;
        break;
      case Profile::kCircumferential:
        d = std::abs(p.x());
        zr = pipe_rho(p) - pipe_radius;
        break;
      case Profile::kAxial:
        d = std::abs(p.y());
        zr = p.z() - (pipe_axis_z + pipe_radius);
        break;
    }
  }

  // Distance bound of the cut (< 0 inside): the slot |d| < gap/2 united with the V whose
  // walls reach the top width at z' = 0, both limited to z' > -thickness.
  double cut_sdf(const Eigen::Vector3d& p) const {
    double d = 0.0, zr = 0.0;
    section(p, d, zr);
    const double slot = d - half_gap;
    const double vee = (d - k * (zr + groove.depth) - half_gap) * wall_norm;
    return std::max(std::min(slot, vee), -groove.thickness - zr);
  }

  double body_sdf(const Eigen::Vector3d& p) const {
    if (body == Body::kBox) {
      const Eigen::Vector3d centre = 0.5 * (box_min + box_max);
      const Eigen::Vector3d half = 0.5 * (box_max - box_min);
      const Eigen::Vector3d q = (p - centre).cwiseAbs() - half;
      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    const double rho = pipe_rho(p);
    return std::max({rho - pipe_radius, pipe_inner - rho, std::abs(p.x()) - pipe_half_length});
  }

  // joints.cpp: the cross-section's signed coordinates, the joints' solid and labels.
  int path_count() const { return profile == Profile::kPath ? static_cast<int>(paths.size()) : 1; }
  double signed_across(const Eigen::Vector3d& p, int path) const;
  double section_height(const Eigen::Vector3d& p) const;
  double raised_body_sdf(const Eigen::Vector3d& p) const;
  double bevel_cut_sdf(const Eigen::Vector3d& p) const;
  double joint_cut_sdf(const Eigen::Vector3d& p) const {
    return joint == JointType::kBevel ? bevel_cut_sdf(p) : cut_sdf(p);
  }
  double joint_solid_sdf(const Eigen::Vector3d& p) const;
  std::uint8_t joint_label(const Eigen::Vector3d& p) const;
  void setup_joint(const SynthParams& params);
  void orient_seam(Seam& seam, const std::vector<Eigen::Vector3d>& left) const;

  // extras.cpp
  double tack_sdf(const synth_detail::TackShape& t, const Eigen::Vector3d& p) const;
  double surface_height(const Eigen::Vector2d& xy) const;
  void add_block(const synth_detail::BlockShape& block);
  void place_clamps(const SynthParams& params, const Seam& seam, double from, double to,
                    std::mt19937_64& rng);
  void place_clutter(const SynthParams& params, std::mt19937_64& rng);

  // The workpiece without tacks and extra objects.
  double base_sdf(const Eigen::Vector3d& p) const {
    if (plain) return std::max(body_sdf(p), -cut_sdf(p));
    return joint_solid_sdf(p);
  }

  double tacks_sdf(const Eigen::Vector3d& p) const {
    double f = synth_detail::kInf;
    for (const synth_detail::TackShape& t : tacks) f = std::min(f, tack_sdf(t, p));
    return f;
  }
  double blocks_sdf(const Eigen::Vector3d& p) const {
    double f = synth_detail::kInf;
    for (const synth_detail::BlockShape& b : blocks) f = std::min(f, b.sdf(p));
    return f;
  }

  double sdf(const Eigen::Vector3d& p) const {
    double f = base_sdf(p);
    if (!tacks.empty()) f = std::min(f, tacks_sdf(p));
    if (!blocks.empty()) f = std::min(f, blocks_sdf(p));
    return f;
  }

  // Outward normal of the body's face at p (p on the body's surface).
  Eigen::Vector3d body_normal(const Eigen::Vector3d& p) const {
    if (body == Body::kBox) {
      const Eigen::Vector3d centre = 0.5 * (box_min + box_max);
      const Eigen::Vector3d half = 0.5 * (box_max - box_min);
      const Eigen::Vector3d q = (p - centre).cwiseAbs() - half;
      int axis = 0;
      q.maxCoeff(&axis);
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = p[axis] < centre[axis] ? -1.0 : 1.0;
      return n;
    }
    const double rho = pipe_rho(p);
    const double outer = rho - pipe_radius, inner = pipe_inner - rho;
    const double end = std::abs(p.x()) - pipe_half_length;
    if (end >= outer && end >= inner) return {p.x() < 0 ? -1.0 : 1.0, 0.0, 0.0};
    const Eigen::Vector3d radial(0.0, p.y() / rho, (p.z() - pipe_axis_z) / rho);
    return outer >= inner ? radial : Eigen::Vector3d(-radial);
  }

  Eigen::Vector3d gradient(const Eigen::Vector3d& p) const {
    // Central differences: the bound is exact (a true distance) near faces, so its gradient
    // there is the face normal.
    constexpr double h = 1e-6;
    Eigen::Vector3d g;
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d e = Eigen::Vector3d::Zero();
      e[a] = h;
      g[a] = sdf(p + e) - sdf(p - e);
    }
    const double n = g.norm();
    return n > 0 ? Eigen::Vector3d(g / n) : Eigen::Vector3d::UnitZ();
  }

  bool in_footprint(const Eigen::Vector2d& p) const {
    return p.x() >= box_min.x() && p.x() <= box_max.x() && p.y() >= box_min.y() &&
           p.y() <= box_max.y();
  }

  std::uint8_t table_label(const Eigen::Vector3d& p) const {
    if (!gap_to_table || !in_footprint(p.head<2>())) return 0;
    return path_distance(p.head<2>()) < half_gap ? 1 : 0;
  }

  // Entry and exit of the ray in the bounds (slab method).
  bool clip(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, double& t0, double& t1) const {
    t0 = -synth_detail::kInf;
    t1 = synth_detail::kInf;
    for (int a = 0; a < 3; ++a) {
      if (dir[a] == 0.0) {
        if (o[a] < bounds_min[a] || o[a] > bounds_max[a]) return false;
        continue;
      }
      double ta = (bounds_min[a] - o[a]) / dir[a];
      double tb = (bounds_max[a] - o[a]) / dir[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    return t0 <= t1;
  }

  void include_in_bounds(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    bounds_min = bounds_min.cwiseMin(lo);
    bounds_max = bounds_max.cwiseMax(hi);
  }

  void build(Shape shape);
  std::vector<std::vector<Eigen::Vector2d>> sample_path(const Path& path) const;
  // The label and normal of a surface point found by march (scene.cpp).
  void classify(const Eigen::Vector3d& p, RayHit& hit) const;

  // First t in [t0, t1] where the ray is inside the solid; NaN if none.
  double march(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, double t0, double t1) const {
    double t = t0;
    double f = sdf(o + t * dir);
    if (f <= 0.0) return t;
    for (int i = 0; i < synth_detail::kMaxSteps && t < t1; ++i) {
      const double t_next = std::min(t + std::max(f, synth_detail::kMinStep), t1);
      const double f_next = sdf(o + t_next * dir);
      if (f_next <= 0.0) {
        double lo = t, hi = t_next;  // f(lo) > 0 >= f(hi)
        while (hi - lo > synth_detail::kBisectTolerance) {
          const double mid = 0.5 * (lo + hi);
          (sdf(o + mid * dir) <= 0.0 ? hi : lo) = mid;
        }
        return hi;
      }
      t = t_next;
      f = f_next;
    }
    return std::numeric_limits<double>::quiet_NaN();
  }
};

}  // namespace groovetrace
