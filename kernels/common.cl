// Definitions shared by every groovetrace kernel; the host prepends this file to the others.
//
// VW (set by the host with -DVW=n, n in 1, 2, 4, 8, 16) is the number of query points one
// work-item handles, one per vector lane. On a GPU the work-items themselves are the SIMD
// lanes, so VW = 1. A CPU driver such as PoCL runs a work-item's code on one core and does not
// vectorize across work-items once a kernel has data-dependent loops, so the kernels are
// written for vectors of queries: each neighbour candidate is tested against VW queries at
// once, and the per-point finish (eigen-solver, quadric solve, variances) runs lane-parallel.
//
// Arrays in search order carry PAD (set by the host) elements before and after the points,
// so that a vector load starting up to VW - 1 elements outside a row stays inside the buffer;
// kernels advance their pointers by PAD first and index the points from 0.

// The squared distance decides neighbourship; computing it without fused multiply-adds
// rounds exactly as the CPU reference does, so both backends see the same neighbour sets.
#pragma OPENCL FP_CONTRACT OFF

#ifndef VW
#define VW 1
#endif
#ifndef PAD
#define PAD 16
#endif

#define GT_CAT_(a, b) a##b
#define GT_CAT(a, b) GT_CAT_(a, b)

#if VW == 1
typedef float vfloat;
typedef int vint;
#define VLOAD(p) (*(p))
#define VSTORE(v, p) (*(p) = (v))
#define LANES 0
#define ANY(m) ((m) != 0)
#elif VW == 2
typedef float2 vfloat;
typedef int2 vint;
#define VLOAD(p) vload2(0, (p))
#define VSTORE(v, p) vstore2((v), 0, (p))
#define LANES ((int2)(0, 1))
#define ANY(m) any(m)
#elif VW == 4
typedef float4 vfloat;
typedef int4 vint;
#define VLOAD(p) vload4(0, (p))
#define VSTORE(v, p) vstore4((v), 0, (p))
#define LANES ((int4)(0, 1, 2, 3))
#define ANY(m) any(m)
#elif VW == 8
typedef float8 vfloat;
typedef int8 vint;
#define VLOAD(p) vload8(0, (p))
#define VSTORE(v, p) vstore8((v), 0, (p))
#define LANES ((int8)(0, 1, 2, 3, 4, 5, 6, 7))
#define ANY(m) any(m)
#elif VW == 16
typedef float16 vfloat;
typedef int16 vint;
#define VLOAD(p) vload16(0, (p))
#define VSTORE(v, p) vstore16((v), 0, (p))
#define LANES ((int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15))
#define ANY(m) any(m)
#else
#error "VW must be 1, 2, 4, 8 or 16"
#endif

// Lane masks: comparisons give 0/1 on scalars and 0/-1 on vectors; select, & and these
// helpers treat both alike.
#define NOT(m) ((m) == 0)
#define SEL(a, b, m) select((a), (b), (m))  // b where m is set, else a
#define MASKED(v, m) select((vfloat)(0.0f), (v), (m))

#define GT_RAD_TO_DEG 57.295779513082320876f

// acos (radians) for |x| <= 1. PoCL computes the built-in acos lane by lane through a scalar
// routine (16 calls per float16), which cost half the descriptor's time; this one stays in
// vector registers. asin on [0, 1/2] is z + z^3 P(z^2), P a degree-5 polynomial fitted (least
// squares towards minimax, relative error 6e-8 in float) to (asin(z) - z) / z^3; then
// acos(y) = 2 asin(sqrt((1 - y) / 2)) for y >= 1/2 (no cancellation near 1, where the small
// angles between neighbouring normals live), pi/2 - asin(y) below, and acos(-y) = pi - acos(y).
// Relative error about 1e-7; NaN stays NaN.
inline vfloat gt_acos(vfloat x) {
  const vfloat y = fabs(x);
  const vint upper = y >= 0.5f;
  const vfloat z = SEL(y, sqrt(0.5f - 0.5f * y), upper);
  const vfloat w = z * z;
  vfloat p = 0.035947748f;
  p = fma(p, w, (vfloat)(0.015506751f));
  p = fma(p, w, (vfloat)(0.031542789f));
  p = fma(p, w, (vfloat)(0.044545658f));
  p = fma(p, w, (vfloat)(0.075003795f));
  p = fma(p, w, (vfloat)(0.16666661f));
  const vfloat asin_z = fma(z * w, p, z);
  const vfloat r = SEL(1.57079632679489662f - asin_z, 2.0f * asin_z, upper);
  return SEL(r, 3.14159265358979324f - r, x < 0.0f);
}

