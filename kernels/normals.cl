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
  vfloat cnt = 0.0f, s1x = 0.0f, s1y = 0.0f, s1z = 0.0f;
  vfloat sxx = 0.0f, sxy = 0.0f, sxz = 0.0f, syy = 0.0f, syz = 0.0f, szz = 0.0f;
  Cand it = cand_begin(s, organized, &Q);
  FOR_EACH_CANDIDATE(s, organized, it, k) {
    vfloat dx = cand_load(organized, xs, k) - Q.p.x;
    vfloat dy = cand_load(organized, ys, k) - Q.p.y;
    vfloat dz = cand_load(organized, zs, k) - Q.p.z;
    const vint m = cand_mask(s, organized, &it, k) & (dx * dx + dy * dy + dz * dz <= r2);
    dx = MASKED(dx, m);
    dy = MASKED(dy, m);
    dz = MASKED(dz, m);
    cnt += MASKED((vfloat)(1.0f), m);
    s1x += dx;
    s1y += dy;
    s1z += dz;
    sxx = fma(dx, dx, sxx);
    sxy = fma(dx, dy, sxy);
    sxz = fma(dx, dz, sxz);
    syy = fma(dy, dy, syy);
    syz = fma(dy, dz, syz);
    szz = fma(dz, dz, szz);
  }
  const vint ok = Q.ok & (cnt >= (float)max(min_neighbors, 3));
  const vfloat inv = 1.0f / fmax(cnt, 1.0f);
  const vfloat mx = s1x * inv, my = s1y * inv, mz = s1z * inv;
  const Sym3 cov = {sxx * inv - mx * mx, sxy * inv - mx * my, sxz * inv - mx * mz,
                    syy * inv - my * my, syz * inv - my * mz, szz * inv - mz * mz};
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
