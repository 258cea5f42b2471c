// Moving-least-squares smoothing, the CPU reference's definition: Gaussian weights
// w = exp(-d^2 / h^2) with h = r; the weighted mean and covariance of the neighbours (relative
// to the query point) give a plane; order 1 projects the query onto it, order 2 onto the
// weighted quadric h(a, b) = c0 + c1 a + c2 b + c3 a^2 + c4 a b + c5 b^2 fitted in the plane
// frame (a, b along the plane, h along its normal). Offsets are taken in units of h, so the
// quadric's normal equations stay near 1 in float instead of spanning 1 .. 1e-10 in metres.
// A point with fewer than min_neighbors neighbours is returned unchanged.

// Solves each lane's symmetric 6x6 system m x = b (m: upper triangle row by row, 21 values)
// by LDL^T without pivoting (the weighted normal equations are positive definite). Lanes
// whose pivot is not clearly positive (a degenerate fit) are cleared from *ok.
inline void solve_sym6(const vfloat* m, const vfloat* b, vfloat* x, vint* ok) {
  vfloat a[6][6], l[6][6], d[6];
  int idx = 0;
  for (int i = 0; i < 6; ++i) {
    for (int j = i; j < 6; ++j) {
      a[i][j] = m[idx];
      a[j][i] = m[idx];
      ++idx;
    }
  }
  for (int j = 0; j < 6; ++j) {
    vfloat dj = a[j][j];
    for (int k = 0; k < j; ++k) dj -= l[j][k] * l[j][k] * d[k];
    const vint good = dj > 1e-6f * a[j][j];
    *ok = *ok & good;
    d[j] = SEL((vfloat)(1.0f), dj, good);
    const vfloat inv = 1.0f / d[j];
    for (int i = j + 1; i < 6; ++i) {
      vfloat v = a[i][j];
      for (int k = 0; k < j; ++k) v -= l[i][k] * l[j][k] * d[k];
      l[i][j] = v * inv;
    }
  }
  vfloat y[6];
  for (int i = 0; i < 6; ++i) {
    vfloat v = b[i];
    for (int k = 0; k < i; ++k) v -= l[i][k] * y[k];
    y[i] = v;
  }
  for (int i = 5; i >= 0; --i) {
    vfloat v = y[i] / d[i];
    for (int k = i + 1; k < 6; ++k) v -= l[k][i] * x[k];
    x[i] = v;
  }
}

