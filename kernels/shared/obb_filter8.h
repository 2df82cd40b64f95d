/* Oriented-box filter of eight BVH children in float8 lanes (the
 * mixed-volume BVH, kernels/accel/bvh.cl with RTCL_BVH_OBB): each lane's
 * OBB (Bvh8Obb, shared/layouts.h) cuts the interval the node's box test
 * found, so a lane is kept when the ray meets its box and its OBB at one t.
 * OpenCL C only.
 *
 * Contract: conservative, as kdop_filter8.h: a lane is rejected only when
 * no t of the box test's [t_entry, t_exit] lies in all three widened OBB
 * slabs.
 *
 * Arithmetic and margin: per lane and axis u_i, a = dot(u_i, o) and
 * b = dot(u_i, d) in float as intersect_slab_volume computes them
 * (kernels/shared/volumes.h), with that header's margin: the host folds
 * RTCL_VOLUME_WIDEN * reach into the stored planes (rounded outward), the
 * ray's part e = RTCL_VOLUME_WIDEN * 2 |o|_inf is subtracted here,
 * (d_near - e - a) and (d_far + e - a) as volumes.h does. The interval is
 * widened by a relative RTCL_VOLUME_T_WIDEN at both ends, at every
 * precision level.
 *
 * ±0: b = ±0 gives a ±inf reciprocal; the planes' distances are then ±inf,
 * or NaN for an origin on a plane of a parallel slab. The distances of one
 * slab are ordered by the reciprocal's sign (select on inv >= 0, NaN
 * carried to whichever end it lands on) and each enters the chain as the
 * first operand of rtcl_fmax8 / rtcl_fmin8, which drop it when NaN (the
 * ray stays in the closed slab). At the fast level (-cl-fast-relaxed-math)
 * a lane with an infinite reciprocal is kept. */
#ifndef RTCL_SHARED_OBB_FILTER8_H
#define RTCL_SHARED_OBB_FILTER8_H

#include "shared/ray.h"

#ifndef RTCL_FILTER_WIDEN
/* RTCL_VOLUME_WIDEN and RTCL_VOLUME_T_WIDEN of kernels/shared/volumes.h. */
#define RTCL_FILTER_WIDEN (16.0f * FLT_EPSILON)
#define RTCL_FILTER_T_WIDEN (8.0f * FLT_EPSILON)
#endif

/* Per-ray constant of the filter: e = RTCL_FILTER_WIDEN * 2 |o|_inf. */
inline float obb_filter_setup(const TraceRay* s) {
  return RTCL_FILTER_WIDEN * 2.0f * fmax(fabs(s->ox), fmax(fabs(s->oy), fabs(s->oz)));
}

/* Lane mask (-1 = keep) of the eight children, given the box test's entry
 * and exit distances of each lane. */
inline int8 obb_filter8(global const Bvh8Obb* v, const TraceRay* s, float e, float8 t_entry, float8 t_exit) {
  global const float8* axis = (global const float8*)v->axis;
  global const float8* d_near = (global const float8*)v->d_near;
  global const float8* d_far = (global const float8*)v->d_far;
  float8 tn = t_entry, tf = t_exit;
  int8 keep = (int8)(0);
  for (int i = 0; i < 3; ++i) {
    float8 ux = axis[3 * i], uy = axis[3 * i + 1], uz = axis[3 * i + 2];
    float8 a = ux * s->ox + uy * s->oy + uz * s->oz;
    float8 b = ux * s->dx + uy * s->dy + uz * s->dz;
    float8 inv = 1.0f / b;
    float8 t1 = (d_near[i] - e - a) * inv;
    float8 t2 = (d_far[i] + e - a) * inv;
    int8 forward = inv >= 0.0f;
    tn = rtcl_fmax8(select(t2, t1, forward), tn);
    tf = rtcl_fmin8(select(t1, t2, forward), tf);
#ifdef RTCL_PRECISION_FAST
    keep |= (as_int8(inv) & 0x7f800000) == 0x7f800000;
#endif
  }
  float8 lo = tn - fabs(tn) * RTCL_FILTER_T_WIDEN;
  float8 hi = tf + fabs(tf) * RTCL_FILTER_T_WIDEN;
  return (lo <= hi) | keep;
}

#endif
