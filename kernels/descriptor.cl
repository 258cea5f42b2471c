// The paper's surface-variation descriptor (eqs. 2-6). For point i with a normal:
//   sigma_l = population variance of theta_j = angle(n_i, n_j) over neighbours j != i,
//   sigma_g = population variance of beta_j = angle(u_b, n_j) over neighbours j, i included,
//   D_i = sqrt(sigma_l^2 + sigma_g^2), angles in degrees; only neighbours with a normal count,
//   and D is NaN without any other such neighbour.
// beta depends on j alone, so it is computed once per point (global_angles) instead of once
// per pair. sigma_g comes from sums of beta_j - beta_i, which removes the float cancellation
// of E[beta^2] - E[beta]^2 when all angles are near 50 degrees (theta needs no shift: it is
// the angle to n_i itself, small on smooth surfaces).

// beta[k] = angle(u_b, n_k) in degrees; NaN where the normal is NaN. Arrays in search order;
// each work-item takes VW consecutive points.
__kernel void global_angles(__global const float* nx, __global const float* ny,
                            __global const float* nz, int n, float ubx, float uby, float ubz,
                            __global float* beta) {
  const int first = get_global_id(0) * VW;
  if (first >= n) return;
  const vfloat x = VLOAD(nx + PAD + first), y = VLOAD(ny + PAD + first),
               z = VLOAD(nz + PAD + first);
  // The CPU reference's dot product (Eigen sums x + (y + z)), rounded exactly alike: near
  // parallel normals, one ulp of the cosine is 1e-3 of a small angle.
  const vfloat c = ubx * x + (uby * y + ubz * z);
  const vfloat b = gt_acos(clamp(c, -1.0f, 1.0f)) * GT_RAD_TO_DEG;
  store_lanes(beta + PAD, first, min(VW, n - first), SEL((vfloat)(NAN), b, isfinite(x)));
}

inline void descriptor_impl(const Search* s, bool organized, __global const float* xs,
                            __global const float* ys, __global const float* zs,
                            __global const float* nxs, __global const float* nys,
                            __global const float* nzs, __global const float* betas,
                            __global float* out) {
  const Queries Q = queries_of(s, organized, xs, ys, zs, get_global_id(0));
  const V3 ni = v3(VLOAD(nxs + Q.first), VLOAD(nys + Q.first), VLOAD(nzs + Q.first));
  const vfloat beta_i = VLOAD(betas + Q.first);
  Queries Qn = Q;
  Qn.ok = Q.ok & isfinite(beta_i);
  const float r2 = s->radius * s->radius;
  vfloat nl = 0.0f, l1 = 0.0f, l2 = 0.0f, ng = 0.0f, g1 = 0.0f, g2 = 0.0f;
  Cand it = cand_begin(s, organized, &Qn);
  FOR_EACH_CANDIDATE(s, organized, it, k) {
    const vfloat dx = cand_load(organized, xs, k) - Q.p.x;
    const vfloat dy = cand_load(organized, ys, k) - Q.p.y;
    const vfloat dz = cand_load(organized, zs, k) - Q.p.z;
    const vfloat beta = cand_load(organized, betas, k);
    const vint with_normal =
        cand_mask(s, organized, &it, k) & (dx * dx + dy * dy + dz * dz <= r2) & isfinite(beta);
    // The window's corners and the grid stencil's far cells hold many candidates that are no
    // lane's neighbour: skip their arc cosines.
    if (!ANY(with_normal)) continue;
    const vfloat g = MASKED(beta - beta_i, with_normal);
    ng += MASKED((vfloat)(1.0f), with_normal);
    g1 += g;
    g2 = fma(g, g, g2);
    const vint other = with_normal & NOT(cand_is_self(organized, k, &Q));
    const vfloat c = ni.x * cand_load(organized, nxs, k) +
                     (ni.y * cand_load(organized, nys, k) + ni.z * cand_load(organized, nzs, k));
    const vfloat theta = MASKED(gt_acos(clamp(c, -1.0f, 1.0f)) * GT_RAD_TO_DEG, other);
    nl += MASKED((vfloat)(1.0f), other);
    l1 += theta;
    l2 = fma(theta, theta, l2);
  }
  const vfloat il = 1.0f / fmax(nl, 1.0f), ig = 1.0f / fmax(ng, 1.0f);
  const vfloat ml = l1 * il, mg = g1 * ig;
  const vfloat var_l = fmax(0.0f, l2 * il - ml * ml);
  const vfloat var_g = fmax(0.0f, g2 * ig - mg * mg);
  const vfloat d = sqrt(var_l * var_l + var_g * var_g);
  store_lanes(out, Q.first, Q.lanes, SEL((vfloat)(NAN), d, Qn.ok & (nl > 0.0f)));
}

// Organized frame: all arrays in pixel order (PAD elements before pixel 0).
__kernel void descriptor_organized(__global const float* xs, __global const float* ys,
                                   __global const float* zs, __global const float* nx,
                                   __global const float* ny, __global const float* nz,
                                   __global const float* beta, int width, int height, float fx,
                                   float fy, float slack, float radius, __global float* out) {
  const Search s = {width, height, fx, fy, slack, 0, {0.0f, 0u, 0, 0, 0, 0, 0}, 0, radius};
  if (get_global_id(0) >= (size_t)(height * ((width + VW - 1) / VW))) return;
  descriptor_impl(&s, true, xs + PAD, ys + PAD, zs + PAD, nx + PAD, ny + PAD, nz + PAD, beta + PAD,
                  out + PAD);
}

// Unorganized cloud: all arrays in sorted order (PAD elements before point 0).
__kernel void descriptor_grid(__global const float* xs, __global const float* ys,
                              __global const float* zs, __global const float* nx,
                              __global const float* ny, __global const float* nz,
                              __global const float* beta, int count,
                              __global const uint* slot_start, GRID_PARAMS, float radius,
                              __global float* out) {
  const Search s = {0, 0, 0.0f, 0.0f, 0.0f, slot_start, GRID_FROM_PARAMS, count, radius};
  if (get_global_id(0) >= (size_t)((count + VW - 1) / VW)) return;
  descriptor_impl(&s, false, xs + PAD, ys + PAD, zs + PAD, nx + PAD, ny + PAD, nz + PAD, beta + PAD,
                  out + PAD);
}
