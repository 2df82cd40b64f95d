/* Bounding-sphere filter of eight BVH children in float8 lanes (the
 * mixed-volume BVH, kernels/accel/bvh.cl with RTCL_BVH_SPHERES). OpenCL C
 * only.
 *
 * Contract: conservative. A lane is rejected only when the ray's line
 * passes farther than the lane's sphere radius from its centre, so a ray
 * that meets the sphere's contents at any t is kept; the t range is left to
 * the box test that runs first. Lanes with r < 0 (no sphere) are kept.
 *
 * Arithmetic and margin: the closest approach of the line to the centre is
 * computed exactly as intersect_sphere_volume does (kernels/shared/
 * volumes.h: direction scaled to max |component| = 1, q = f - (f.d / d.d) d
 * for f = o - c), and the radius is widened by that header's margin,
 * RTCL_VOLUME_WIDEN * (2 |o|_inf + reach). The host folds the ray-independent
 * part RTCL_VOLUME_WIDEN * reach into Bvh8Spheres::r (rounded up); the
 * ray's part is added here. The filter widens at every precision level: it
 * may only cost a box's worth of extra work, never a hit. */
#ifndef RTCL_SHARED_SPHERE_FILTER8_H
#define RTCL_SHARED_SPHERE_FILTER8_H

#include "shared/ray.h"

/* Spatial widening per unit of (2 |o|_inf + reach): RTCL_VOLUME_WIDEN of
 * kernels/shared/volumes.h (same value, that header is not included here:
 * it carries host-side definitions). */
#define RTCL_SPHERE_FILTER_WIDEN (16.0f * FLT_EPSILON)

/* Per-ray constants of the filter. */
typedef struct SphereFilterRay {
  float dx, dy, dz; /* direction scaled to max |component| = 1 */
  float a;          /* d.d of the scaled direction, in [1, 3] */
  float widen;      /* RTCL_SPHERE_FILTER_WIDEN * 2 |o|_inf */
} SphereFilterRay;

inline void sphere_filter_setup(const TraceRay* s, SphereFilterRay* f) {
  float scale = fmax(fabs(s->dx), fmax(fabs(s->dy), fabs(s->dz)));
  f->dx = s->dx / scale;
  f->dy = s->dy / scale;
  f->dz = s->dz / scale;
  f->a = f->dx * f->dx + f->dy * f->dy + f->dz * f->dz;
  f->widen = RTCL_SPHERE_FILTER_WIDEN * 2.0f * fmax(fabs(s->ox), fmax(fabs(s->oy), fabs(s->oz)));
}

/* Lane mask (-1 = keep) of the eight spheres of one node. */
inline int8 sphere_filter8(global const Bvh8Spheres* v, const TraceRay* s, const SphereFilterRay* f) {
  float8 r = vload8(0, v->r);
  float8 fx = (float8)(s->ox) - vload8(0, v->cx);
  float8 fy = (float8)(s->oy) - vload8(0, v->cy);
  float8 fz = (float8)(s->oz) - vload8(0, v->cz);
  float8 b = fx * f->dx + fy * f->dy + fz * f->dz;
  float8 t_mid = -b / f->a;
  float8 qx = fx + t_mid * f->dx, qy = fy + t_mid * f->dy, qz = fz + t_mid * f->dz;
  float8 l2 = qx * qx + qy * qy + qz * qz;
  float8 radius = r + f->widen;
  return (l2 <= radius * radius) | (r < 0.0f);
}

#endif