inline void mls_impl(const Search* s, bool organized, __global const float* xs,
                     __global const float* ys, __global const float* zs, int order,
                     int min_neighbors, __global float* ox, __global float* oy,
                     __global float* oz) {
  const Queries Q = queries_of(s, organized, xs, ys, zs, get_global_id(0));
  const float h = s->radius, inv_h = 1.0f / h, r2 = h * h, inv_h2 = 1.0f / (h * h);

  // Pass 1: weighted mean and covariance of the offsets (units of h).
  vfloat cnt = 0.0f, sw = 0.0f, s1x = 0.0f, s1y = 0.0f, s1z = 0.0f;
  vfloat sxx = 0.0f, sxy = 0.0f, sxz = 0.0f, syy = 0.0f, syz = 0.0f, szz = 0.0f;
  Cand it = cand_begin(s, organized, &Q);
  FOR_EACH_CANDIDATE(s, organized, it, k) {
    const vfloat dx = cand_load(organized, xs, k) - Q.p.x;
    const vfloat dy = cand_load(organized, ys, k) - Q.p.y;
    const vfloat dz = cand_load(organized, zs, k) - Q.p.z;
    const vfloat d2 = dx * dx + dy * dy + dz * dz;
    const vint m = cand_mask(s, organized, &it, k) & (d2 <= r2);
    if (!ANY(m)) continue;  // no lane's neighbour: skip the exponential
    const vfloat w = MASKED(gt_exp_neg_unit(d2 * inv_h2), m);
    const vfloat ux = MASKED(dx * inv_h, m), uy = MASKED(dy * inv_h, m), uz = MASKED(dz * inv_h, m);
    const vfloat wx = w * ux, wy = w * uy, wz = w * uz;
    cnt += MASKED((vfloat)(1.0f), m);
    sw += w;
    s1x += wx;
    s1y += wy;
    s1z += wz;
    sxx = fma(wx, ux, sxx);
    sxy = fma(wx, uy, sxy);
    sxz = fma(wx, uz, sxz);
    syy = fma(wy, uy, syy);
    syz = fma(wy, uz, syz);
    szz = fma(wz, uz, szz);
  }
  const vint fit = Q.ok & (cnt >= (float)min_neighbors) & (sw > 0.0f);
  const vfloat iw = 1.0f / SEL((vfloat)(1.0f), sw, sw > 0.0f);
  const V3 mean = v3(s1x * iw, s1y * iw, s1z * iw);
  const Sym3 cov = {sxx * iw - mean.x * mean.x, sxy * iw - mean.x * mean.y,
                    sxz * iw - mean.x * mean.z, syy * iw - mean.y * mean.y,
                    syz * iw - mean.y * mean.z, szz * iw - mean.z * mean.z};
  const V3 n = sym3_smallest_eigenvector(cov);
  // The query relative to the weighted mean; its height above the plane is removed.
  const V3 qm = v3_neg(mean);
  const vfloat height = v3_dot(qm, n);
  vfloat fitted = 0.0f;

  vint quadric = fit & (cnt >= 6.0f);
  if (order >= 2 && ANY(quadric)) {
    // Pass 2: weighted moments of the plane coordinates (a, b) up to degree 4, and of the
    // height times each monomial: the normal equations of the quadric fit.
    V3 u, v;
    sym3_complement(n, &u, &v);
    vfloat m0 = 0.0f, ma = 0.0f, mb = 0.0f, maa = 0.0f, mab = 0.0f, mbb = 0.0f;
    vfloat maaa = 0.0f, maab = 0.0f, mabb = 0.0f, mbbb = 0.0f;
    vfloat maaaa = 0.0f, maaab = 0.0f, maabb = 0.0f, mabbb = 0.0f, mbbbb = 0.0f;
    vfloat mh = 0.0f, mha = 0.0f, mhb = 0.0f, mhaa = 0.0f, mhab = 0.0f, mhbb = 0.0f;
    Queries Q2 = Q;
    Q2.ok = quadric;
    // Plane coordinates straight from the offsets in metres: a = d . u / h - mean . u.
    const V3 uh = v3_scale(u, (vfloat)(inv_h)), vh = v3_scale(v, (vfloat)(inv_h));
    const V3 nh = v3_scale(n, (vfloat)(inv_h));
    const vfloat ca = v3_dot(mean, u), cb = v3_dot(mean, v), cn = v3_dot(mean, n);
    it = cand_begin(s, organized, &Q2);
    FOR_EACH_CANDIDATE(s, organized, it, k) {
      const vfloat dx = cand_load(organized, xs, k) - Q.p.x;
      const vfloat dy = cand_load(organized, ys, k) - Q.p.y;
      const vfloat dz = cand_load(organized, zs, k) - Q.p.z;
      const vfloat d2 = dx * dx + dy * dy + dz * dz;
      const vint m = cand_mask(s, organized, &it, k) & (d2 <= r2);
      if (!ANY(m)) continue;
      const vfloat w = MASKED(gt_exp_neg_unit(d2 * inv_h2), m);
      const vfloat a = MASKED(fma(dx, uh.x, fma(dy, uh.y, fma(dz, uh.z, -ca))), m);
      const vfloat b = MASKED(fma(dx, vh.x, fma(dy, vh.y, fma(dz, vh.z, -cb))), m);
      const vfloat hh = MASKED(fma(dx, nh.x, fma(dy, nh.y, fma(dz, nh.z, -cn))), m);
      const vfloat aa = a * a, ab = a * b, bb = b * b;
      const vfloat wa = w * a, wb = w * b, waa = w * aa, wab = w * ab, wbb = w * bb, wh = w * hh;
      m0 += w;
      ma += wa;
      mb += wb;
      maa += waa;
      mab += wab;
      mbb += wbb;
      maaa = fma(waa, a, maaa);
      maab = fma(waa, b, maab);
      mabb = fma(wab, b, mabb);
      mbbb = fma(wbb, b, mbbb);
      maaaa = fma(waa, aa, maaaa);
      maaab = fma(waa, ab, maaab);
      maabb = fma(waa, bb, maabb);
      mabbb = fma(wab, bb, mabbb);
      mbbbb = fma(wbb, bb, mbbbb);
      mh += wh;
      mha = fma(wh, a, mha);
      mhb = fma(wh, b, mhb);
      mhaa = fma(wh, aa, mhaa);
      mhab = fma(wh, ab, mhab);
      mhbb = fma(wh, bb, mhbb);
    }
    // Rows and columns follow the monomials (1, a, b, a^2, ab, b^2).
    const vfloat ata[21] = {m0,  ma,   mb,   maa,  mab,   mbb,   maa,   mab,   maaa,  maab, mabb,
                            mbb, maab, mabb, mbbb, maaaa, maaab, maabb, maabb, mabbb, mbbbb};
    const vfloat atb[6] = {mh, mha, mhb, mhaa, mhab, mhbb};
    vfloat c[6];
    // Lanes that skipped pass 2 have an all-zero system; give them the identity instead.
    vfloat sys[21];
    for (int k = 0; k < 21; ++k) sys[k] = ata[k];
    sys[0] = SEL((vfloat)(1.0f), sys[0], quadric);
    sys[6] = SEL((vfloat)(1.0f), sys[6], quadric);
    sys[11] = SEL((vfloat)(1.0f), sys[11], quadric);
    sys[15] = SEL((vfloat)(1.0f), sys[15], quadric);
    sys[18] = SEL((vfloat)(1.0f), sys[18], quadric);
    sys[20] = SEL((vfloat)(1.0f), sys[20], quadric);
    solve_sym6(sys, atb, c, &quadric);
    const vfloat qa = v3_dot(qm, u), qb = v3_dot(qm, v);
    const vfloat f =
        c[0] + c[1] * qa + c[2] * qb + c[3] * qa * qa + c[4] * qa * qb + c[5] * qb * qb;
    fitted = SEL((vfloat)(0.0f), f, quadric & isfinite(f));
  }
  const vfloat shift = (height - fitted) * h;
  const V3 moved = v3_sub(Q.p, v3_scale(n, shift));
  store_lanes(ox, Q.first, Q.lanes, SEL(Q.p.x, moved.x, fit));
  store_lanes(oy, Q.first, Q.lanes, SEL(Q.p.y, moved.y, fit));
  store_lanes(oz, Q.first, Q.lanes, SEL(Q.p.z, moved.z, fit));
}

