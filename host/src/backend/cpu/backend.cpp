// The CPU reference backend: plain loops over a neighbour grid, double accumulation,
// OpenMP across points. Every OpenCL kernel is checked against these results.
#include <omp.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <groovetrace/features.hpp>

#include "backend/cpu/crease.hpp"
#include "core/eigen3.hpp"
#include "core/neighbor_grid.hpp"
#include "core/stats.hpp"

namespace groovetrace {
namespace {

double angle_deg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  const double c = std::clamp(static_cast<double>(a.dot(b)), -1.0, 1.0);
  return rad_to_deg(std::acos(c));
}

// Weighted plane (and optionally quadric) fit around point i; returns the projected point.
// The neighbourhood of the one query is kept in a per-thread scratch buffer so the quadric
// pass does not search again (this is not a neighbour list: nothing outlives the query).
Eigen::Vector3f mls_project(const Cloud& cloud, const NeighborGrid& grid, std::size_t i,
                            const SmoothParams& params) {
  struct Sample {
    Eigen::Vector3d d;
    double w;
  };
  thread_local std::vector<Sample> samples;
  samples.clear();
  const Eigen::Vector3f p = cloud.point(i);
  const double inv_h2 = 1.0 / (static_cast<double>(params.radius) * params.radius);
  // Offsets from the query point keep the sums well conditioned in float input.
  double sw = 0;
  Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
  grid.for_each_within(p, params.radius, [&](std::uint32_t j, float d2) {
    const double w = std::exp(-d2 * inv_h2);
    const Eigen::Vector3d d = (cloud.point(j) - p).cast<double>();
    sw += w;
    s1 += w * d;
    s2 += w * d * d.transpose();
    samples.push_back({d, w});
  });
  const int count = static_cast<int>(samples.size());
  if (count < params.min_neighbors || sw <= 0) return p;
  const Eigen::Vector3d mean = s1 / sw;
  const Eigen::Matrix3d cov = s2 / sw - mean * mean.transpose();
  const Eigen::Vector3d n = smallest_eigenvector(cov);
  // Query point relative to the weighted mean, in the plane frame (u, v, n).
  const Eigen::Vector3d q = -mean;
  double height = q.dot(n);  // plane projection: remove the normal component entirely
  double fitted = 0.0;
  if (params.order >= 2 && count >= 6) {
    const Eigen::Vector3d u = n.unitOrthogonal();
    const Eigen::Vector3d v = n.cross(u);
    Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
    for (const Sample& s : samples) {
      const Eigen::Vector3d d = s.d - mean;
      const double a = d.dot(u), b = d.dot(v), h = d.dot(n);
      Eigen::Matrix<double, 6, 1> row;
      row << 1, a, b, a * a, a * b, b * b;
      ata.selfadjointView<Eigen::Lower>().rankUpdate(row, s.w);
      atb += s.w * h * row;
    }
    Eigen::LDLT<Eigen::Matrix<double, 6, 6>, Eigen::Lower> ldlt(ata);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive()) {
      const Eigen::Matrix<double, 6, 1> c = ldlt.solve(atb);
      const double a = q.dot(u), b = q.dot(v);
      const double f = c(0) + c(1) * a + c(2) * b + c(3) * a * a + c(4) * a * b + c(5) * b * b;
      if (std::isfinite(f)) fitted = f;
    }
  }
  return (p.cast<double>() - (height - fitted) * n).cast<float>();
}

class CpuBackend final : public FeatureBackend {
 public:
  std::string name() const override { return "cpu"; }
  std::string device() const override {
    return "OpenMP, " + std::to_string(omp_get_max_threads()) + " threads";
  }

  Cloud smooth(const Cloud& cloud, const SmoothParams& params) override {
    Cloud out = cloud;
    const NeighborGrid grid(cloud, params.radius);
    const std::int64_t n = static_cast<std::int64_t>(cloud.size());
#pragma omp parallel for schedule(dynamic, 1024)
    for (std::int64_t i = 0; i < n; ++i) {
      if (!cloud.valid(i)) continue;
      const Eigen::Vector3f q = mls_project(cloud, grid, i, params);
      out.x[i] = q.x();
      out.y[i] = q.y();
      out.z[i] = q.z();
    }
    return out;
  }

  Normals normals(const Cloud& cloud, float radius, int min_neighbors) override {
    Normals out;
    out.resize(cloud.size());
    const NeighborGrid grid(cloud, radius);
    const std::int64_t n = static_cast<std::int64_t>(cloud.size());
#pragma omp parallel for schedule(dynamic, 1024)
    for (std::int64_t i = 0; i < n; ++i) {
      if (!cloud.valid(i)) continue;
      const Eigen::Vector3f p = cloud.point(i);
      Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
      Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
      int count = 0;
      grid.for_each_within(p, radius, [&](std::uint32_t j, float) {
        const Eigen::Vector3d d = (cloud.point(j) - p).cast<double>();
        s1 += d;
        s2 += d * d.transpose();
        ++count;
      });
      if (count < min_neighbors || count < 3) continue;
      const Eigen::Vector3d mean = s1 / count;
      const Eigen::Matrix3d cov = s2 / count - mean * mean.transpose();
      Eigen::Vector3d normal = smallest_eigenvector(cov);
      if (normal.dot((cloud.viewpoint - p).cast<double>()) < 0) normal = -normal;
      out.x[i] = static_cast<float>(normal.x());
      out.y[i] = static_cast<float>(normal.y());
      out.z[i] = static_cast<float>(normal.z());
    }
    return out;
  }

  std::vector<float> descriptor(const Cloud& cloud, const Normals& normals, float radius,
                                const Eigen::Vector3f& u_b) override {
    std::vector<float> out(cloud.size(), NAN);
    const NeighborGrid grid(cloud, radius);
    const std::int64_t n = static_cast<std::int64_t>(cloud.size());
#pragma omp parallel for schedule(dynamic, 1024)
    for (std::int64_t i = 0; i < n; ++i) {
      if (!cloud.valid(i) || !normals.valid(i)) continue;
      const Eigen::Vector3f n_i = normals.normal(i);
      double l1 = 0, l2 = 0, g1 = 0, g2 = 0;
      int nl = 0, ng = 0;
      grid.for_each_within(cloud.point(i), radius, [&](std::uint32_t j, float) {
        if (!normals.valid(j)) return;
        const Eigen::Vector3f n_j = normals.normal(j);
        const double beta = angle_deg(u_b, n_j);
        g1 += beta;
        g2 += beta * beta;
        ++ng;
        if (j == static_cast<std::uint32_t>(i)) return;
        const double theta = angle_deg(n_i, n_j);
        l1 += theta;
        l2 += theta * theta;
        ++nl;
      });
      if (nl == 0) continue;
      const double ml = l1 / nl, mg = g1 / ng;
      const double var_l = std::max(0.0, l2 / nl - ml * ml);
      const double var_g = std::max(0.0, g2 / ng - mg * mg);
      out[i] = static_cast<float>(std::sqrt(var_l * var_l + var_g * var_g));
    }
    return out;
  }

  CreaseMeasure crease(const Cloud& cloud, const CreaseParams& params) override {
    return crease_cpu(cloud, params);
  }
};

}  // namespace

std::unique_ptr<FeatureBackend> make_cpu_backend() { return std::make_unique<CpuBackend>(); }

}  // namespace groovetrace
