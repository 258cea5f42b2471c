// Workpieces of the synthetic scans as signed distance bounds, and ray casting against them
// (the bound's parts: synth/scene_impl.hpp). Sphere tracing on that bound, then bisection on
// its sign, finds the exact boundary of the solid, whose faces (planes, cylinders) are
// therefore hit to far better than 1e-5 m.

#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <limits>
#include <string>
#include <vector>

#include "core/stats.hpp"
#include "synth/internal.hpp"
#include "synth/scene_impl.hpp"

namespace groovetrace {

using namespace synth_detail;

// Builds the workpiece of a shape. Dimensions are fixed per shape (metres); the groove's
// cross-section comes from the params.
void SynthScene::Impl::build(Shape shape) {
  Impl& s = *this;
  const double pipe_radius = s.pipe_radius;  // set by the constructor
  const double t = s.groove.thickness;
  const auto plate = [&](double half_x, double half_y) {
    s.body = Body::kBox;
    s.box_min = {-half_x, -half_y, 0.0};
    s.box_max = {half_x, half_y, t};
    s.profile = Profile::kPath;
    s.top_z = t;
    s.gap_to_table = true;
    s.look_at = {0.0, 0.0, t};
  };
  const auto pipe = [&](Profile profile, double half_length) {
    s.body = Body::kPipe;
    s.pipe_radius = pipe_radius;
    s.pipe_inner = s.pipe_radius - t;
    s.pipe_half_length = half_length;
    s.pipe_axis_z = s.pipe_radius;  // lying on the table
    s.box_min = {-half_length, -s.pipe_radius, 0.0};
    s.box_max = {half_length, s.pipe_radius, 2.0 * s.pipe_radius};
    s.profile = profile;
    s.top_z = 2.0 * s.pipe_radius;
    s.look_at = {0.0, 0.0, s.top_z};
  };
  // Paths run well beyond the parts so that the groove crosses them completely.
  const double far = 0.3;
  switch (shape) {
    case Shape::kStraight:
      plate(0.15, 0.10);
      s.paths = {{PathPiece::segment({-far, 0}, {far, 0})}};
      break;
    case Shape::kCurve: {
      // An S: lead-in along +x, a 60 degree left arc, a 60 degree right arc, lead-out; the
      // arcs (radius 60 mm) meet at the origin with the tangent (cos 60, sin 60).
      plate(0.15, 0.10);
      const double r = 0.06, sweep = kPi / 3.0;
      const double run = r * std::sin(sweep), rise = r * (1.0 - std::cos(sweep));
      s.paths = {{PathPiece::segment({-far, -rise}, {-run, -rise}),
                  PathPiece::make_arc({-run, r - rise}, r, -kPi / 2.0, sweep),
                  PathPiece::make_arc({run, rise - r}, r, kPi / 2.0 + sweep, -sweep),
                  PathPiece::segment({run, rise}, {far, rise})}};
      break;
    }
    case Shape::kLShape:
      plate(0.15, 0.10);
      s.paths = {{PathPiece::segment({-0.08, -far}, {-0.08, 0.04}),
                  PathPiece::segment({-0.08, 0.04}, {far, 0.04})}};
      break;
    case Shape::kMulti:
      plate(0.15, 0.10);
      s.paths = {{PathPiece::segment({-far, -0.04}, {far, -0.04})},
                 {PathPiece::segment({-far, 0.04}, {far, 0.04})}};
      break;
    case Shape::kBox:
      s.body = Body::kBox;
      s.box_min = {-0.08, -0.05, 0.0};
      s.box_max = {0.08, 0.05, 0.06};
      s.profile = Profile::kPath;
      s.top_z = 0.06;
      s.look_at = {0.0, 0.0, s.top_z};
      s.paths = {{PathPiece::segment({-far, 0}, {far, 0})}};
      break;
    case Shape::kCylinder:
      pipe(Profile::kCircumferential, 0.12);
      break;
    case Shape::kPipeLong:
      pipe(Profile::kAxial, 0.14);
      break;
  }
}

// Vertices of a path every kSeamStep inside the footprint, split into the runs that lie inside
// and cut exactly at the footprint's border.
std::vector<std::vector<Eigen::Vector2d>> SynthScene::Impl::sample_path(const Path& path) const {
  const Impl& s = *this;
  std::vector<Eigen::Vector2d> pts;
  for (const PathPiece& piece : path) {
    const int n = std::max(1, static_cast<int>(std::ceil(piece.length() / kSeamStep)));
    for (int i = pts.empty() ? 0 : 1; i <= n; ++i) pts.push_back(piece.at(piece.length() * i / n));
  }
  std::vector<std::vector<Eigen::Vector2d>> runs;
  std::vector<Eigen::Vector2d> run;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const bool inside = s.in_footprint(pts[i]);
    if (i > 0 && inside != s.in_footprint(pts[i - 1])) {
      Eigen::Vector2d in = inside ? pts[i] : pts[i - 1], out = inside ? pts[i - 1] : pts[i];
      for (int it = 0; it < 60 && (in - out).norm() > 1e-9; ++it) {
        const Eigen::Vector2d mid = 0.5 * (in + out);
        (s.in_footprint(mid) ? in : out) = mid;
      }
      run.push_back(in);
      if (!inside) {
        runs.push_back(run);
        run.clear();
      }
    }
    if (inside) run.push_back(pts[i]);
  }
  if (run.size() > 1) runs.push_back(run);
  // A crossing can coincide with a sample; drop the zero-length steps that makes.
  for (auto& r : runs)
    r.erase(std::unique(r.begin(), r.end(),
                        [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
                          return (a - b).norm() < 1e-9;
                        }),
            r.end());
  return runs;
}

