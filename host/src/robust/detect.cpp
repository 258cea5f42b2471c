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

// The nodes whose V fit across their own direction passed (a thicker slab: one fit only) with
// a width (m) in the band [lo, hi) this scale reads, and the corners (fillet, lap): each fit's
// root (m), tangent and top normal.
struct ConfirmedNodes {
  std::vector<Eigen::Vector3d> roots, tangents, normals;
  void add(const GrooveSection& c) {
    roots.push_back(c.root);
    tangents.push_back(c.tangent);
    normals.push_back(c.normal);
  }
};

// The confirmed nodes of each kind: grooves (V, bevel) and corners (fillet, lap). They are
// traced apart: a chain through both kinds (a pipe's V running into the corner along its foot)
// is no one joint.
struct ConfirmedKinds {
  ConfirmedNodes grooves, corners;
};

ConfirmedKinds confirm_nodes(const Context& ctx, const CreaseNodes& nodes, double lo, double hi) {
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
  ConfirmedKinds out;
  for (const GrooveSection& c : checks) {
    if (!c.ok) continue;
    // A corner's width is its weld's (the legs'), not a measure of the scale it fits.
    if (c.corner) {
      out.corners.add(c);
    } else if (c.width >= lo && c.width < hi) {
      out.grooves.add(c);
    }
  }
  return out;
}

// Every path of confirmed nodes (linked within `link`, m) traced as a seam, then the seams
// that are one merged.
std::vector<SeamCandidate> trace_seams(const Context& ctx, const ConfirmedNodes& nodes, double link,
                                       bool corner) {
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
    seams.push_back(robust_detail::trace_seam(ctx, ordered, normals, path.closed, corner));
  }
  robust_detail::merge_seams(ctx, seams, link);
  return seams;
}

// The widest groove a scale's window holds with top surface on both sides, per metre of scale.
constexpr double kWidthPerScale = 1.6;
// The half-window of the smoothing along the seam per metre of scale (see at_scale).
constexpr double kSmoothPerScale = 0.3;

// The parameters of the search at `scale` (m): the crease radius and the section window
// follow it, and so do the voxels (a tenth of it, never finer than `cell`), so that a ball
// holds about as many voxels at every scale. So does the smoothing along the seam beyond
// 20 mm (0.3 scale, never below `smooth`): a joint 60-100 mm wide bends slowly, but
// the root of its 10-15 deg walls moves across by several times the depth noise, and over
// +-6 mm its path wandered by 1-2 mm (docs/method-robust.md, "Smoothing along the seam").
RobustParams at_scale(const RobustParams& params, double scale) {
  RobustParams p = params;
  p.scale = scale;
  p.cell = std::max(params.cell, 0.1 * scale);
  p.smooth = std::max(params.smooth, kSmoothPerScale * scale);
  return p;
}

// One scale's search: candidates and crease nodes, then seams traced from them and scored.
struct ScaleSearch {
  RobustParams params;
  double lo = 0, hi = INFINITY;  // the groove widths it traces (m; see width_bands)
  CreaseMap map;
  CreaseNodes nodes;
  ScaleSearchSummary summary;
  std::vector<SeamCandidate> seams;
};

// The search at `params.scale` on its crease `map`: the candidates above the map's threshold
// and their nodes.
ScaleSearch search_on(const RobustParams& params, CreaseMap map) {
  ScaleSearch out{params, 0, INFINITY, std::move(map), {}, {}, {}};
  ScaleSearchSummary& sum = out.summary;
  sum.scale = params.scale;
  sum.cell = params.cell;
  sum.threshold = out.map.threshold;
  for (float c : out.map.concavity) sum.candidates += (std::isfinite(c) && c > sum.threshold);
  out.nodes = crease_nodes(out.map, params);
  sum.nodes = out.nodes.voxel.size();
  return out;
}

ScaleSearch find_creases(const Cloud& cloud, const RobustParams& params, FeatureBackend& backend) {
  return search_on(params, crease_map(cloud, params, backend));
}

