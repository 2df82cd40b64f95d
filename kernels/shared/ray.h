/* Per-ray setup shared by every trace kernel, the compile-time query kind and
 * precision level, and small float8 lane helpers. OpenCL C only.
 *
 * Specialisations (Device::program -D options, never runtime branches):
 *   RTCL_QUERY_CLOSEST / RTCL_QUERY_ANY   closest hit, or some hit (occlusion)
 *   RTCL_PRECISION_FAST / _ROBUST / _EXACT   src/rtcl/accel/precision.hpp */
#ifndef RTCL_SHARED_RAY_H
#define RTCL_SHARED_RAY_H

#include "shared/layouts.h"

#ifdef RTCL_HAS_FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif
/* a*d - b*c must negate exactly when the operands swap (shared edges): no
 * contraction into fma. */
#pragma OPENCL FP_CONTRACT OFF

#ifdef RTCL_QUERY_ANY
#define RTCL_ANY_HIT 1
#else
#define RTCL_ANY_HIT 0
#endif

#if !defined(RTCL_PRECISION_FAST) && !defined(RTCL_PRECISION_EXACT)
#ifndef RTCL_PRECISION_ROBUST
#define RTCL_PRECISION_ROBUST
#endif
#endif
#if defined(RTCL_PRECISION_EXACT) && !defined(RTCL_HAS_FP64)
#error "RTCL_PRECISION_EXACT needs cl_khr_fp64 (the host refuses exact on such a device)"
#endif

/* Per-ray constants for traversal, computed once per ray. */
typedef struct TraceRay {
  float ox, oy, oz, tmin, tmax;
  float ix, iy, iz;          /* reciprocal direction, ±inf for ±0 (slab test) */
  int near_x, near_y, near_z; /* bounds row holding each axis's entry plane */
  int far_x, far_y, far_z;    /* ... and its exit plane */
  /* watertight triangle test (Woop, Benthin, Wald 2013, JCGT 2(1)) */
  int kx, ky, kz;             /* axis permutation, kz = dominant axis */
  float sx, sy, sz;           /* shear constants */
  float okx, oky, okz;        /* origin, permuted */
  float dkx, dky, dkz;        /* direction, permuted */
  float dx, dy, dz;
#ifdef RTCL_PRECISION_EXACT
  double3 shear_exact; /* exact_shear of the permuted direction */
#endif
} TraceRay;

/* Bit tests, immune to -cl-fast-relaxed-math (which lets the compiler
 * assume isnan / isinf are false). */
inline int rtcl_is_finite(float x) { return (as_uint(x) & 0x7f800000u) != 0x7f800000u; }
inline int rtcl_is_nan(float x) { return (as_uint(x) & 0x7fffffffu) > 0x7f800000u; }
/* Lane-wise, -1 where x is not NaN / where x is finite. */
inline int8 rtcl_not_nan8(float8 x) { return (as_uint8(x) & 0x7fffffffu) <= 0x7f800000u; }
inline int8 rtcl_is_finite8(float8 x) { return (as_uint8(x) & 0x7f800000u) != 0x7f800000u; }

/* any() for comparison results (lanes 0 or -1), written as an OR reduction
 * tested against zero: one vptest on AVX, where any()'s sign-bit reduction
 * becomes a chain of shuffles. */
inline int rtcl_any8(int8 m) {
  uint8 u = as_uint8(m);
  uint4 o4 = u.lo | u.hi;
  uint2 o2 = o4.lo | o4.hi;
  return (o2.lo | o2.hi) != 0u;
}

/* The invalid-ray rule (docs/robustness.md): NaN or ±inf in any origin
 * or direction component, a zero direction, a NaN tmin or tmax, or
 * tmin > tmax: the ray reports a miss. For one ray, its fields in eight
 * lanes in Ray's order: the origin's and direction's exponent bits, and
 * tmin's and tmax's magnitude bits, against their limits in one compare
 * (about 10 instructions less per ray than the test of each field by
 * itself, callgrind); then a nonzero direction and tmin <= tmax. */
inline int rtcl_ray_valid(float ox, float oy, float oz, float dx, float dy, float dz, float tmin, float tmax) {
  const int e = 0x7f800000; /* exponent bits: all set for inf and NaN */
  int8 bits = as_int8((float8)(ox, oy, oz, dx, dy, dz, tmin, tmax)) & (int8)(e, e, e, e, e, e, 0x7fffffff, 0x7fffffff);
  int8 beyond = bits >= (int8)(e, e, e, e, e, e, e + 1, e + 1);
  return !rtcl_any8(beyond) & (((as_uint(dx) | as_uint(dy) | as_uint(dz)) & 0x7fffffffu) != 0u) & (tmin <= tmax);
}

