#pragma once
// The paper's pipeline built from PCL, the side-by-side peer of the groovetrace backends:
// MovingLeastSquares, NormalEstimationOMP and the GFH descriptor over pcl::search::KdTree,
// each on 2 threads like the backends on this machine.
#include <omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/search/kdtree.h>
#include <pcl/search/organized.h>
#include <pcl/surface/mls.h>

#include <algorithm>
#include <cmath>

#include "bench_common.hpp"

namespace bench {

constexpr int kPclThreads = 2;

inline pcl::PointCloud<pcl::PointXYZ> pcl_mls(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                                              float radius) {
  pcl::MovingLeastSquares<pcl::PointXYZ, pcl::PointXYZ> mls;
  mls.setInputCloud(cloud);
  mls.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  mls.setSearchRadius(radius);
  mls.setPolynomialOrder(2);
  mls.setNumberOfThreads(kPclThreads);
  pcl::PointCloud<pcl::PointXYZ> out;
  mls.process(out);
  return out;
}

// Normals over a kd-tree (organized = false) or OrganizedNeighbor, flipped to the viewpoint.
inline pcl::PointCloud<pcl::Normal> pcl_normals(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                                                float radius, bool organized,
                                                const Eigen::Vector3f& viewpoint) {
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(kPclThreads);
  ne.setInputCloud(cloud);
  if (organized) {
    ne.setSearchMethod(pcl::make_shared<pcl::search::OrganizedNeighbor<pcl::PointXYZ>>());
  } else {
    ne.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  }
  ne.setRadiusSearch(radius);
  ne.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
  pcl::PointCloud<pcl::Normal> normals;
  ne.compute(normals);
  return normals;
}

inline Eigen::Vector3f pcl_benchmark_normal(const pcl::PointCloud<pcl::Normal>& normals) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& n : normals.points) {
    if (std::isfinite(n.normal_x)) sum += Eigen::Vector3d(n.normal_x, n.normal_y, n.normal_z);
  }
  return (sum / sum.norm()).cast<float>();
}

// The paper's GFH descriptor D (deg^2) with the neighbours of pcl::search::KdTree::radiusSearch:
// the definition of the groovetrace backends (local variance over neighbours j != i, global
// variance over all neighbours, angles in degrees). Tree build included, as in
// NormalEstimation::compute.
inline std::vector<float> pcl_gfh(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud,
                                  const pcl::PointCloud<pcl::Normal>& normals, float radius,
                                  const Eigen::Vector3f& u_b) {
  pcl::search::KdTree<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  const auto n = static_cast<std::int64_t>(cloud->size());
  std::vector<float> out(cloud->size(), NAN);
  auto angle = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    return std::acos(std::clamp(static_cast<double>(a.dot(b)), -1.0, 1.0)) * 57.29577951308232;
  };
#pragma omp parallel num_threads(kPclThreads)
  {
    std::vector<int> idx;
    std::vector<float> d2;
#pragma omp for schedule(dynamic, 1024)
    for (std::int64_t i = 0; i < n; ++i) {
      const auto& p = (*cloud)[i];
      const auto& ni = normals[i];
      if (!pcl::isFinite(p) || !std::isfinite(ni.normal_x)) continue;
      if (tree.radiusSearch(p, radius, idx, d2) <= 0) continue;
      const Eigen::Vector3f n_i(ni.normal_x, ni.normal_y, ni.normal_z);
      double l1 = 0, l2 = 0, g1 = 0, g2 = 0;
      int nl = 0, ng = 0;
      for (int j : idx) {
        const auto& nj = normals[j];
        if (!std::isfinite(nj.normal_x)) continue;
        const Eigen::Vector3f n_j(nj.normal_x, nj.normal_y, nj.normal_z);
        const double beta = angle(u_b, n_j);
        g1 += beta;
        g2 += beta * beta;
        ++ng;
        if (j == i) continue;
        const double theta = angle(n_i, n_j);
        l1 += theta;
        l2 += theta * theta;
        ++nl;
      }
      if (nl == 0) continue;
      const double ml = l1 / nl, mg = g1 / ng;
      const double vl = std::max(0.0, l2 / nl - ml * ml), vg = std::max(0.0, g2 / ng - mg * mg);
      out[i] = static_cast<float>(std::sqrt(vl * vl + vg * vg));
    }
  }
  return out;
}

}  // namespace bench
