// The top surface around a point of a seam: its normal from the voxels beside the groove, the
// seam's tangent laid into it, and whether the sensor sees it at a slant.

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "core/eigen3.hpp"
#include "core/stats.hpp"
#include "robust/context.hpp"

namespace groovetrace::robust_detail {
namespace {

// The normal of the surface at q, from the points `pts` (weights `w`) whose plane's normal is
// `n`. A plane's normal is the surface's at the points' centroid; on a pipe's flank, seen from
// one side at a grazing angle, the centroid lies millimetres along the seam from q, and on
// girth seams the sections tilted with the pipe's turn by up to 10-20 deg towards the seam's
// ends, and the torch with them. So on a seam that bends out of its surface (trace.cpp,
// bends_out_of_surface) the normal is that of a quadratic height field over the plane, taken
// at q's foot. On plates the plane stays: there a quadratic only adds noise.
Eigen::Vector3d curved_normal_at(const std::vector<Eigen::Vector3d>& pts,
                                 const std::vector<double>& w, const Eigen::Vector3d& n,
                                 const Eigen::Vector3d& q) {
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const double x = e1.dot(pts[k]), y = e2.dot(pts[k]);
    Eigen::Matrix<double, 6, 1> f;
    f << 1, x, y, x * x, x * y, y * y;
    A += w[k] * f * f.transpose();
    b += w[k] * f * n.dot(pts[k]);
  }
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(A);
  const Eigen::Matrix<double, 6, 1> h = ldlt.solve(b);
  if (ldlt.info() != Eigen::Success || !h.allFinite()) return n;
  const double x = e1.dot(q), y = e2.dot(q);
  const double hx = h[1] + 2 * h[3] * x + h[4] * y, hy = h[2] + h[4] * x + 2 * h[5] * y;
  const Eigen::Vector3d m = n - hx * e1 - hy * e2;
  return m.norm() > 1e-9 ? Eigen::Vector3d(m.normalized()) : n;
}

// The surface normal at p: the plane of the voxels within `scale` of p that are not in a
// groove (concavity below half the candidate threshold), PCA reweighted twice (Tukey on the
// distance to the plane, scale from the residuals' MAD). Only the top surface counts, so a
// wall the sensor did not see cannot tilt it; the reweighting drops what lies off that plane
// - near a part's end its end face and the table beyond, which tilted the tool by up to 7 deg
// over a seam's last 10 mm. `curved`: the normal is then taken at p's foot on a curved
// surface fitted to the same voxels (curved_normal_at), so it follows a seam round a pipe to
// the seam's ends. `fallback` when too few voxels qualify.
Eigen::Vector3d surface_normal(const Context& ctx, const Eigen::Vector3d& p, bool curved,
                               const Eigen::Vector3d& fallback) {
  const float r = static_cast<float>(ctx.params.scale);
  const double limit = 0.5 * ctx.map.threshold;
  // Centred half a scale above p (p is near the root): the top surface around the opening.
  const Eigen::Vector3d c = p + 0.5 * ctx.params.scale * fallback.normalized();
  std::vector<Eigen::Vector3d> pts;
  ctx.voxel_grid.for_each_within(c.cast<float>(), r, [&](std::uint32_t j, float) {
    if (ctx.map.concavity[j] < limit) pts.push_back(ctx.map.points[j].cast<double>() - c);
  });
  if (pts.size() < 20) return fallback;
  std::vector<double> w(pts.size(), 1.0), dist(pts.size());
  Eigen::Vector3d n = fallback;
  for (int iter = 0; iter < 3; ++iter) {
    double sw = 0;
    Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
    for (std::size_t k = 0; k < pts.size(); ++k) {
      sw += w[k];
      s1 += w[k] * pts[k];
      s2 += w[k] * pts[k] * pts[k].transpose();
    }
    if (!(sw > 10)) break;
    const Eigen::Vector3d mean = s1 / sw;
    n = smallest_eigenvector(s2 / sw - mean * mean.transpose());
    if (iter == 2) break;
    for (std::size_t k = 0; k < pts.size(); ++k) dist[k] = std::abs(n.dot(pts[k] - mean));
    // Floor: a tenth of a voxel, so that a noise-free plane does not reject its own rounding.
    const double cut = kTukeyC * std::max(kMadToSigma * upper_median(dist), 0.1 * ctx.params.cell);
    for (std::size_t k = 0; k < pts.size(); ++k) w[k] = tukey_weight(dist[k], cut);
  }
  if (n.dot(fallback) < 0) n = -n;
  return curved ? curved_normal_at(pts, w, n, p - c) : n;
}

}  // namespace

// The tangent taken in the surface at p: the roots' depth wobble (undulation, one-wall fits)
// must not tip a section. Only the top-surface normal's component along the seam matters here,
// so its tilt across the seam (a wall the sensor did not see) does no harm.
Eigen::Vector3d surface_tangent(const Context& ctx, const Eigen::Vector3d& p,
                                const Eigen::Vector3d& tangent, const Eigen::Vector3d& normal,
                                bool curved) {
  const Eigen::Vector3d n = surface_normal(ctx, p, curved, normal).normalized();
  const Eigen::Vector3d t = tangent - tangent.dot(n) * n;
  return t.norm() > 1e-6 ? Eigen::Vector3d(t.normalized()) : tangent;
}

// A gap in the top surface stands for a groove only where the walls can hide: where the
// surface is seen at a slant (over kGrazingDeg incidence; a pipe's flanks). Square on, a gap is a
// hole or the part's end.
constexpr double kGrazingDeg = 55.0;
bool grazing(const Context& ctx, const Eigen::Vector3d& p, const Eigen::Vector3d& normal) {
  const Eigen::Vector3d ray = (ctx.cloud.viewpoint.cast<double>() - p).normalized();
  return std::abs(ray.dot(normal.normalized())) < std::cos(deg_to_rad(kGrazingDeg));
}

}  // namespace groovetrace::robust_detail
