// The robust method's crease measure (host/src/backend/cpu/crease.cpp is the reference): per point,
// the plane normal of the points within r, and its concavity = the `quantile` of the
// neighbours' heights along that normal (the upper envelope) minus the point's own height,
// averaged over the neighbours within own_r. Unorganized clouds only (the robust method runs
// on voxel centroids): arrays in grid-sorted order.
//
// A quantile needs the heights sorted, and a ball holds hundreds of points: no per-lane list
// fits a SIMD lane or a GPU thread. Instead the walk is repeated. The first walk gives the
// plane (covariance relative to the query point) and the mean mu and spread sd of the heights;
// the quantile lies in [mu - 0.63 sd, mu + 2 sd] (Cantelli's inequality on the ball's own
// distribution, for >= 10 points), which the bracket widens a little. Each further walk counts
// the heights at or below CREASE_SPLIT + 1 evenly spaced thresholds across the bracket and keeps
// the sub-interval that holds the k-th smallest height, until every lane's bracket is at most
// `tolerance` wide (m; 3-4 walks at 10 mm and 2 um) or CREASE_MAX_PASSES walks have run. A
// bracket that misses (float rounding) falls back to the whole range [-r, r] on that side. The
// result is the final bracket's midpoint.

#ifndef CREASE_SPLIT
#define CREASE_SPLIT 8
#endif
#ifndef CREASE_MAX_PASSES
#define CREASE_MAX_PASSES 12
#endif

__kernel void crease_grid(__global const float* xs, __global const float* ys,
                          __global const float* zs, int count, __global const uint* slot_start,
                          GRID_PARAMS, float radius, float own_radius, float quantile,
                          int min_neighbors, float tolerance, float vpx, float vpy, float vpz,
                          __global float* nx, __global float* ny, __global float* nz,
                          __global float* concavity) {
  const Search s = {0, 0, 0.0f, 0.0f, 0.0f, slot_start, GRID_FROM_PARAMS, count, radius};
  if (get_global_id(0) >= (size_t)((count + VW - 1) / VW)) return;
  xs += PAD;
  ys += PAD;
  zs += PAD;
  const Queries Q = queries_of(&s, false, xs, ys, zs, get_global_id(0));
  const float r2 = radius * radius, own2 = own_radius * own_radius;

  // Walk 1: the plane and the own ball.
  Moments mo = moments_zero();
  vfloat own_cnt = 0.0f, ox = 0.0f, oy = 0.0f, oz = 0.0f;
  Cand it = cand_begin(&s, false, &Q);
  FOR_EACH_CANDIDATE(&s, false, it, k) {
    const vfloat dx = cand_load(false, xs, k) - Q.p.x;
    const vfloat dy = cand_load(false, ys, k) - Q.p.y;
    const vfloat dz = cand_load(false, zs, k) - Q.p.z;
    const vfloat d2 = dx * dx + dy * dy + dz * dz;
    const vint m = cand_mask(&s, false, &it, k) & (d2 <= r2);
    moments_add(&mo, dx, dy, dz, m);
    const vint own = m & (d2 <= own2);
    own_cnt += MASKED((vfloat)(1.0f), own);
    ox += MASKED(dx, own);
    oy += MASKED(dy, own);
    oz += MASKED(dz, own);
  }
  const vfloat cnt = mo.n;
  const vint ok = Q.ok & (cnt >= (float)max(min_neighbors, 3));
  V3 mean;
  const Sym3 cov = moments_covariance(&mo, &mean);
  V3 n = sym3_smallest_eigenvector(cov);
  const V3 to_view = v3_sub(v3((vfloat)(vpx), (vfloat)(vpy), (vfloat)(vpz)), Q.p);
  n = v3_select(n, v3_neg(n), v3_dot(n, to_view) < 0.0f);
  const vfloat own_height = v3_dot(n, v3(ox, oy, oz)) / fmax(own_cnt, 1.0f);

  // The bracket. var = n' C n, the spread of the heights about their mean.
  const vfloat mu = v3_dot(n, mean);
  const vfloat sd = sqrt(fmax(v3_dot(n, sym3_mul(&cov, n)), 0.0f));
  const vfloat slack = 1e-6f * radius;
  vfloat lo = mu - 0.7f * sd - slack, hi = mu + 2.2f * sd + slack;
  // Heights at or below the answer number more than k; at or below lo, at most k.
  const vfloat kth = floor(quantile * (cnt - 1.0f));
  const vfloat reach = radius * (1.0f + 1e-6f);
  for (int pass = 0; pass < CREASE_MAX_PASSES && ANY(ok & (hi - lo > tolerance)); ++pass) {
    const vfloat step = (hi - lo) * (1.0f / CREASE_SPLIT);
    // below[j]: heights <= at[j] = lo + j * step, j = 0 .. CREASE_SPLIT. The next bracket is
    // made of these same thresholds, so that it holds the answer whatever their rounding.
    vfloat at[CREASE_SPLIT + 1], below[CREASE_SPLIT + 1];
    for (int j = 0; j <= CREASE_SPLIT; ++j) {
      at[j] = fma((vfloat)(j), step, lo);
      below[j] = 0.0f;
    }
    it = cand_begin(&s, false, &Q);
    FOR_EACH_CANDIDATE(&s, false, it, k) {
      const vfloat dx = cand_load(false, xs, k) - Q.p.x;
      const vfloat dy = cand_load(false, ys, k) - Q.p.y;
      const vfloat dz = cand_load(false, zs, k) - Q.p.z;
      const vint m = cand_mask(&s, false, &it, k) & (dx * dx + dy * dy + dz * dz <= r2);
      // Outside the ball: above every threshold.
      const vfloat h = SEL((vfloat)(INFINITY), n.x * dx + n.y * dy + n.z * dz, m);
      for (int j = 0; j <= CREASE_SPLIT; ++j) {
        below[j] += SEL((vfloat)(0.0f), (vfloat)(1.0f), h <= at[j]);
      }
    }
    // The answer lies in (at[j - 1], at[j]] for the first j with below[j] > k; none: above hi;
    // j = 0: at or below lo.
    vfloat new_lo = hi, new_hi = reach;
    for (int j = CREASE_SPLIT; j >= 0; --j) {
      const vint in = below[j] > kth;
      new_hi = SEL(new_hi, at[j], in);
      new_lo = SEL(new_lo, j > 0 ? at[j - 1] : -reach, in);
    }
    lo = new_lo;
    hi = new_hi;
  }
  const vfloat c = 0.5f * (lo + hi) - own_height;
  const vfloat nan = NAN;
  store_lanes(nx + PAD, Q.first, Q.lanes, SEL(nan, n.x, ok));
  store_lanes(ny + PAD, Q.first, Q.lanes, SEL(nan, n.y, ok));
  store_lanes(nz + PAD, Q.first, Q.lanes, SEL(nan, n.z, ok));
  store_lanes(concavity + PAD, Q.first, Q.lanes, SEL(nan, c, ok));
}