void trace_scale(const Cloud& cloud, ScaleSearch& search) {
  const RobustParams& params = search.params;
  if (search.nodes.voxel.empty()) return;
  const Context ctx{cloud,
                    params,
                    search.map,
                    NeighborGrid(voxel_cloud(search.map), static_cast<float>(params.scale)),
                    BoxBins(cloud, 0.25 * params.scale),
                    2 * params.scale};
  const ConfirmedKinds confirmed = confirm_nodes(ctx, search.nodes, search.lo, search.hi);
  search.summary.confirmed_nodes = confirmed.grooves.roots.size() + confirmed.corners.roots.size();
  search.seams = trace_seams(ctx, confirmed.grooves, 1.5 * params.scale, false);
  for (SeamCandidate& seam : trace_seams(ctx, confirmed.corners, 1.5 * params.scale, true))
    search.seams.push_back(std::move(seam));
  for (SeamCandidate& seam : search.seams) {
    score_seam(seam, params);
    seam.scale = params.scale;
  }
  robust_detail::accept_continuations(search.seams, params.scale);
  for (SeamCandidate& seam : search.seams) {
    if (seam.accepted) robust_detail::extend_to_groove_ends(ctx, seam);
  }
  search.summary.seams = search.seams.size();
}

// The scales finer than `base` trace only the nodes whose fitted width they hold (up to
// kWidthPerScale times the scale): a 10 mm groove is not traced again at 5 mm to be dropped
// as a repeat. The base and coarser scales trace every node: a single node's width is noisy
// (at 640x480 and 0.55 m a 10 mm groove's nodes read 4-18 mm), and a groove the base scale
// does not accept may still be read at a coarser one (a single bevel 8.5 mm wide at 1280x720
// was found at 20 mm only; cut from 20 mm as "narrower than that scale's band", it was lost).
void width_bands(std::vector<ScaleSearch>& searches, double base) {
  for (ScaleSearch& s : searches) {
    if (s.params.scale < base) s.hi = kWidthPerScale * s.params.scale;
  }
}

// A seam fits the scale it was found at when the window holds its groove with top surface to
// spare on both sides (up to kWidthPerScale times the scale wide). Found at a smaller scale,
// its top was fitted on its rims or walls: the tool axis tilts with them, and a wide joint
// reads as a narrower V.
bool fits_scale(const SeamCandidate& seam) { return seam.width <= kWidthPerScale * seam.scale; }

// The score as a reading of the groove at its scale: discounted the more the groove
// overfills the window.
double scale_fit_score(const SeamCandidate& seam) {
  const double over = seam.width / (kWidthPerScale * seam.scale);
  return over > 1 ? seam.score / (over * over) : seam.score;
}

// The order in which one groove's readings at several scales are kept: accepted first, then
// those that fit their scale, the finest of those first (its crease nodes and stations are
// the densest), then the best scale_fit_score.
bool keep_before(const SeamCandidate& a, const SeamCandidate& b) {
  if (a.accepted != b.accepted) return a.accepted;
  if (fits_scale(a) != fits_scale(b)) return fits_scale(a);
  if (fits_scale(a) && a.scale != b.scale) return a.scale < b.scale;
  return scale_fit_score(a) > scale_fit_score(b);
}

// The grooves of every scale, each at one scale: accepted first, then by scale_fit_score.
std::vector<SeamCandidate> one_scale_per_groove(std::vector<SeamCandidate> all) {
  std::stable_sort(all.begin(), all.end(), keep_before);
  std::vector<SeamCandidate> kept =
      robust_detail::drop_duplicate_scales(std::move(all), fits_scale);
  std::stable_sort(kept.begin(), kept.end(), [](const SeamCandidate& a, const SeamCandidate& b) {
    if (a.accepted != b.accepted) return a.accepted;
    return scale_fit_score(a) > scale_fit_score(b);
  });
  return kept;
}

}  // namespace

RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                              const std::function<void(const std::string&)>& lap) {
  const auto cpu = make_cpu_backend();
  return detect_robust(cloud, params, *cpu, lap);
}

