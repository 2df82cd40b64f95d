/* Ray/primitive and ray/box tests, eight primitives or boxes per call in SoA
 * float8 lanes (PoCL maps each lane onto a SIMD lane; see PERFORMANCE.md).
 * OpenCL C only. */
#ifndef RTCL_SHARED_INTERSECT_H
#define RTCL_SHARED_INTERSECT_H

#include "shared/layouts.h"

#ifdef RTCL_HAS_FP64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif
/* a*d - b*c must negate exactly when the operands swap (shared edges): no
 * contraction into fma. */
#pragma OPENCL FP_CONTRACT OFF

/* Slab test and ±0 direction components: the reciprocal of ±0 is ±inf, so a
 * ray parallel to an axis gets slab distances (b - o) * inf = ±inf, exact for
 * an origin strictly inside or outside the slab. An origin exactly on one of
 * the slab's planes gives 0 * inf = NaN, and fmin/fmax drop a NaN operand
 * (OpenCL C 1.2, 6.12.2): that plane then does not limit the interval, which
 * is exact too, since the ray stays on the closed slab for every t. Clamping
 * |d| to a tiny finite value instead would reject a box whose face the ray
 * lies on (tf = 0 * 1/eps = 0) for one sign of zero but not the other. */
/* Relative widening of each slab interval: covers the rounding of (b - o),
 * of the reciprocal (<= 2.5 ulp in OpenCL C) and of the product, with margin
 * (Ize 2013, "Robust BVH ray traversal"). */
#define RTCL_SLAB_WIDEN (8.0f * FLT_EPSILON)

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
  float dx, dy, dz;
} TraceRay;

/* Returns 0 for a ray that cannot be traced (NaN anywhere, zero direction,
 * tmin > tmax): such a ray reports a miss. */
inline int trace_ray_setup(const Ray r, TraceRay* s) {
  float o[3] = {r.ox, r.oy, r.oz};
  float d[3] = {r.dx, r.dy, r.dz};
  float ad[3] = {fabs(r.dx), fabs(r.dy), fabs(r.dz)};
  int kz = ad[0] > ad[1] ? (ad[0] > ad[2] ? 0 : 2) : (ad[1] > ad[2] ? 1 : 2);
  if (!(ad[kz] > 0.0f) || !(r.tmin <= r.tmax) || isnan(r.ox + r.oy + r.oz + r.dx + r.dy + r.dz))
    return 0;
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
  return 1;
}

/* Lane-wise fmax/fmin for a second operand that is never NaN: b where a is
 * NaN, as fmax/fmin give. One SIMD instruction each (maxps/minps), where
 * fmax/fmin's rules for a NaN in either operand cost a compare and a blend
 * more per call on AVX. */
inline float8 rtcl_fmax8(float8 a, float8 b) { return select(b, a, a > b); }
inline float8 rtcl_fmin8(float8 a, float8 b) { return select(b, a, a < b); }

/* any() for comparison results (lanes 0 or -1), written as an OR reduction
 * tested against zero: one vptest on AVX, where any()'s sign-bit reduction
 * becomes a chain of shuffles. */
inline int rtcl_any8(int8 m) {
  uint8 u = as_uint8(m);
  uint4 o4 = u.lo | u.hi;
  uint2 o2 = o4.lo | o4.hi;
  return (o2.lo | o2.hi) != 0u;
}

/* Slab test of the ray against the node's eight child boxes over
 * [tmin, tmax]. Returns the hit mask (lane = -1 where hit) and the entry
 * distances. Empty slots (lower = +inf, upper = -inf) never hit. The NaN of
 * an origin on the plane of a parallel slab is dropped (see above): each
 * axis's distance enters a chain that starts from tmin or tmax, which are
 * never NaN, so tn and tf are not either. */
inline int8 intersect_boxes8(global const Bvh8Node* node, const TraceRay* s, float tmax, float8* t_entry) {
  global const float8* b = (global const float8*)node->bounds;
  float8 tnx = (b[s->near_x] - s->ox) * s->ix;
  float8 tny = (b[s->near_y] - s->oy) * s->iy;
  float8 tnz = (b[s->near_z] - s->oz) * s->iz;
  float8 tfx = (b[s->far_x] - s->ox) * s->ix;
  float8 tfy = (b[s->far_y] - s->oy) * s->iy;
  float8 tfz = (b[s->far_z] - s->oz) * s->iz;
  float8 tn = rtcl_fmax8(tnx, rtcl_fmax8(tny, rtcl_fmax8(tnz, (float8)(s->tmin))));
  float8 tf = rtcl_fmin8(tfx, rtcl_fmin8(tfy, rtcl_fmin8(tfz, (float8)(tmax))));
  tn = tn - fabs(tn) * RTCL_SLAB_WIDEN;
  tf = tf + fabs(tf) * RTCL_SLAB_WIDEN;
  *t_entry = tn;
  return tn <= tf;
}

/* Closest-hit state of one ray. t_best starts just above tmax, so that a hit
 * at exactly tmax is accepted by the strict t < t_best test. */
typedef struct HitState {
  float t_best, u, v;
  int prim;
} HitState;

inline float rtcl_min8(float8 a) {
  float4 m4 = fmin(a.lo, a.hi);
  float2 m2 = fmin(m4.lo, m4.hi);
  return fmin(m2.lo, m2.hi);
}

