/* k-DOP filter of eight BVH children in float8 lanes (the mixed-volume
 * BVH, kernels/accel/bvh.cl with RTCL_BVH_KDOP): the four body-diagonal
 * slabs of Bvh8Kdop (shared/layouts.h) cut the interval the node's box test
 * found, so a lane is kept when the ray meets box and diagonal slabs at one
 * t, the 14-DOP. OpenCL C only.
 *
 * Contract: conservative. A lane is rejected only when no t of the box
 * test's [t_entry, t_exit] lies in every widened diagonal slab, so a ray
 * that meets the child's contents within [tmin, best t] is kept.
 *
 * Arithmetic and margin: per ray and diagonal n_j, a_j = dot(n_j, o) and
 * b_j = dot(n_j, d) in float as intersect_slab_volume computes them
 * (kernels/shared/volumes.h), whose margin applies: each slab widened by
 * RTCL_VOLUME_WIDEN * (2 |o|_inf + reach). The host folds the
 * ray-independent part RTCL_VOLUME_WIDEN * reach into the stored planes
 * (rounded outward); the ray's part e is folded here into the shifted
 * origins a_j + e (entry plane d_near, when b_j >= +0) or a_j - e (the
 * other), one rounding where volumes.h has one subtraction: the same
 * error budget. The final interval is widened by a relative
 * RTCL_VOLUME_T_WIDEN on both ends (covering the reciprocal and the box
 * test's own rounding at the fast level, where box.h does not widen). The
 * filter widens at every precision level.
 *
 * ±0: the entry/exit plane of each diagonal is picked by the sign of
 * 1 / b_j (±inf for b_j = ±0), as box.h picks rows, so a plane distance is
 * NaN only for an origin on the plane of a parallel slab; rtcl_fmax8 /
 * rtcl_fmin8 drop a NaN first operand, so that plane does not limit the
 * interval (the ray stays in the closed slab). At the fast level
 * (-cl-fast-relaxed-math, no infinities assumed) a ray with an infinite
 * reciprocal keeps every lane. */
#ifndef RTCL_SHARED_KDOP_FILTER8_H
#define RTCL_SHARED_KDOP_FILTER8_H

#include "shared/ray.h"

#ifndef RTCL_FILTER_WIDEN
/* RTCL_VOLUME_WIDEN and RTCL_VOLUME_T_WIDEN of kernels/shared/volumes.h
 * (same values; that header carries host-side definitions). */
#define RTCL_FILTER_WIDEN (16.0f * FLT_EPSILON)
#define RTCL_FILTER_T_WIDEN (8.0f * FLT_EPSILON)
#endif

/* Per-ray constants of the filter. */
typedef struct KdopFilterRay {
  float inv[RTCL_KDOP_FILTER_SLABS];     /* 1 / b_j */
  float entry_o[RTCL_KDOP_FILTER_SLABS]; /* a_j + e or a_j - e, the shifted origin of the entry plane */
  float exit_o[RTCL_KDOP_FILTER_SLABS];  /* ... and of the exit plane */
  int entry_row[RTCL_KDOP_FILTER_SLABS]; /* j (d_near) when 1 / b_j >= 0, else j + 4 (d_far) */
  int keep_all;                          /* fast level, an infinite reciprocal */
} KdopFilterRay;

inline void kdop_filter_setup(const TraceRay* s, KdopFilterRay* f) {
  const float c = RTCL_KDOP_DIAGONAL;
  const float sy[RTCL_KDOP_FILTER_SLABS] = {1.0f, 1.0f, -1.0f, 1.0f};
  const float sz[RTCL_KDOP_FILTER_SLABS] = {1.0f, -1.0f, 1.0f, 1.0f};
  const float sx[RTCL_KDOP_FILTER_SLABS] = {1.0f, 1.0f, 1.0f, -1.0f};
  float e = RTCL_FILTER_WIDEN * 2.0f * fmax(fabs(s->ox), fmax(fabs(s->oy), fabs(s->oz)));
  f->keep_all = 0;
  for (int j = 0; j < RTCL_KDOP_FILTER_SLABS; ++j) {
    float nx = sx[j] * c, ny = sy[j] * c, nz = sz[j] * c;
    float a = nx * s->ox + ny * s->oy + nz * s->oz;
    float b = nx * s->dx + ny * s->dy + nz * s->dz;
    float inv = 1.0f / b;
    int forward = inv >= 0.0f;
    f->inv[j] = inv;
    f->entry_row[j] = forward ? j : j + RTCL_KDOP_FILTER_SLABS;
    f->entry_o[j] = forward ? a + e : a - e;
    f->exit_o[j] = forward ? a - e : a + e;
#ifdef RTCL_PRECISION_FAST
    f->keep_all |= !rtcl_is_finite(inv);
#endif
  }
}

/* Lane mask (-1 = keep) of the eight children, given the box test's entry
 * and exit distances of each lane. */
inline int8 kdop_filter8(global const Bvh8Kdop* v, const KdopFilterRay* f, float8 t_entry, float8 t_exit) {
  if (f->keep_all) return (int8)(-1);
  global const float8* rows = (global const float8*)v;
  float8 tn = t_entry, tf = t_exit;
#define KDOP_FILTER_SLAB(j)                                                                      \
  {                                                                                              \
    int er = f->entry_row[j];                                                                    \
    tn = rtcl_fmax8((rows[er] - f->entry_o[j]) * f->inv[j], tn);                                 \
    tf = rtcl_fmin8((rows[(er + RTCL_KDOP_FILTER_SLABS) & 7] - f->exit_o[j]) * f->inv[j], tf);   \
  }
  KDOP_FILTER_SLAB(0) KDOP_FILTER_SLAB(1) KDOP_FILTER_SLAB(2) KDOP_FILTER_SLAB(3)
#undef KDOP_FILTER_SLAB
  float8 lo = tn - fabs(tn) * RTCL_FILTER_T_WIDEN;
  float8 hi = tf + fabs(tf) * RTCL_FILTER_T_WIDEN;
  return lo <= hi;
}

#endif