/* The same for eight rays in lanes: -1 in the valid lanes. */
inline int8 rtcl_ray_valid8(float8 ox, float8 oy, float8 oz, float8 dx, float8 dy, float8 dz, float8 tmin,
                            float8 tmax) {
  return rtcl_is_finite8(ox) & rtcl_is_finite8(oy) & rtcl_is_finite8(oz) & rtcl_is_finite8(dx) &
         rtcl_is_finite8(dy) & rtcl_is_finite8(dz) &
         (((as_uint8(dx) | as_uint8(dy) | as_uint8(dz)) & 0x7fffffffu) != 0u) & rtcl_not_nan8(tmin) &
         rtcl_not_nan8(tmax) & (tmin <= tmax);
}

/* How trace_ray_setup is compiled: a plain inline function, which PoCL
 * keeps as a call (the Ray passed by value through memory), or always
 * inlined where the kernel defines RTCL_INLINE_RAY_SETUP (the BVH,
 * kernels/accel/bvh.cl, which traces faster so). */
#ifdef RTCL_INLINE_RAY_SETUP
#define RTCL_RAY_SETUP_INLINE inline __attribute__((always_inline))
#else
#define RTCL_RAY_SETUP_INLINE inline
#endif

/* Returns 0 for a ray that cannot be traced (rtcl_ray_valid); such a ray
 * reports a miss. */
RTCL_RAY_SETUP_INLINE int trace_ray_setup(const Ray r, TraceRay* s) {
  if (!rtcl_ray_valid(r.ox, r.oy, r.oz, r.dx, r.dy, r.dz, r.tmin, r.tmax)) return 0;
  float o[3] = {r.ox, r.oy, r.oz};
  float d[3] = {r.dx, r.dy, r.dz};
  float ad[3] = {fabs(r.dx), fabs(r.dy), fabs(r.dz)};
  int kz = ad[0] > ad[1] ? (ad[0] > ad[2] ? 0 : 2) : (ad[1] > ad[2] ? 1 : 2);
  /* a subnormal dominant component under a flush-to-zero device */
  if (!(ad[kz] > 0.0f)) return 0;
  int kx = kz == 2 ? 0 : kz + 1;
  int ky = kx == 2 ? 0 : kx + 1;
  if (d[kz] < 0.0f) { int tmp = kx; kx = ky; ky = tmp; }
  s->ox = r.ox; s->oy = r.oy; s->oz = r.oz;
  s->dx = r.dx; s->dy = r.dy; s->dz = r.dz;
  s->tmin = r.tmin; s->tmax = r.tmax;
  s->ix = 1.0f / r.dx;
  s->iy = 1.0f / r.dy;
  s->iz = 1.0f / r.dz;
  s->near_x = s->ix >= 0.0f ? 0 : 3;
  s->near_y = s->iy >= 0.0f ? 1 : 4;
  s->near_z = s->iz >= 0.0f ? 2 : 5;
  s->far_x = 3 - s->near_x;
  s->far_y = 5 - s->near_y;
  s->far_z = 7 - s->near_z;
  s->kx = kx; s->ky = ky; s->kz = kz;
  s->sx = d[kx] / d[kz];
  s->sy = d[ky] / d[kz];
  s->sz = 1.0f / d[kz];
  s->okx = o[kx]; s->oky = o[ky]; s->okz = o[kz];
  s->dkx = d[kx]; s->dky = d[ky]; s->dkz = d[kz];
#ifdef RTCL_PRECISION_EXACT
  double sz = 1.0 / (double)d[kz]; /* exact_shear (shared/exact.h, which includes this file) */
  s->shear_exact = (double3)((double)d[kx] * sz, (double)d[ky] * sz, sz);
#endif
  return 1;
}

/* Closest-hit state of one ray. t_best starts just above tmax, so that a hit
 * at exactly tmax is accepted by the strict t < t_best test. At the exact
 * level t_exact is the double-precision t of prim (+inf while none) and
 * t_best is t_exact rounded up to float: a bound for culling boxes that
 * never drops a candidate tied with the best. */
typedef struct HitState {
  float t_best, u, v;
  int prim;
#ifdef RTCL_PRECISION_EXACT
  double t_exact;
#endif
} HitState;

/* nextafter(x, INFINITY) for x not NaN, in integer steps: the builtin's
 * general form (any direction, NaN operands) cost the ray setup about 20
 * instructions. +-0 -> the smallest positive subnormal, +inf stays. */
