// Closed-form eigen-decomposition of symmetric 3x3 matrices in float, one matrix per lane:
// the arithmetic of host/src/eigen3.cpp (trigonometric eigenvalues, the eigenvector of the best
// separated eigenvalue first, the other two from the 2x2 problem in its complement, the
// Rayleigh quotients deciding at the end), with its branches turned into lane selects.

typedef struct {
  vfloat a00, a01, a02, a11, a12, a22;
} Sym3;

// Sums over a query's neighbours of their offsets d from it (m): count, sum d and sum d d',
// for a plane fit. Offsets from the query keep the float sums exact enough where absolute
// coordinates would cancel.
typedef struct {
  vfloat n, x, y, z, xx, xy, xz, yy, yz, zz;
} Moments;

inline Moments moments_zero(void) {
  const Moments m = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  return m;
}

// Adds offset d in the lanes of `in`.
inline void moments_add(Moments* m, vfloat dx, vfloat dy, vfloat dz, vint in) {
  dx = MASKED(dx, in);
  dy = MASKED(dy, in);
  dz = MASKED(dz, in);
  m->n += MASKED((vfloat)(1.0f), in);
  m->x += dx;
  m->y += dy;
  m->z += dz;
  m->xx = fma(dx, dx, m->xx);
  m->xy = fma(dx, dy, m->xy);
  m->xz = fma(dx, dz, m->xz);
  m->yy = fma(dy, dy, m->yy);
  m->yz = fma(dy, dz, m->yz);
  m->zz = fma(dz, dz, m->zz);
}

// The covariance about the mean offset (population), and the mean itself.
inline Sym3 moments_covariance(const Moments* m, V3* mean) {
  const vfloat inv = 1.0f / fmax(m->n, 1.0f);
  *mean = v3(m->x * inv, m->y * inv, m->z * inv);
  const Sym3 c = {m->xx * inv - mean->x * mean->x, m->xy * inv - mean->x * mean->y,
                  m->xz * inv - mean->x * mean->z, m->yy * inv - mean->y * mean->y,
                  m->yz * inv - mean->y * mean->z, m->zz * inv - mean->z * mean->z};
  return c;
}

inline V3 sym3_mul(const Sym3* a, V3 v) {
  return v3(a->a00 * v.x + a->a01 * v.y + a->a02 * v.z, a->a01 * v.x + a->a11 * v.y + a->a12 * v.z,
            a->a02 * v.x + a->a12 * v.y + a->a22 * v.z);
}

// Unit vector spanning the null space of (A - lambda I) when that space is 1-D: the longest
// cross product of two rows is perpendicular to both.
inline V3 sym3_null_vector(const Sym3* a, vfloat lambda) {
  const V3 r0 = v3(a->a00 - lambda, a->a01, a->a02);
  const V3 r1 = v3(a->a01, a->a11 - lambda, a->a12);
  const V3 r2 = v3(a->a02, a->a12, a->a22 - lambda);
  const V3 c01 = v3_cross(r0, r1), c02 = v3_cross(r0, r2), c12 = v3_cross(r1, r2);
  const vfloat d01 = v3_dot(c01, c01), d02 = v3_dot(c02, c02), d12 = v3_dot(c12, c12);
  const vint use01 = (d01 >= d02) & (d01 >= d12) & (d01 > 0.0f);
  const vint use02 = NOT(use01) & (d02 >= d12) & (d02 > 0.0f);
  const vint use12 = NOT(use01) & NOT(use02) & (d12 > 0.0f);
  V3 v = v3((vfloat)(1.0f), (vfloat)(0.0f), (vfloat)(0.0f));
  v = v3_select(v, v3_scale(c12, rsqrt(d12)), use12);
  v = v3_select(v, v3_scale(c02, rsqrt(d02)), use02);
  return v3_select(v, v3_scale(c01, rsqrt(d01)), use01);
}

// An orthonormal pair (u, v) perpendicular to the unit vector w.
inline void sym3_complement(V3 w, V3* u, V3* v) {
  const V3 ux = v3_scale(v3(-w.z, (vfloat)(0.0f), w.x), rsqrt(w.x * w.x + w.z * w.z));
  const V3 uy = v3_scale(v3((vfloat)(0.0f), w.z, -w.y), rsqrt(w.y * w.y + w.z * w.z));
  *u = v3_select(uy, ux, fabs(w.x) > fabs(w.y));
  *v = v3_cross(w, *u);
}

