// The robust method end to end: candidates -> nodes confirmed by a V fit -> ordered seams ->
// sections every `station` along each seam, fitted twice (the second time across the
// smoothed first result) and smoothed along the seam -> score -> region.

#include <algorithm>
#include <cmath>

#include "robust/context.hpp"

namespace groovetrace {

using robust_detail::Context;
using robust_detail::merge_seams;
using robust_detail::section_at;
using robust_detail::trace_seam;

RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                              const std::function<void(const std::string&)>& lap) {
  const auto cpu = make_cpu_backend();
  return detect_robust(cloud, params, *cpu, lap);
}

RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                              FeatureBackend& backend,
                              const std::function<void(const std::string&)>& lap) {
  RobustDetection det;
  det.groove.assign(cloud.size(), 0);
  det.concavity.assign(cloud.size(), NAN);
  det.normals.resize(cloud.size());
  const CreaseMap map = crease_map(cloud, params, backend);
  det.threshold = map.threshold;
  det.noise_sigma = map.sigma;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::int32_t v = map.voxel[i];
    if (v < 0) continue;
    det.concavity[i] = map.concavity[v];
    det.normals.x[i] = map.normals[v].x();
    det.normals.y[i] = map.normals[v].y();
    det.normals.z[i] = map.normals[v].z();
  }
  for (float c : map.concavity) det.candidates += (std::isfinite(c) && c > map.threshold) ? 1 : 0;
  const CreaseNodes nodes = crease_nodes(map, params);
  det.nodes = nodes.voxel.size();
  if (lap) lap("candidates");
  if (nodes.voxel.empty()) return det;

  const Context ctx{cloud,
                    params,
                    map,
                    NeighborGrid(voxel_cloud(map), static_cast<float>(params.scale)),
                    BoxBins(cloud, 0.25 * params.scale),
                    2 * params.scale};

  // Confirm each node with a V fit across its own direction (a thicker slab: one fit only).
  const std::size_t nn = nodes.voxel.size();
  std::vector<GrooveSection> checks(nn);
  const std::int64_t count = static_cast<std::int64_t>(nn);
#pragma omp parallel
  {
    std::vector<std::uint32_t> scratch;
#pragma omp for schedule(dynamic, 8)
    for (std::int64_t k = 0; k < count; ++k) {
      const std::int32_t v = nodes.voxel[k];
      checks[k] = section_at(ctx, map.points[v].cast<double>(), nodes.tangent[k],
                             map.normals[v].cast<double>(), 2 * params.slab, scratch);
    }
  }
  std::vector<Eigen::Vector3d> pts, tans, nrms;
  for (std::size_t k = 0; k < nn; ++k) {
    if (!checks[k].ok) continue;
    pts.push_back(checks[k].root);
    tans.push_back(checks[k].tangent);
    nrms.push_back(checks[k].normal);
  }
  det.confirmed_nodes = pts.size();

  const double link = 1.5 * params.scale;
  const auto min_nodes =
      static_cast<std::size_t>(std::max(5.0, params.min_length / params.cell / 3));
  for (const NodePath& path : order_nodes(pts, tans, link, min_nodes)) {
    std::vector<Eigen::Vector3d> ordered, normals;
    for (int v : path.nodes) {
      ordered.push_back(pts[v]);
      normals.push_back(nrms[v]);
    }
    det.seams.push_back(trace_seam(ctx, ordered, normals, path.closed));
  }
  merge_seams(ctx, det.seams, link);
  for (SeamCandidate& seam : det.seams) score_seam(seam, params);
  std::stable_sort(det.seams.begin(), det.seams.end(),
                   [](const SeamCandidate& a, const SeamCandidate& b) {
                     if (a.accepted != b.accepted) return a.accepted;
                     return a.score > b.score;
                   });
  if (lap) lap("seams");
  det.groove = label_grooves(cloud, det.seams);
  if (lap) lap("region");
  return det;
}

}  // namespace groovetrace