inline float rtcl_next_up(float x) {
  uint b = as_uint(x);
  uint up = x == 0.0f ? 1u : x > 0.0f ? b + 1u : b - 1u;
  return x == INFINITY ? x : as_float(up);
}

inline float8 rtcl_next_up8(float8 x) {
  uint8 b = as_uint8(x);
  uint8 up = select(select(b - 1u, b + 1u, x > 0.0f), (uint8)(1u), x == 0.0f);
  return select(as_float8(up), x, x == INFINITY);
}

inline void hit_state_init(HitState* h, float tmax) {
  h->t_best = rtcl_next_up(tmax);
  h->u = 0.0f;
  h->v = 0.0f;
  h->prim = -1;
#ifdef RTCL_PRECISION_EXACT
  h->t_exact = INFINITY;
#endif
}

/* The t a kernel reports for h: +inf for a miss; at the exact level the
 * double t rounded to nearest. */
inline float hit_state_t(const HitState* h) {
  if (h->prim < 0) return INFINITY;
#ifdef RTCL_PRECISION_EXACT
  return convert_float_rte(h->t_exact);
#else
  return h->t_best;
#endif
}

/* Lane-wise fmax/fmin for a second operand that is never NaN: b where a is
 * NaN, as fmax/fmin give. One SIMD instruction each (maxps/minps), where
 * fmax/fmin's rules for a NaN in either operand cost a compare and a blend
 * more per call on AVX. */
/* A lane-generic helper shared by the single-ray and packet tests, inlined
 * whatever the compiler's heuristics say: called, it would pass its float8
 * aggregates through memory, a visible cost in the packet kernels. */
#define RTCL_LANES_INLINE inline __attribute__((always_inline))

inline float8 rtcl_fmax8(float8 a, float8 b) { return select(b, a, a > b); }
inline float8 rtcl_fmin8(float8 a, float8 b) { return select(b, a, a < b); }

/* Min / max over the lanes by compares, for lanes that are never NaN:
 * fmin / fmax's NaN rules cost a compare and a blend more per step. */
inline float rtcl_min8_ordered(float8 a) {
  float4 m4 = select(a.hi, a.lo, a.lo < a.hi);
  float2 m2 = select(m4.hi, m4.lo, m4.lo < m4.hi);
  return m2.x < m2.y ? m2.x : m2.y;
}

inline float rtcl_max8_ordered(float8 a) {
  float4 m4 = select(a.hi, a.lo, a.lo > a.hi);
  float2 m2 = select(m4.hi, m4.lo, m4.lo > m4.hi);
  return m2.x > m2.y ? m2.x : m2.y;
}

/* The lanes of a comparison result (lanes 0 or -1) as bits 0..7. */
inline int rtcl_lane_bits8(int8 m) {
  int8 bits = m & (int8)(1, 2, 4, 8, 16, 32, 64, 128);
  int4 o4 = bits.lo | bits.hi;
  int2 o2 = o4.lo | o4.hi;
  return o2.lo | o2.hi;
}

inline float rtcl_min8(float8 a) {
  float4 m4 = fmin(a.lo, a.hi);
  float2 m2 = fmin(m4.lo, m4.hi);
  return fmin(m2.lo, m2.hi);
}

inline float rtcl_max8(float8 a) {
  float4 m4 = fmax(a.lo, a.hi);
  float2 m2 = fmax(m4.lo, m4.hi);
  return fmax(m2.lo, m2.hi);
}

/* Index of the first lane of a that equals m (m is one of a's values; 0
 * where none does). A bit per lane, OR-reduced, and the lowest set bit's
 * index: PoCL turns a loop over the stored lanes into a store and a branch
 * per lane, which is slower. */
inline int rtcl_lane_of(float8 a, float m) {
  int mask = rtcl_lane_bits8(a == (float8)(m));
  return mask ? 31 - (int)clz(mask & -mask) : 0;
}

/* Lane i (0..7) of a: the other lanes masked to zero and the eight OR-ed
 * together, in registers (bit for bit the lane). */
inline int rtcl_lane_i(int8 a, int i) {
  int8 m = a & ((int8)(0, 1, 2, 3, 4, 5, 6, 7) == (int8)(i));
  int4 o4 = m.lo | m.hi;
  int2 o2 = o4.lo | o4.hi;
  return o2.lo | o2.hi;
}

inline float rtcl_lane(float8 a, int i) { return as_float(rtcl_lane_i(as_int8(a), i)); }

#endif
