// Stage 2 of the robust method, corners: a fillet (T-joint) or a lap joint is a concave corner
// between two faces, with no top surface across it for the V model to stand on. The profile
// (u across, v out of the workpiece, m) is fitted with two straight faces meeting at the root:
// each face a Tukey-weighted line through the points nearest to it, the root their
// intersection, refitted as the points change faces. The weld itself is not in the scan, so its
// size is the user's: its legs (`leg`, m) run from the root along each face, and the weld face
// between their ends is the joint's opening (what labels the region and orients the torch).

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/stats.hpp"
#include "robust/stages.hpp"
#include "robust/vmodel.hpp"

namespace groovetrace {
namespace {

using robust_detail::fit_line;
using robust_detail::robust_sigma;

// A face of the corner: a ray from the root along the face, its points and fit.
struct Face {
  Eigen::Vector2d dir{0, 1};         // unit, from the root along the face
  std::vector<Eigen::Vector2d> pts;  // the points nearest to this face, off the root
  int inliers = 0;                   // points of its unbroken run (measure_corner)
  double extent = 0;                 // where that run ends, from the root along dir (m)
};

// Distance (m) from p to the ray from `root` along `dir`.
double ray_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& root,
                    const Eigen::Vector2d& dir) {
  const double t = std::max(0.0, (p - root).dot(dir));
  return (p - (root + t * dir)).norm();
}

// Intersection of the lines through a along da and b along db; false when near parallel.
bool intersect(const Eigen::Vector2d& a, const Eigen::Vector2d& da, const Eigen::Vector2d& b,
               const Eigen::Vector2d& db, Eigen::Vector2d& out) {
  Eigen::Matrix2d M;
  M.col(0) = da;
  M.col(1) = -db;
  if (std::abs(M.determinant()) < 0.2) return false;  // faces within ~12 deg of parallel
  out = a + (M.inverse() * (b - a)).x() * da;
  return out.allFinite();
}

// Turns `face`'s direction to run away from `root`, towards its point `on_line`.
void point_away(Face& face, const Eigen::Vector2d& root, const Eigen::Vector2d& on_line) {
  if ((on_line - root).dot(face.dir) < 0) face.dir = -face.dir;
}

// Fits a line to `face.pts` at Tukey `scale` (m) and points it away from `root`. Once the face
// has an extent, the points within `zone` (m) of its far end stay out: a lap's upper plate edge
// is rounded off there as a V's rims are, and the upper plate's top begins.
void fit_face(Face& face, const Eigen::Vector2d& root, double scale, double zone,
              Eigen::Vector2d& on_line) {
  std::vector<Eigen::Vector2d> used;
  for (const auto& p : face.pts) {
    if (!(face.extent > 0) || (p - root).dot(face.dir) <= face.extent - zone) used.push_back(p);
  }
  const auto [c, d] = fit_line(used.size() >= 8 ? used : face.pts, scale);
  on_line = c;
  face.dir = d;
  point_away(face, root, on_line);
}

// The corner's state as the fit moves it.
struct Corner {
  Eigen::Vector2d root{0, 0};
  Face left, right;
  double sigma = 0;     // robust sigma of the points' distances to their faces (m)
  int upper = 0;        // points on a lap's upper plate (upper_plate_points)
  std::size_t far = 0;  // points farther than the zone from the root
};

// Whether p, on the side of `face`, lies within its reach: up to two zones past its extent
// (m; a face without an extent yet reaches everywhere). Past a lap's upper plate edge its
// top begins, which is no part of the edge's face.
bool within_reach(const Eigen::Vector2d& p, const Eigen::Vector2d& root, const Face& face,
                  double zone) {
  return !(face.extent > 0) || (p - root).dot(face.dir) <= face.extent + 2 * zone;
}

// One round: every point farther than `zone` from the root goes to the face it lies nearer -
// if within 3 sigma (at least `zone`) of it and within its reach (the first round splits at u =
// root.u and takes the points within `start` of the root: a lap's upper plate top, more points than
// its edge face in a wide window, must not be taken for that face), both faces are refitted, the
// root moves to their intersection. False when a face has too few points or the faces are near
// parallel.
bool refit_corner(const std::vector<Eigen::Vector2d>& pts, Corner& c, double zone, double scale,
                  bool first, double start) {
  c.left.pts.clear();
  c.right.pts.clear();
  c.far = 0;
  for (const auto& p : pts) {
    const double r = (p - c.root).norm();
    if (r < zone) continue;
    ++c.far;
    if (first) {
      if (r <= start) (p.x() < c.root.x() ? c.left : c.right).pts.push_back(p);
      continue;
    }
    const double dl = ray_distance(p, c.root, c.left.dir);
    const double dr = ray_distance(p, c.root, c.right.dir);
    Face& face = dl < dr ? c.left : c.right;
    if (std::min(dl, dr) <= std::max(3 * c.sigma, zone) && within_reach(p, c.root, face, zone))
      face.pts.push_back(p);
  }
  if (c.left.pts.size() < 8 || c.right.pts.size() < 8) return false;
  Eigen::Vector2d on_l, on_r;
  fit_face(c.left, c.root, scale, zone, on_l);
  fit_face(c.right, c.root, scale, zone, on_r);
  if (!intersect(on_l, c.left.dir, on_r, c.right.dir, c.root)) return false;
  point_away(c.left, c.root, on_l);
  point_away(c.right, c.root, on_r);
  return true;
}

// The corner's sigma (from its faces' points), and each face's run: of all points `pts` within
// 3 sigma of the face (none within `zone` of the root), those in an unbroken run from the root
// (no gap over `gap`, m) - its inliers and its extent, where the face ends (a lap's upper plate
// edge) or leaves the window.
void measure_corner(const std::vector<Eigen::Vector2d>& pts, Corner& c, double zone, double gap) {
  std::vector<double> r;
  for (Face* f : {&c.left, &c.right}) {
    for (const auto& p : f->pts) r.push_back(ray_distance(p, c.root, f->dir));
  }
  c.sigma = robust_sigma(r);
  for (Face* f : {&c.left, &c.right}) {
    std::vector<double> along;
    for (const auto& p : pts) {
      if ((p - c.root).norm() >= zone && ray_distance(p, c.root, f->dir) <= 3 * c.sigma)
        along.push_back((p - c.root).dot(f->dir));
    }
    std::sort(along.begin(), along.end());
    f->inliers = 0;
    f->extent = 0;
    for (double t : along) {
      if (t > f->extent + gap && f->inliers > 0) break;
      ++f->inliers;
      f->extent = t;
    }
  }
}

// A lap's upper plate: beyond the end of the shorter face (the upper plate's edge), points off
// both faces that lie on a line parallel to the longer face (the upper plate's top, a plate
// thickness above the lower one's). How many points that line holds; 0 when it is not there.
int upper_plate_points(const std::vector<Eigen::Vector2d>& pts, const Corner& c, double scale) {
  const bool left_short = c.left.extent < c.right.extent;
  const Face& edge = left_short ? c.left : c.right;
  const Face& lower = left_short ? c.right : c.left;
  const double tol = 3 * c.sigma;
  std::vector<Eigen::Vector2d> off;
  for (const auto& p : pts) {
    if (ray_distance(p, c.root, c.left.dir) <= tol || ray_distance(p, c.root, c.right.dir) <= tol)
      continue;
    if ((p - c.root).dot(edge.dir) > 0.5 * edge.extent) off.push_back(p);
  }
  if (off.size() < 5) return 0;
  const auto [on, dir] = fit_line(off, scale);
  if (std::abs(dir.dot(lower.dir)) < std::cos(deg_to_rad(15))) return 0;
  const Eigen::Vector2d n(-dir.y(), dir.x());
  // C++17 lets no lambda capture a structured binding (clang refuses it), so `on` is copied.
  return static_cast<int>(std::count_if(
      off.begin(), off.end(),
      [&, on = on](const Eigen::Vector2d& p) { return std::abs((p - on).dot(n)) <= tol; }));
}

// Why the fitted corner is not a fillet or lap joint, or nullptr when it is: both faces
// straight and at least a leg long, the corner open towards the sensor at 60-120 deg, near
// the window's centre, and nothing else in the window but a lap's upper plate (a top surface
// or another face would leave points off both faces).
const char* why_not_corner(const Corner& c, double W, double leg, const Eigen::Vector2d& view) {
  const double opening = rad_to_deg(std::acos(std::clamp(c.left.dir.dot(c.right.dir), -1.0, 1.0)));
  if (opening < 60 || opening > 120) return "corner: implausible angle";
  if ((c.left.dir + c.right.dir).normalized().dot(view) < 0.3)
    return "corner: not open to the sensor";
  if (std::abs(c.root.x()) > 0.5 * W) return "corner: root leaves the window";
  if (c.sigma > 0.08 * W) return "corner: faces are not straight";
  if (c.left.extent < leg || c.right.extent < leg) return "corner: a face is shorter than the leg";
  if (c.left.inliers + c.right.inliers + c.upper < 0.8 * static_cast<double>(c.far)) {
    return "corner: points off both faces";
  }
  return nullptr;
}

// The corner as a profile: root, the legs' ends as edges, the weld face as the top.
VProfile describe_corner(const Corner& c, double leg) {
  VProfile o;
  o.corner = true;
  o.root = c.root;
  o.edge_left = c.root + leg * c.left.dir;
  o.edge_right = c.root + leg * c.right.dir;
  const Eigen::Vector2d chord = o.edge_right - o.edge_left;
  const double slope = chord.y() / chord.x();
  o.top = Eigen::Vector3d(o.edge_left.y() - slope * o.edge_left.x(), slope, 0);
  o.bisector = (c.left.dir + c.right.dir).normalized();
  o.opening_deg = rad_to_deg(std::acos(std::clamp(c.left.dir.dot(c.right.dir), -1.0, 1.0)));
  const Eigen::Vector2d along = chord.normalized();
  o.wall_left_deg = rad_to_deg(std::acos(std::clamp(c.left.dir.dot(-along), -1.0, 1.0)));
  o.wall_right_deg = rad_to_deg(std::acos(std::clamp(c.right.dir.dot(along), -1.0, 1.0)));
  o.width = chord.norm();
  o.depth = std::abs(Eigen::Vector2d(-along.y(), along.x()).dot(c.root - o.edge_left));
  o.noise = o.rms = c.sigma;
  o.wall_left = c.left.inliers;
  o.wall_right = c.right.inliers;
  o.short_face = c.upper > 0;
  return o;
}

}  // namespace