GrooveGeometry groove_geometry(const SynthParams& params) {
  GrooveGeometry g;
  g.top_width = params.groove_width;
  g.root_gap = params.root_gap;
  g.misalignment = params.misalignment;
  if (params.joint == JointType::kFillet || params.joint == JointType::kLap) {
    // The weld's isosceles right triangle in the 90 deg corner: its face (hypotenuse) is the
    // top width, its throat the depth; the parts touch, there is no gap.
    g.root_gap = 0.0;
    g.depth = 0.5 * params.groove_width;
    g.included_angle_deg = 90.0;
    g.thickness = std::max(0.010, params.groove_width / std::sqrt(2.0) + 0.0015);
    return g;
  }
  if (params.joint == JointType::kBevel) {
    // One vertical wall: the inclined wall alone runs the width less the gap.
    const double run = params.groove_width - params.root_gap;
    if (params.groove_depth > 0.0) {
      g.depth = params.groove_depth;
      g.included_angle_deg = std::atan(run / g.depth) * 180.0 / kPi;
    } else {
      g.included_angle_deg = params.groove_angle_deg;
      g.depth = run / std::tan(deg_to_rad(params.groove_angle_deg));
    }
    g.thickness = std::max(0.010, g.depth + 0.0015);
    return g;
  }
  const double run = 0.5 * (params.groove_width - params.root_gap);
  if (params.groove_depth > 0.0) {
    g.depth = params.groove_depth;
    g.included_angle_deg = 2.0 * std::atan(run / g.depth) * 180.0 / kPi;
  } else {
    g.included_angle_deg = params.groove_angle_deg;
    g.depth = run / std::tan(deg_to_rad(0.5 * params.groove_angle_deg));
  }
  g.thickness = std::max(0.010, g.depth + 0.0015);
  return g;
}

SynthScene::SynthScene(const SynthParams& params) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.groove = groove_geometry(params);
  s.half_gap = 0.5 * s.groove.root_gap;
  s.k = 0.5 * (s.groove.top_width - s.groove.root_gap) / s.groove.depth;
  s.wall_norm = 1.0 / std::sqrt(1.0 + s.k * s.k);
  s.pipe_radius = 0.5 * params.pipe_diameter;
  s.build(params.shape);
  s.bounds_min = s.box_min;
  s.bounds_max = s.box_max;
  s.setup_joint(params);
}

SynthScene::~SynthScene() = default;

