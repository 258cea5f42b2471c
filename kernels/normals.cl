// PCA normals: covariance of the neighbours within r, accumulated relative to the query point
// (offsets of a few mm keep float sums exact enough; absolute coordinates would cancel), the
// smallest eigenvector, flipped towards the viewpoint. Fewer than max(3, min_neighbors)
// neighbours (the query included): NaN.

inline void normals_impl(const Search* s, bool organized, __global const float* xs,
                         __global const float* ys, __global const float* zs, float3 vp,
                         int min_neighbors, __global float* nx, __global float* ny,
                         __global float* nz) {
  const Queries Q = queries_of(s, organized, xs, ys, zs, get_global_id(0));
  const float r2 = s->radius * s->radius;
  Moments mo = moments_zero();
  Cand it = cand_begin(s, organized, &Q);
  FOR_EACH_CANDIDATE(s, organized, it, k) {
    const vfloat dx = cand_load(organized, xs, k) - Q.p.x;
    const vfloat dy = cand_load(organized, ys, k) - Q.p.y;
    const vfloat dz = cand_load(organized, zs, k) - Q.p.z;
    moments_add(&mo, dx, dy, dz,
                cand_mask(s, organized, &it, k) & (dx * dx + dy * dy + dz * dz <= r2));
  }
  const vint ok = Q.ok & (mo.n >= (float)max(min_neighbors, 3));
  V3 mean;
  const Sym3 cov = moments_covariance(&mo, &mean);
  V3 n = sym3_smallest_eigenvector(cov);
  const V3 to_view = v3_sub(v3((vfloat)(vp.x), (vfloat)(vp.y), (vfloat)(vp.z)), Q.p);
  n = v3_select(n, v3_neg(n), v3_dot(n, to_view) < 0.0f);
  const vfloat nan = NAN;
  store_lanes(nx, Q.first, Q.lanes, SEL(nan, n.x, ok));
  store_lanes(ny, Q.first, Q.lanes, SEL(nan, n.y, ok));
  store_lanes(nz, Q.first, Q.lanes, SEL(nan, n.z, ok));
}

// Organized frame: all arrays in pixel order (PAD elements before pixel 0).
__kernel void normals_organized(__global const float* xs, __global const float* ys,
                                __global const float* zs, int width, int height, float fx, float fy,
                                float slack, float radius, float vpx, float vpy, float vpz,
                                int min_neighbors, __global float* nx, __global float* ny,
                                __global float* nz) {
  const Search s = {width, height, fx, fy, slack, 0, {0.0f, 0u, 0, 0, 0, 0, 0}, 0, radius};
  if (get_global_id(0) >= (size_t)(height * ((width + VW - 1) / VW))) return;
  normals_impl(&s, true, xs + PAD, ys + PAD, zs + PAD, (float3)(vpx, vpy, vpz), min_neighbors,
               nx + PAD, ny + PAD, nz + PAD);
}

// Unorganized cloud: all arrays in sorted order (PAD elements before point 0).
__kernel void normals_grid(__global const float* xs, __global const float* ys,
                           __global const float* zs, int count, __global const uint* slot_start,
                           GRID_PARAMS, float radius, float vpx, float vpy, float vpz,
                           int min_neighbors, __global float* nx, __global float* ny,
                           __global float* nz) {
  const Search s = {0, 0, 0.0f, 0.0f, 0.0f, slot_start, GRID_FROM_PARAMS, count, radius};
  if (get_global_id(0) >= (size_t)((count + VW - 1) / VW)) return;
  normals_impl(&s, false, xs + PAD, ys + PAD, zs + PAD, (float3)(vpx, vpy, vpz), min_neighbors,
               nx + PAD, ny + PAD, nz + PAD);
}

// Partial sums of the valid normals (the benchmark normal u_b = their normalized sum): each
// work-item sums one contiguous chunk; the host adds the partials in double.
__kernel void sum_normals(__global const float* nx, __global const float* ny,
                          __global const float* nz, int n, int chunk, __global float* partial) {
  const int g = get_global_id(0);
  const int begin = g * chunk;
  if (begin >= n) return;
  nx += PAD;
  ny += PAD;
  nz += PAD;
  float sx = 0.0f, sy = 0.0f, sz = 0.0f;
  for (int k = begin; k < min(begin + chunk, n); ++k) {
    const float x = nx[k];
    if (isfinite(x)) {
      sx += x;
      sy += ny[k];
      sz += nz[k];
    }
  }
  partial[3 * g] = sx;
  partial[3 * g + 1] = sy;
  partial[3 * g + 2] = sz;
}