// Organized frame: all arrays in pixel order (PAD elements before pixel 0); invalid pixels
// are copied.
__kernel void mls_organized(__global const float* xs, __global const float* ys,
                            __global const float* zs, int width, int height, float fx, float fy,
                            float slack, float radius, int order, int min_neighbors,
                            __global float* ox, __global float* oy, __global float* oz) {
  const Search s = {width, height, fx, fy, slack, 0, {0.0f, 0u, 0, 0, 0, 0, 0}, 0, radius};
  if (get_global_id(0) >= (size_t)(height * ((width + VW - 1) / VW))) return;
  mls_impl(&s, true, xs + PAD, ys + PAD, zs + PAD, order, min_neighbors, ox + PAD, oy + PAD,
           oz + PAD);
}

// Unorganized cloud: all arrays in sorted order (PAD elements before point 0).
__kernel void mls_grid(__global const float* xs, __global const float* ys, __global const float* zs,
                       int count, __global const uint* slot_start, GRID_PARAMS, float radius,
                       int order, int min_neighbors, __global float* ox, __global float* oy,
                       __global float* oz) {
  const Search s = {0, 0, 0.0f, 0.0f, 0.0f, slot_start, GRID_FROM_PARAMS, count, radius};
  if (get_global_id(0) >= (size_t)((count + VW - 1) / VW)) return;
  mls_impl(&s, false, xs + PAD, ys + PAD, zs + PAD, order, min_neighbors, ox + PAD, oy + PAD,
           oz + PAD);
}