// exp(-t) for t in [0, 1] (the Gaussian weights exp(-d^2 / h^2) of neighbours within h): a
// degree-7 polynomial fitted (least squares towards minimax) to exp(-t) there, relative error
// 3e-7 in float, without the range reduction of the general exp. Meaningless outside [0, 1].
inline vfloat gt_exp_neg_unit(vfloat t) {
  vfloat p = -0.00011603566f;
  p = fma(p, t, (vfloat)(0.0012551778f));
  p = fma(p, t, (vfloat)(-0.0082127154f));
  p = fma(p, t, (vfloat)(0.041603763f));
  p = fma(p, t, (vfloat)(-0.16664807f));
  p = fma(p, t, (vfloat)(0.49999714f));
  p = fma(p, t, (vfloat)(-0.99999982f));
  return fma(p, t, (vfloat)(1.0f));
}

// cos and sin of angles in [0, pi/3] (the eigen-solver's): Taylor series to the x^10 and x^11
// terms, whose remainders there (4e-9, 3e-10) are below float rounding. The built-ins go lane
// by lane through a scalar argument reduction on PoCL.
inline void gt_cos_sin_third(vfloat x, vfloat* c, vfloat* s) {
  const vfloat w = x * x;
  vfloat pc = -1.0f / 3628800.0f;
  pc = fma(pc, w, (vfloat)(1.0f / 40320.0f));
  pc = fma(pc, w, (vfloat)(-1.0f / 720.0f));
  pc = fma(pc, w, (vfloat)(1.0f / 24.0f));
  pc = fma(pc, w, (vfloat)(-0.5f));
  *c = fma(pc, w, (vfloat)(1.0f));
  vfloat ps = -1.0f / 39916800.0f;
  ps = fma(ps, w, (vfloat)(1.0f / 362880.0f));
  ps = fma(ps, w, (vfloat)(-1.0f / 5040.0f));
  ps = fma(ps, w, (vfloat)(1.0f / 120.0f));
  ps = fma(ps, w, (vfloat)(-1.0f / 6.0f));
  *s = fma(ps * w, x, x);
}

// Smallest and largest lane of an int vector.
inline int hmin_int(vint v) {
#if VW == 1
  return v;
#elif VW == 2
  return min(v.x, v.y);
#elif VW == 4
  const int2 a = min(v.lo, v.hi);
  return min(a.x, a.y);
#elif VW == 8
  const int4 a = min(v.lo, v.hi);
  const int2 b = min(a.lo, a.hi);
  return min(b.x, b.y);
#else
  const int8 a = min(v.lo, v.hi);
  const int4 b = min(a.lo, a.hi);
  const int2 c = min(b.lo, b.hi);
  return min(c.x, c.y);
#endif
}
inline int hmax_int(vint v) {
#if VW == 1
  return v;
#elif VW == 2
  return max(v.x, v.y);
#elif VW == 4
  const int2 a = max(v.lo, v.hi);
  return max(a.x, a.y);
#elif VW == 8
  const int4 a = max(v.lo, v.hi);
  const int2 b = max(a.lo, a.hi);
  return max(b.x, b.y);
#else
  const int8 a = max(v.lo, v.hi);
  const int4 b = max(a.lo, a.hi);
  const int2 c = max(b.lo, b.hi);
  return max(c.x, c.y);
#endif
}

// Largest lane of a float vector.
inline float hmax_float(vfloat v) {
#if VW == 1
  return v;
#elif VW == 2
  return fmax(v.x, v.y);
#elif VW == 4
  const float2 a = fmax(v.lo, v.hi);
  return fmax(a.x, a.y);
#elif VW == 8
  const float4 a = fmax(v.lo, v.hi);
  const float2 b = fmax(a.lo, a.hi);
  return fmax(b.x, b.y);
#else
  const float8 a = fmax(v.lo, v.hi);
  const float4 b = fmax(a.lo, a.hi);
  const float2 c = fmax(b.lo, b.hi);
  return fmax(c.x, c.y);
#endif
}

// Writes the first `lanes` lanes of v to out[first ..]: the last work-item of a row or of
// a cloud may own fewer than VW points, and the rest belong to another work-item.
inline void store_lanes(__global float* out, int first, int lanes, vfloat v) {
  if (lanes == VW) {
    VSTORE(v, out + first);
    return;
  }
  float tmp[VW];
  VSTORE(v, tmp);
  for (int q = 0; q < lanes; ++q) out[first + q] = tmp[q];
}

// Three-vectors with one point per lane.
typedef struct {
  vfloat x, y, z;
} V3;

inline V3 v3(vfloat x, vfloat y, vfloat z) {
  V3 r = {x, y, z};
  return r;
}
inline vfloat v3_dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 v3_cross(V3 a, V3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
inline V3 v3_scale(V3 a, vfloat s) { return v3(a.x * s, a.y * s, a.z * s); }
inline V3 v3_sub(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
inline V3 v3_neg(V3 a) { return v3(-a.x, -a.y, -a.z); }
inline V3 v3_select(V3 a, V3 b, vint m) {  // b where m is set, else a
  return v3(SEL(a.x, b.x, m), SEL(a.y, b.y, m), SEL(a.z, b.z, m));
}
