// Multi-pass planning: the beads that fill a groove's cross-section, and the section at every
// waypoint of a seam's path (docs/robot.md, "Multi-pass welds").

#include <algorithm>
#include <cmath>
#include <groovetrace/error.hpp>
#include <groovetrace/weld.hpp>

#include "core/stats.hpp"

namespace groovetrace {
namespace {

// A flat parabolic bead: area = 2/3 * width * height, width = kBeadAspect * height. Fill beads
// of GMAW run 2-3 times wider than high.
constexpr double kBeadAspect = 2.5;

// Area between the walls from height a to b above the root (m^2): the width grows linearly.
double area_between(const SectionShape& s, double a, double b) {
  return 0.5 * (s.run_pos_y + s.run_neg_y) * (b * b - a * a);
}

// The layer's beads side by side across its width at mid-height, +y first. The outermost beads
// of a layer of two or more lean towards their wall by a quarter of the angle between the wall
// and the layer's flat top, so the arc wets the corner (a rule of thumb: 15 deg at a 60 deg V,
// 22.5 deg at a square wall); the others stay on the path's axis.
void add_layer(PassPlan& plan, const SectionShape& s, int layer, double base, double top, int n,
               const std::string& kind, int& numbered) {
  const double mid = 0.5 * (base + top);
  const double hi = s.run_pos_y * mid, lo = -s.run_neg_y * mid;
  for (int i = 0; i < n; ++i) {
    Bead b;
    b.layer = layer;
    b.height = base;
    b.mid_height = mid;
    b.lateral = hi - (i + 0.5) * (hi - lo) / n;
    if (n >= 2 && (i == 0 || i == n - 1)) {
      const double wall_deg = rad_to_deg(std::atan(i == 0 ? s.run_pos_y : s.run_neg_y));
      // Work angle + turns tool z towards -y: the +y wall's bead needs a negative one.
      b.work_angle = (i == 0 ? -1.0 : 1.0) * 0.25 * (90.0 - wall_deg);
    }
    // The first bead lies on the root; a shallow groove's one layer is also its cap.
    b.name = plan.beads.empty() ? "root" : kind + " " + std::to_string(++numbered);
    plan.beads.push_back(b);
  }
}

}  // namespace

PassPlan plan_passes(const SectionShape& s, double bead_area) {
  if (!(std::isfinite(bead_area) && bead_area > 0)) {
    throw UsageError("bead_area: the bead area must be positive");
  }
  if (!(s.depth > 0 && s.run_pos_y >= 0 && s.run_neg_y >= 0 && s.width_at(1.0) > 0)) {
    throw UsageError("multi_pass: the groove's section has no depth or width to fill");
  }
  PassPlan plan;
  plan.bead_area = bead_area;
  plan.section_area = area_between(s, 0.0, s.depth);
  plan.bead_height = std::sqrt(1.5 * bead_area / kBeadAspect);
  plan.bead_width = kBeadAspect * plan.bead_height;
  int fills = 0, caps = 0;
  double base = 0.0;
  for (int layer = 0; base < s.depth; ++layer) {
    // As many beads as fit across the layer's middle; the layer is as high as they fill.
    const double guess_mid = base + 0.5 * plan.bead_height;
    int n = std::max(1, static_cast<int>(std::lround(s.width_at(guess_mid) / plan.bead_width)));
    double top = std::sqrt(base * base + 2.0 * n * bead_area / (s.run_pos_y + s.run_neg_y));
    // The last layer reaches the top and covers its whole width: the cap (its excess over the
    // section is the reinforcement). A layer ending within half a bead of the top is the cap.
    if (top > s.depth - 0.5 * plan.bead_height) {
      const double rest = area_between(s, base, s.depth);
      n = std::max({1, static_cast<int>(std::ceil(rest / bead_area - 1e-9)),
                    static_cast<int>(std::ceil(s.width_at(s.depth) / plan.bead_width - 1e-9))});
      add_layer(plan, s, layer, base, s.depth, n, "cap", caps);
      break;
    }
    add_layer(plan, s, layer, base, top, n, "fill", fills);
    base = top;
  }
  return plan;
}

double bead_area(const WeldParams& weld, const ProgramParams& program) {
  if (weld.bead_area > 0) return weld.bead_area;
  const double wire = 0.25 * M_PI * weld.wire_diameter * weld.wire_diameter;
  return wire * weld.wire_feed / program.weld_speed;
}

namespace {

// The section of one fitted cross-section in a pose's tool frame: each top edge's distance
// across (along tool y) per metre of depth.
SectionShape shape_of(const GrooveSection& g, const Eigen::Vector3d& tool_y) {
  SectionShape s;
  s.depth = g.depth;
  const double a = (g.edge_left - g.root).dot(tool_y), b = (g.edge_right - g.root).dot(tool_y);
  s.run_pos_y = std::max({a, b, 0.0}) / g.depth;
  s.run_neg_y = std::max({-a, -b, 0.0}) / g.depth;
  return s;
}

bool usable(const GrooveSection& g) {
  return g.ok && !g.corner && std::isfinite(g.depth) && g.depth > 1e-4 && g.root.allFinite() &&
         g.edge_left.allFinite() && g.edge_right.allFinite();
}

}  // namespace

std::vector<SectionShape> section_shapes(const Trajectory& path, const SeamCandidate& seam) {
  std::vector<const GrooveSection*> fitted;
  for (const GrooveSection& g : seam.sections) {
    if (usable(g)) fitted.push_back(&g);
  }
  std::vector<SectionShape> shapes;
  if (fitted.empty()) return shapes;
  for (const Waypoint& w : path.waypoints) {
    const Eigen::Vector3d y = w.orientation * Eigen::Vector3d::UnitY();
    const GrooveSection* best = fitted.front();
    for (const GrooveSection* g : fitted) {
      if ((g->root - w.position).squaredNorm() < (best->root - w.position).squaredNorm()) best = g;
    }
    shapes.push_back(shape_of(*best, y));
  }
  return shapes;
}

}  // namespace groovetrace