VProfile fit_corner_profile(const std::vector<Eigen::Vector2d>& uv, double half_window, double leg,
                            const Eigen::Vector2d& view) {
  VProfile out;
  const double W = half_window;
  std::vector<Eigen::Vector2d> pts;
  for (const auto& p : uv) {
    if (std::abs(p.x()) <= W && p.allFinite()) pts.push_back(p);
  }
  Corner c;
  // Start at the lowest point near the centre: the crease node sits on the corner.
  double lowest = INFINITY;
  for (const auto& p : pts) {
    if (std::abs(p.x()) < 0.25 * W && p.y() < lowest) {
      lowest = p.y();
      c.root = p;
    }
  }
  const double zone = 0.1 * W;
  double scale = 0.05 * W;
  for (int round = 0; round < 4; ++round) {
    if (!refit_corner(pts, c, zone, scale, round == 0, 0.5 * W)) {
      out.why = "corner: no two faces";
      return out;
    }
    measure_corner(pts, c, zone, 0.15 * W);
    scale = std::max(c.sigma, 0.005 * W);
  }
  c.upper = upper_plate_points(pts, c, scale);
  if (const char* why = why_not_corner(c, W, leg, view.normalized())) {
    out.why = why;
    return out;
  }
  out = describe_corner(c, leg);
  out.ok = true;
  return out;
}

}  // namespace groovetrace