void SynthScene::Impl::classify(const Eigen::Vector3d& p, RayHit& hit) const {
  const Impl& s = *this;
  if (!s.tacks.empty() || !s.blocks.empty()) {
    // The surface is that of the part whose bound is lowest there: a block (label 0), a tack
    // (1, it sits in the joint) or the workpiece.
    const double base = s.base_sdf(p), tack = s.tacks_sdf(p), block = s.blocks_sdf(p);
    if (block < base && block <= tack) {
      hit.label = 0;
      hit.normal = s.gradient(p);
      return;
    }
    if (tack < base) {
      hit.label = 1;
      hit.normal = s.gradient(p);
      return;
    }
  }
  if (!s.plain) {
    hit.label = s.joint_label(p);
    hit.normal = s.gradient(p);
    return;
  }
  // The groove's faces are where the cut, not the body, bounds the solid; the body's faces
  // have analytic normals, the cut's come from the distance bound's gradient.
  hit.label = -s.cut_sdf(p) >= s.body_sdf(p) ? 1 : 0;
  hit.normal = hit.label ? s.gradient(p) : s.body_normal(p);
}

RayHit SynthScene::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             double t_max) const {
  const Impl& s = *impl_;
  RayHit hit;
  // The table is the plane z = 0, seen from above.
  const double t_table =
      (direction.z() < 0.0 && origin.z() > 0.0) ? -origin.z() / direction.z() : kInf;
  double t0 = 0.0, t1 = 0.0;
  if (s.clip(origin, direction, t0, t1)) {
    t0 = std::max(t0, 0.0);
    t1 = std::min({t1, t_max, t_table});
    if (t0 <= t1) {
      const double t = s.march(origin, direction, t0, t1);
      if (std::isfinite(t)) {
        hit.hit = true;
        hit.t = t;
        hit.point = origin + t * direction;
        s.classify(hit.point, hit);
        return hit;
      }
    }
  }
  if (t_table < t_max) {
    hit.hit = true;
    hit.table = true;
    hit.t = t_table;
    hit.point = origin + t_table * direction;
    hit.point.z() = 0.0;
    hit.normal = Eigen::Vector3d::UnitZ();
    hit.label = s.table_label(hit.point);
  }
  return hit;
}

bool SynthScene::occluded(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                          double tolerance) const {
  const Impl& s = *impl_;
  const Eigen::Vector3d delta = to - from;
  const double length = delta.norm();
  if (length <= tolerance) return false;
  const Eigen::Vector3d dir = delta / length;
  const double t_max = length - tolerance;
  if (dir.z() < 0.0 && from.z() > 0.0 && -from.z() / dir.z() < t_max) return true;  // table
  double t0 = 0.0, t1 = 0.0;
  if (!s.clip(from, dir, t0, t1)) return false;
  t0 = std::max(t0, 0.0);
  t1 = std::min(t1, t_max);
  return t0 <= t1 && std::isfinite(s.march(from, dir, t0, t1));
}

double SynthScene::signed_distance(const Eigen::Vector3d& p) const { return impl_->sdf(p); }

Eigen::Vector3d SynthScene::look_at() const { return impl_->look_at; }

const GrooveGeometry& SynthScene::groove() const { return impl_->groove; }

