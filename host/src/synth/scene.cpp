// Workpieces of the synthetic scans as signed distance bounds, and ray casting against them.
//
// Every workpiece is a body (a box or a pipe) minus the groove's cut. The cut is defined in a
// 2-D cross-section (d, z'): d = distance from the seam's centre plane or path (>= 0), z' =
// height relative to the top surface. Because (d, z') is a 1-Lipschitz function of the 3-D
// point, a 1-Lipschitz 2-D bound composed with it is a valid 3-D distance bound, so one cut
// function serves straight, curved, circumferential and axial seams alike. Sphere tracing on
// that bound, then bisection on its sign, finds the exact boundary of the solid, whose faces
// (planes, cylinders) are therefore hit to far better than 1e-5 m.

#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <limits>
#include <string>
#include <vector>

#include "core/stats.hpp"
#include "synth/internal.hpp"

namespace groovetrace {
namespace {

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

  double distance(const Eigen::Vector2d& p) const {
    if (!arc) {
      const Eigen::Vector2d ab = b - a;
      const double s = std::clamp((p - a).dot(ab) * inv_length2, 0.0, 1.0);
      return (p - (a + s * ab)).norm();
    }
    const Eigen::Vector2d q = p - centre;
    bool within = false;
    if (std::abs(sweep) <= kPi) {
      // Inside the arc's wedge: on the sweep side of the start ray and before the end ray
      // (cross products; cheaper than atan2, which this runs millions of times).
      const Eigen::Vector2d s = a - centre, e = b - centre;
      const double sense = sweep > 0 ? 1.0 : -1.0;
      within = sense * (s.x() * q.y() - s.y() * q.x()) >= 0.0 &&
               sense * (q.x() * e.y() - q.y() * e.x()) >= 0.0;
    } else {
      // Angle of p from `start` in the arc's sense of rotation, in [0, 2 pi).
      double rel = std::atan2(q.y(), q.x()) - start;
      if (sweep < 0) rel = -rel;
      rel -= 2.0 * kPi * std::floor(rel / (2.0 * kPi));
      within = rel <= std::abs(sweep);
    }
    if (within) return std::abs(q.norm() - radius);
    return std::min((p - a).norm(), (p - b).norm());
  }
};

using Path = std::vector<PathPiece>;

enum class Body { kBox, kPipe };
// How the cross-section coordinates (d, z') are taken from a 3-D point.
enum class Profile {
  kPath,             // d = distance to a path in the table plane, z' = z - top
  kCircumferential,  // d = |x| (groove plane x = 0), z' = radius from the pipe axis - R
  kAxial,            // d = |y| (groove plane y = 0), z' = z - top of the pipe
};

}  // namespace

struct SynthScene::Impl {
  GrooveGeometry groove;
  double half_gap = 0.0;
  double k = 0.0;          // tan(included angle / 2): wall run per unit of depth
  double wall_norm = 1.0;  // 1 / sqrt(1 + k^2), makes the wall's distance 1-Lipschitz

  Body body = Body::kBox;
  Eigen::Vector3d box_min{0, 0, 0}, box_max{0, 0, 0};  // also the bounding box of a pipe
  double pipe_radius = 0.0, pipe_inner = 0.0, pipe_half_length = 0.0, pipe_axis_z = 0.0;

  Profile profile = Profile::kPath;
  std::vector<Path> paths;
  double top_z = 0.0;         // height of the top surface at the seam (m)
  bool gap_to_table = false;  // the root gap runs down to the table (plates)

  Eigen::Vector3d look_at{0, 0, 0};

  double path_distance(const Eigen::Vector2d& p) const {
    double d = kInf;
    for (const Path& path : paths)
      for (const PathPiece& piece : path) d = std::min(d, piece.distance(p));
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

  double sdf(const Eigen::Vector3d& p) const { return std::max(body_sdf(p), -cut_sdf(p)); }

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

  // Entry and exit of the ray in the bounding box (slab method).
  bool clip(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, double& t0, double& t1) const {
    t0 = -kInf;
    t1 = kInf;
    for (int a = 0; a < 3; ++a) {
      if (dir[a] == 0.0) {
        if (o[a] < box_min[a] || o[a] > box_max[a]) return false;
        continue;
      }
      double ta = (box_min[a] - o[a]) / dir[a];
      double tb = (box_max[a] - o[a]) / dir[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    return t0 <= t1;
  }

  void build(Shape shape);
  std::vector<std::vector<Eigen::Vector2d>> sample_path(const Path& path) const;

  // First t in [t0, t1] where the ray is inside the solid; NaN if none.
  double march(const Eigen::Vector3d& o, const Eigen::Vector3d& dir, double t0, double t1) const {
    double t = t0;
    double f = sdf(o + t * dir);
    if (f <= 0.0) return t;
    for (int i = 0; i < kMaxSteps && t < t1; ++i) {
      const double t_next = std::min(t + std::max(f, kMinStep), t1);
      const double f_next = sdf(o + t_next * dir);
      if (f_next <= 0.0) {
        double lo = t, hi = t_next;  // f(lo) > 0 >= f(hi)
        while (hi - lo > kBisectTolerance) {
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

// Builds the workpiece of a shape. Dimensions are fixed per shape (metres); the groove's
// cross-section comes from the params.
void SynthScene::Impl::build(Shape shape) {
  Impl& s = *this;
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
    s.pipe_radius = 0.05;
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
  s.build(params.shape);
}

SynthScene::~SynthScene() = default;

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
        // The groove's faces are where the cut, not the body, bounds the solid; the body's
        // faces have analytic normals, the cut's come from the distance bound's gradient.
        hit.label = -s.cut_sdf(hit.point) >= s.body_sdf(hit.point) ? 1 : 0;
        hit.normal = hit.label ? s.gradient(hit.point) : s.body_normal(hit.point);
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
  const auto add = [&seams](Seam seam) {
    seam.in_view.assign(seam.root.size(), 1);
    seams.push_back(std::move(seam));
  };
  const double depth = s.groove.depth;
  switch (s.profile) {
    case Profile::kPath:
      for (const Path& path : s.paths) {
        for (const auto& run : s.sample_path(path)) {
          Seam seam;
          for (const Eigen::Vector2d& p : run) {
            seam.root.emplace_back(p.x(), p.y(), s.top_z - depth);
            seam.normal.push_back(Eigen::Vector3d::UnitZ());
            seam.bisector.push_back(Eigen::Vector3d::UnitZ());
          }
          add(std::move(seam));
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
      add(std::move(seam));
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
      add(std::move(seam));
      break;
    }
  }
  return seams;
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