// Eigenvector of lambda inside the plane perpendicular to evec0: (A - lambda I) reduced to
// that plane is the 2x2 [m00 m01; m01 m11], and its null direction is the answer. The row
// with the larger diagonal is used, scaled by its largest entry (the host's pivoting; the
// sign of an eigenvector carries no meaning).
inline V3 sym3_second_vector(const Sym3* a, V3 evec0, vfloat lambda) {
  V3 u, v;
  sym3_complement(evec0, &u, &v);
  const V3 au = sym3_mul(a, u), av = sym3_mul(a, v);
  const vfloat m00 = v3_dot(u, au) - lambda, m01 = v3_dot(u, av), m11 = v3_dot(v, av) - lambda;
  const vint row0 = fabs(m00) >= fabs(m11);
  // The null direction of row (m00, m01) is (m01, -m00), of row (m01, m11) it is (m11, -m01),
  // in (u, v) coordinates.
  const vfloat pu = SEL(m11, m01, row0), pv = SEL(m01, m00, row0);
  const vfloat mx = fmax(fabs(pu), fabs(pv));
  const vint zero = mx == 0.0f;
  const vfloat inv = 1.0f / SEL(mx, (vfloat)(1.0f), zero);
  const vfloat cu = pu * inv, cv = pv * inv;
  const V3 r = v3_sub(v3_scale(u, cu), v3_scale(v, cv));
  return v3_select(v3_scale(r, rsqrt(v3_dot(r, r))), u, zero);
}

// Unit eigenvector of the smallest eigenvalue of each lane's symmetric matrix (a covariance:
// its plane normal). A zero or non-finite matrix, or a multiple of the identity, gives
// (1, 0, 0) as on the host.
inline V3 sym3_smallest_eigenvector(Sym3 m) {
  const vfloat scale = fmax(fmax(fmax(fabs(m.a00), fabs(m.a01)), fmax(fabs(m.a02), fabs(m.a11))),
                            fmax(fabs(m.a12), fabs(m.a22)));
  const vint degenerate =
      NOT(isfinite(m.a00 + m.a01 + m.a02 + m.a11 + m.a12 + m.a22)) | (scale == 0.0f);
  // Scaling keeps the cubic's coefficients near 1 whatever the units of the covariance.
  const vfloat s = 1.0f / SEL(scale, (vfloat)(1.0f), degenerate);
  Sym3 a = {m.a00 * s, m.a01 * s, m.a02 * s, m.a11 * s, m.a12 * s, m.a22 * s};
  const vfloat q = (a.a00 + a.a11 + a.a22) / 3.0f;
  const vfloat p1 = a.a01 * a.a01 + a.a02 * a.a02 + a.a12 * a.a12;
  const vfloat p2 =
      (a.a00 - q) * (a.a00 - q) + (a.a11 - q) * (a.a11 - q) + (a.a22 - q) * (a.a22 - q) + 2.0f * p1;
  const vfloat p = sqrt(p2 / 6.0f);
  // A multiple of the identity (to float precision): every basis is an eigenbasis.
  const vint isotropic = p < 1e-7f;
  const vfloat ip = 1.0f / SEL(p, (vfloat)(1.0f), isotropic);
  const vfloat b00 = (a.a00 - q) * ip, b11 = (a.a11 - q) * ip, b22 = (a.a22 - q) * ip;
  const vfloat b01 = a.a01 * ip, b02 = a.a02 * ip, b12 = a.a12 * ip;
  const vfloat det =
      b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02);
  const vfloat phi = gt_acos(clamp(det * 0.5f, -1.0f, 1.0f)) / 3.0f;  // in [0, pi/3]
  vfloat cos_phi, sin_phi;
  gt_cos_sin_third(phi, &cos_phi, &sin_phi);
  // cos(phi + 2 pi / 3) = -cos(phi) / 2 - sin(phi) sqrt(3) / 2
  const vfloat l_max = q + 2.0f * p * cos_phi;
  const vfloat l_min = q + 2.0f * p * (-0.5f * cos_phi - 0.86602540378443865f * sin_phi);
  const vfloat l_mid = 3.0f * q - l_max - l_min;

  // Start from the eigenvalue farthest from the other two: its null space is surely 1-D.
  const vint far_is_max = (l_max - l_mid) >= (l_mid - l_min);
  const V3 v_far = sym3_null_vector(&a, SEL(l_min, l_max, far_is_max));
  const V3 v_mid = sym3_second_vector(&a, v_far, l_mid);
  const V3 v_other = v3_cross(v_far, v_mid);
  const V3 v_min = v3_select(v_far, v_other, far_is_max);
  const V3 v_max = v3_select(v_other, v_far, far_is_max);
  // acos loses half the digits where two eigenvalues meet; the Rayleigh quotients of the
  // (accurate) vectors decide which one belongs to the smallest eigenvalue.
  const vfloat r_min = v3_dot(v_min, sym3_mul(&a, v_min));
  const vfloat r_mid = v3_dot(v_mid, sym3_mul(&a, v_mid));
  const vfloat r_max = v3_dot(v_max, sym3_mul(&a, v_max));
  const vint take_mid = r_mid < r_min;
  V3 best = v3_select(v_min, v_mid, take_mid);
  const vfloat r_best = SEL(r_min, r_mid, take_mid);
  best = v3_select(best, v_max, r_max < r_best);
  return v3_select(best, v3((vfloat)(1.0f), (vfloat)(0.0f), (vfloat)(0.0f)),
                   degenerate | isotropic);
}