namespace {

bool any_accepted(const std::vector<SeamCandidate>& seams) {
  return std::any_of(seams.begin(), seams.end(), [](const SeamCandidate& s) { return s.accepted; });
}

// Stage 1 at every scale: the crease maps and their nodes.
std::vector<ScaleSearch> find_all_creases(const Cloud& cloud, const RobustParams& params,
                                          FeatureBackend& backend) {
  std::vector<double> scales = params.scales;
  if (std::find(scales.begin(), scales.end(), params.scale) == scales.end()) {
    scales.push_back(params.scale);
  }
  std::sort(scales.begin(), scales.end());
  std::vector<ScaleSearch> searches;
  for (double scale : scales)
    searches.push_back(find_creases(cloud, at_scale(params, scale), backend));
  width_bands(searches, params.scale);
  return searches;
}

// The same searches with the candidates' threshold at `k` robust sigmas: the crease maps are
// kept (the measure does not depend on k), the candidates and nodes found again.
void rethreshold(std::vector<ScaleSearch>& searches, double k) {
  for (ScaleSearch& s : searches) {
    RobustParams p = s.params;
    p.threshold_k = k;
    set_threshold(s.map, p);
    const double lo = s.lo, hi = s.hi;
    s = search_on(p, std::move(s.map));
    s.lo = lo;
    s.hi = hi;
  }
}

// Stages 2-3 on every scale's search: the grooves, one scale each, without the per-point
// labels; the fields of the search at `params.scale` (the base) reported.
RobustDetection trace_searches(const Cloud& cloud, std::vector<ScaleSearch>& searches,
                               double base) {
  RobustDetection det;
  std::vector<SeamCandidate> all;
  for (ScaleSearch& search : searches) {
    trace_scale(cloud, search);
    if (search.params.scale == base) {
      per_point_fields(cloud, search.map, det);
      det.threshold_k = search.params.threshold_k;
      det.threshold = search.map.threshold;
      det.noise_sigma = search.map.sigma;
      det.candidates = search.summary.candidates;
      det.nodes = search.summary.nodes;
      det.confirmed_nodes = search.summary.confirmed_nodes;
    }
    det.scales.push_back(search.summary);
    const int first = static_cast<int>(all.size());
    for (SeamCandidate& seam : search.seams) {
      seam.id = static_cast<int>(all.size());
      if (seam.continues >= 0) seam.continues += first;
      all.push_back(std::move(seam));
    }
  }
  robust_detail::reject_corners_on_table(searches.back().map, all);
  det.seams = one_scale_per_groove(std::move(all));
  for (ScaleSearchSummary& sum : det.scales) {
    for (const SeamCandidate& seam : det.seams) sum.kept += (seam.scale == sum.scale);
  }
  return det;
}

}  // namespace

RobustDetection detect_robust(const Cloud& cloud, const RobustParams& params,
                              FeatureBackend& backend,
                              const std::function<void(const std::string&)>& lap) {
  require_in_range(cloud);  // the voxel keys of every scale stay far inside 64 bits
  std::vector<ScaleSearch> searches = find_all_creases(cloud, params, backend);
  if (lap) lap("candidates");
  RobustDetection det = trace_searches(cloud, searches, params.scale);
  if (lap) lap("seams");
  // Nothing accepted: once more with the candidates' threshold lowered, on the same crease
  // maps (docs/method-robust.md, "A second search"). The V fits, not the threshold, decide
  // what a groove is; the threshold only keeps their number down, and at 0.70 m and 640x480 a
  // 10 mm V's root stands 2-3 sigmas above the flats.
  const double retry_k = params.retry_threshold_k;
  if (!any_accepted(det.seams) && retry_k > 0 && retry_k < params.threshold_k) {
    rethreshold(searches, retry_k);
    if (lap) lap("retry_candidates");
    RobustDetection second = trace_searches(cloud, searches, params.scale);
    if (lap) lap("retry_seams");
    det.retried = true;
    if (any_accepted(second.seams)) {
      second.retried = true;
      det = std::move(second);
    }
  }
  det.groove = label_grooves(cloud, det.seams);
  if (lap) lap("region");
  return det;
}

std::vector<bool> exported_seams(const std::vector<SeamCandidate>& seams, int max_seams) {
  std::vector<bool> out(seams.size(), false);
  std::vector<int> ids;
  for (std::size_t k = 0; k < seams.size(); ++k) {
    if (!seams[k].accepted || seams[k].continues >= 0) continue;
    if (static_cast<int>(ids.size()) >= max_seams) break;
    out[k] = true;
    ids.push_back(seams[k].id);
  }
  for (std::size_t k = 0; k < seams.size(); ++k) {
    const SeamCandidate& s = seams[k];
    out[k] = out[k] || (s.accepted && s.continues >= 0 &&
                        std::find(ids.begin(), ids.end(), s.continues) != ids.end());
  }
  return out;
}

}  // namespace groovetrace
