// The robust method end to end: candidates -> nodes confirmed by a V fit -> ordered seams ->
// sections every `station` along each seam, fitted twice (the second time across the
// smoothed first result) and smoothed along the seam -> score -> region.

#include <algorithm>
#include <cmath>

#include "robust/context.hpp"

namespace groovetrace {

using robust_detail::Context;

namespace {

// Per input point: its voxel's concavity and plane normal (NaN and invalid where it has none).
void per_point_fields(const Cloud& cloud, const CreaseMap& map, RobustDetection& det) {
  det.concavity.assign(cloud.size(), NAN);
  det.normals.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::int32_t v = map.voxel[i];
    if (v < 0) continue;
    det.concavity[i] = map.concavity[v];
    det.normals.x[i] = map.normals[v].x();
    det.normals.y[i] = map.normals[v].y();
    det.normals.z[i] = map.normals[v].z();
  }
}

// The nodes whose V fit across their own direction passed (a thicker slab: one fit only):
// each fit's root (m), tangent and top normal.
struct ConfirmedNodes {
  std::vector<Eigen::Vector3d> roots, tangents, normals;
};

ConfirmedNodes confirm_nodes(const Context& ctx, const CreaseNodes& nodes) {
  const std::size_t nn = nodes.voxel.size();
  std::vector<GrooveSection> checks(nn);
  const std::int64_t count = static_cast<std::int64_t>(nn);
#pragma omp parallel
  {
    std::vector<std::uint32_t> scratch;
#pragma omp for schedule(dynamic, 8)
    for (std::int64_t k = 0; k < count; ++k) {
      const std::int32_t v = nodes.voxel[k];
      checks[k] = robust_detail::section_at(ctx, ctx.map.points[v].cast<double>(), nodes.tangent[k],
                                            ctx.map.normals[v].cast<double>(), 2 * ctx.params.slab,
                                            scratch);
    }
  }
  ConfirmedNodes out;
  for (const GrooveSection& c : checks) {
    if (!c.ok) continue;
    out.roots.push_back(c.root);
    out.tangents.push_back(c.tangent);
    out.normals.push_back(c.normal);
  }
  return out;
}

// Every path of confirmed nodes (linked within `link`, m) traced as a seam, then the seams
// that are one merged.
std::vector<SeamCandidate> trace_seams(const Context& ctx, const ConfirmedNodes& nodes,
                                       double link) {
  const RobustParams& params = ctx.params;
  const auto min_nodes =
      static_cast<std::size_t>(std::max(5.0, params.min_length / params.cell / 3));
  std::vector<SeamCandidate> seams;
  for (const NodePath& path : order_nodes(nodes.roots, nodes.tangents, link, min_nodes)) {
    std::vector<Eigen::Vector3d> ordered, normals;
    for (int v : path.nodes) {
      ordered.push_back(nodes.roots[v]);
      normals.push_back(nodes.normals[v]);
    }
    seams.push_back(robust_detail::trace_seam(ctx, ordered, normals, path.closed));
  }
  robust_detail::merge_seams(ctx, seams, link);
  return seams;
}

}  // namespace

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
  const CreaseMap map = crease_map(cloud, params, backend);
  per_point_fields(cloud, map, det);
  det.threshold = map.threshold;
  det.noise_sigma = map.sigma;
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
  const ConfirmedNodes confirmed = confirm_nodes(ctx, nodes);
  det.confirmed_nodes = confirmed.roots.size();
  det.seams = trace_seams(ctx, confirmed, 1.5 * params.scale);
  for (SeamCandidate& seam : det.seams) score_seam(seam, params);
  // Accepted seams first, each group best score first.
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