std::vector<Seam> SynthScene::seams() const {
  const Impl& s = *impl_;
  std::vector<Seam> seams;
  // Per seam, the direction across it towards its +s side (the seam's left), for the joints
  // whose root frame is not symmetric.
  std::vector<std::vector<Eigen::Vector3d>> lefts;
  const bool oriented = s.joint != JointType::kV;
  const auto add = [&](Seam seam, std::vector<Eigen::Vector3d> left) {
    seam.in_view.assign(seam.root.size(), 1);
    seams.push_back(std::move(seam));
    lefts.push_back(std::move(left));
  };
  // Fillet and lap roots are the corner on the top surface; V and bevel roots lie D below it.
  const bool corner = s.joint == JointType::kFillet || s.joint == JointType::kLap;
  const double depth = corner ? 0.0 : s.groove.depth;
  switch (s.profile) {
    case Profile::kPath:
      for (const Path& path : s.paths) {
        for (const auto& run : s.sample_path(path)) {
          Seam seam;
          std::vector<Eigen::Vector3d> left;
          for (const Eigen::Vector2d& p : run) {
            seam.root.emplace_back(p.x(), p.y(), s.top_z - depth);
            seam.normal.push_back(Eigen::Vector3d::UnitZ());
            seam.bisector.push_back(Eigen::Vector3d::UnitZ());
            if (oriented) {
              const Eigen::Vector2d t = path_tangent(path, p);
              left.emplace_back(-t.y(), t.x(), 0.0);
            }
          }
          add(std::move(seam), std::move(left));
        }
      }
      break;
    case Profile::kCircumferential: {
      // The root circle in the plane x = 0; phi = 0 at the top, growing towards +y.
      const double rho = s.pipe_radius - depth;
      const int n = static_cast<int>(std::ceil(2.0 * kPi * rho / kSeamStep));
      Seam seam;
      seam.closed = true;
      for (int i = 0; i <= n; ++i) {
        const double phi = 2.0 * kPi * (i % n) / n;
        const Eigen::Vector3d radial(0.0, std::sin(phi), std::cos(phi));
        seam.root.push_back(Eigen::Vector3d(0.0, 0.0, s.pipe_axis_z) + rho * radial);
        seam.normal.push_back(radial);
        seam.bisector.push_back(radial);
      }
      add(std::move(seam), std::vector<Eigen::Vector3d>(n + 1, Eigen::Vector3d::UnitX()));
      break;
    }
    case Profile::kAxial: {
      const double half = s.pipe_half_length;
      const int n = static_cast<int>(std::ceil(2.0 * half / kSeamStep));
      Seam seam;
      for (int i = 0; i <= n; ++i) {
        seam.root.emplace_back(-half + 2.0 * half * i / n, 0.0, s.top_z - depth);
        seam.normal.push_back(Eigen::Vector3d::UnitZ());
        seam.bisector.push_back(Eigen::Vector3d::UnitZ());
      }
      add(std::move(seam), std::vector<Eigen::Vector3d>(n + 1, Eigen::Vector3d::UnitY()));
      break;
    }
  }
  for (std::size_t k = 0; k < seams.size(); ++k) {
    seams[k].joint = s.joint;
    if (oriented) s.orient_seam(seams[k], lefts[k]);
    if (k < s.seam_tacks.size()) seams[k].tacks = s.seam_tacks[k];
  }
  return seams;
}

const char* joint_name(JointType joint) {
  switch (joint) {
    case JointType::kV:
      return "V";
    case JointType::kBevel:
      return "bevel";
    case JointType::kFillet:
      return "fillet";
    case JointType::kLap:
      return "lap";
  }
  return "?";
}

JointType parse_joint(const std::string& name) {
  if (name == "v") return JointType::kV;
  for (JointType j : {JointType::kV, JointType::kBevel, JointType::kFillet, JointType::kLap})
    if (name == joint_name(j)) return j;
  throw UsageError("unknown joint '" + name + "' (expected v|bevel|fillet|lap)");
}

const char* shape_name(Shape shape) {
  switch (shape) {
    case Shape::kStraight:
      return "straight";
    case Shape::kCurve:
      return "curve";
    case Shape::kBox:
      return "box";
    case Shape::kCylinder:
      return "cylinder";
    case Shape::kPipeLong:
      return "pipe-long";
    case Shape::kLShape:
      return "lshape";
    case Shape::kMulti:
      return "multi";
  }
  return "?";
}

std::vector<std::string> shape_names() {
  std::vector<std::string> names;
  for (Shape s : {Shape::kStraight, Shape::kCurve, Shape::kBox, Shape::kCylinder, Shape::kPipeLong,
                  Shape::kLShape, Shape::kMulti})
    names.emplace_back(shape_name(s));
  return names;
}

Shape parse_shape(const std::string& name) {
  for (Shape s : {Shape::kStraight, Shape::kCurve, Shape::kBox, Shape::kCylinder, Shape::kPipeLong,
                  Shape::kLShape, Shape::kMulti})
    if (name == shape_name(s)) return s;
  std::string known;
  for (const std::string& n : shape_names()) known += (known.empty() ? "" : "|") + n;
  throw UsageError("unknown shape '" + name + "' (expected " + known + ")");
}

}  // namespace groovetrace