/* Index of the first lane of a that equals m (m is one of a's values). */
inline int rtcl_lane_of(float8 a, float m) {
  int8 eq = a == (float8)(m);
  int lanes[8];
  vstore8(eq, 0, lanes);
  for (int i = 0; i < 8; ++i)
    if (lanes[i]) return i;
  return 0;
}

inline float rtcl_lane(float8 a, int i) {
  float lanes[8];
  vstore8(a, 0, lanes);
  return lanes[i];
}

/* Edge function a*d - b*c; where the float result is exactly zero it is
 * recomputed in double (Woop et al. 2013, section 4): a shared edge is then
 * decided identically by both triangles that own it. */
inline float8 rtcl_edge8(float8 a, float8 b, float8 c, float8 d) {
  float8 e = a * d - b * c;
#ifdef RTCL_HAS_FP64
  if (any(e == 0.0f)) {
    /* two double4 halves: double8 is not a native vector type on AVX2 */
    double4 lo = convert_double4(a.lo) * convert_double4(d.lo) - convert_double4(b.lo) * convert_double4(c.lo);
    double4 hi = convert_double4(a.hi) * convert_double4(d.hi) - convert_double4(b.hi) * convert_double4(c.hi);
    float8 ed = (float8)(convert_float4(lo), convert_float4(hi));
    e = select(e, ed, e == 0.0f);
  }
#endif
  return e;
}

/* Watertight test of eight triangles: if one of them is hit in
 * [tmin, h->t_best), records the nearest in h and returns 1. */
inline int intersect_triangles8(global const TriangleBlock* block, const TraceRay* s, HitState* h) {
  global const float* v = &block->v[0][0][0];
  /* v[vertex][axis] rows of 8 lanes: row (3 * vertex + axis) */
  float8 az = vload8(s->kz, v) - s->okz;
  float8 bz = vload8(3 + s->kz, v) - s->okz;
  float8 cz = vload8(6 + s->kz, v) - s->okz;
  float8 ax = vload8(s->kx, v) - s->okx - s->sx * az;
  float8 ay = vload8(s->ky, v) - s->oky - s->sy * az;
  float8 bx = vload8(3 + s->kx, v) - s->okx - s->sx * bz;
  float8 by = vload8(3 + s->ky, v) - s->oky - s->sy * bz;
  float8 cx = vload8(6 + s->kx, v) - s->okx - s->sx * cz;
  float8 cy = vload8(6 + s->ky, v) - s->oky - s->sy * cz;
  float8 U = rtcl_edge8(cx, cy, bx, by);
  float8 V = rtcl_edge8(ax, ay, cx, cy);
  float8 W = rtcl_edge8(bx, by, ax, ay);
  int8 inside = ((U >= 0.0f) & (V >= 0.0f) & (W >= 0.0f)) | ((U <= 0.0f) & (V <= 0.0f) & (W <= 0.0f));
  float8 det = U + V + W;
  float8 T = s->sz * (U * az + V * bz + W * cz);
  float8 t = T / det;
  int8 ok = inside & (det != 0.0f) & (t >= s->tmin) & (t < h->t_best);
  if (!rtcl_any8(ok)) return 0;
  float8 t_ok = select((float8)(INFINITY), t, ok);
  float m = rtcl_min8(t_ok);
  int lane = rtcl_lane_of(t_ok, m);
  float inv_det = 1.0f / rtcl_lane(det, lane);
  h->t_best = m;
  h->u = rtcl_lane(V, lane) * inv_det;
  h->v = rtcl_lane(W, lane) * inv_det;
  h->prim = block->prim[lane];
  return 1;
}

/* Eight spheres (Haines et al., "Precision improvements for ray/sphere
 * intersection", Ray Tracing Gems ch. 7): the discriminant is formed from the
 * distance of the centre to the line, not from b^2 - 4ac. */
inline int intersect_spheres8(global const SphereBlock* block, const TraceRay* s, HitState* h) {
  float8 r = vload8(0, block->r);
  float8 fx = s->ox - vload8(0, block->cx);
  float8 fy = s->oy - vload8(0, block->cy);
  float8 fz = s->oz - vload8(0, block->cz);
  float a = s->dx * s->dx + s->dy * s->dy + s->dz * s->dz;
  float8 b = -(fx * s->dx + fy * s->dy + fz * s->dz); /* = a * t_closest */
  float8 k = b / a;
  float8 lx = fx + k * s->dx, ly = fy + k * s->dy, lz = fz + k * s->dz;
  float8 disc = a * (r * r - (lx * lx + ly * ly + lz * lz));
  int8 real = disc >= 0.0f;
  float8 c = fx * fx + fy * fy + fz * fz - r * r;
  float8 q = b + copysign(sqrt(fmax(disc, 0.0f)), b);
  float8 t0 = c / q, t1 = q / a;
  float8 tn = fmin(t0, t1), tf = fmax(t0, t1);
  int8 ok_n = real & (tn >= s->tmin) & (tn < h->t_best);
  int8 ok_f = real & (tf >= s->tmin) & (tf < h->t_best);
  float8 t = select(select((float8)(INFINITY), tf, ok_f), tn, ok_n);
  int8 ok = ok_n | ok_f;
  if (!rtcl_any8(ok)) return 0;
  float m = rtcl_min8(t);
  int lane = rtcl_lane_of(t, m);
  h->t_best = m;
  h->u = 0.0f;
  h->v = 0.0f;
  h->prim = block->prim[lane];
  return 1;
}

#endif
