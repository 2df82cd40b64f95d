/* Ray tests of the bounding volumes (shared/bounds_layouts.h): one source,
 * compiled as OpenCL C (kernels/bounds/volume_rays.cl) and as C++
 * (rtcl/bounds/volume_rays.hpp), so host and device run the same arithmetic.
 *
 * Contract: conservative. A valid ray (rtcl_ray_valid's rule) that meets the
 * bounded contents at some t in [tmin, tmax] is reported as a hit, with
 * *t_entry <= that t; a miss may be reported as a hit near the volume's
 * boundary (within the margin below). Invalid rays and the empty volume
 * report a miss.
 *
 * Rounding margin: computing dot(n, o) and t * dot(n, d) in float errs by at
 * most 3 ulp of sum |n_i o_i| <= sqrt(3) |o|_inf and of
 * t |d| = |p - o| <= reach + sqrt(3) |o|_inf for a contents point p; the
 * subtractions against d_near / d_far (|d| <= reach) add 2 ulp of those.
 * Together that is below 14 |o|_inf + 6 reach ulp; each slab (and the
 * sphere's radius) is widened by RTCL_VOLUME_WIDEN * (2 |o|_inf + reach),
 * 32 |o|_inf + 16 reach ulp, with a factor two to spare. The t interval is
 * then widened by a relative 8 ulp, as box.h does (Ize 2013), for the
 * rounding of the division.
 *
 * ±0 direction components: a slab whose dot(n, d) is ±0 gets a ±inf
 * reciprocal, so its distances are ±inf (parallel and outside: a miss;
 * inside: no limit) and a numerator of exactly 0 gives a NaN that fmin/fmax
 * drop (C99 / OpenCL C 1.2 6.12.2), as for box.h. */
#ifndef RTCL_SHARED_VOLUMES_H
#define RTCL_SHARED_VOLUMES_H

#ifdef __OPENCL_VERSION__
#include "shared/ray.h"
#include "shared/bounds_layouts.h"
#define RTCL_VOLUME_ARG global const
#define RTCL_VOLUME_INLINE inline
#define RTCL_VOLUME_FMIN fmin
#define RTCL_VOLUME_FMAX fmax
#define RTCL_VOLUME_FABS fabs
#define RTCL_VOLUME_SQRT sqrt
inline int rtcl_volume_ray_valid(const Ray* r) {
  return rtcl_ray_valid(r->ox, r->oy, r->oz, r->dx, r->dy, r->dz, r->tmin, r->tmax);
}
#else
#include <cfloat>
#include <cmath>

/* Angle brackets: the kernel embedder inlines only quoted includes. */
#include <rtcl/layouts.hpp>
#include <rtcl/shared/bounds_layouts.h>
namespace rtcl {
#define RTCL_VOLUME_ARG const
#define RTCL_VOLUME_INLINE inline
#define RTCL_VOLUME_FMIN std::fmin
#define RTCL_VOLUME_FMAX std::fmax
#define RTCL_VOLUME_FABS std::fabs
#define RTCL_VOLUME_SQRT std::sqrt
/* rtcl_ray_valid's rule (kernels/shared/ray.h), host side. */
inline int rtcl_volume_ray_valid(const Ray* r) {
  bool finite = std::isfinite(r->ox) && std::isfinite(r->oy) && std::isfinite(r->oz) && std::isfinite(r->dx) &&
                std::isfinite(r->dy) && std::isfinite(r->dz);
  bool nonzero = r->dx != 0.0f || r->dy != 0.0f || r->dz != 0.0f;
  return finite && nonzero && !std::isnan(r->tmin) && !std::isnan(r->tmax) && r->tmin <= r->tmax;
}
#endif

/* Spatial widening per unit of (2 |o|_inf + reach); see the header comment. */
#define RTCL_VOLUME_WIDEN (16.0f * FLT_EPSILON)
/* Relative widening of the t interval. */
#define RTCL_VOLUME_T_WIDEN (8.0f * FLT_EPSILON)

RTCL_VOLUME_INLINE float rtcl_volume_margin(const Ray* r, float reach) {
  float o = RTCL_VOLUME_FMAX(RTCL_VOLUME_FABS(r->ox), RTCL_VOLUME_FMAX(RTCL_VOLUME_FABS(r->oy), RTCL_VOLUME_FABS(r->oz)));
  return RTCL_VOLUME_WIDEN * (2.0f * o + reach);
}

/* 1 when the ray enters the slab volume within [tmin, tmax]; *t_entry is
 * then the (widened) entry distance, >= tmin. */
RTCL_VOLUME_INLINE int intersect_slab_volume(RTCL_VOLUME_ARG SlabVolume* v, const Ray* r, float* t_entry) {
  if (!rtcl_volume_ray_valid(r) || v->count <= 0) return 0;
  float e = rtcl_volume_margin(r, v->reach);
  float tn = r->tmin, tf = r->tmax;
  for (int i = 0; i < v->count && i < RTCL_MAX_SLABS; ++i) {
    float nx = v->normal[i][0], ny = v->normal[i][1], nz = v->normal[i][2];
    float a = nx * r->ox + ny * r->oy + nz * r->oz;
    float b = nx * r->dx + ny * r->dy + nz * r->dz;
    float inv = 1.0f / b;
    float t1 = (v->d_near[i] - e - a) * inv;
    float t2 = (v->d_far[i] + e - a) * inv;
    tn = RTCL_VOLUME_FMAX(tn, RTCL_VOLUME_FMIN(t1, t2));
    tf = RTCL_VOLUME_FMIN(tf, RTCL_VOLUME_FMAX(t1, t2));
  }
  float lo = tn - RTCL_VOLUME_FABS(tn) * RTCL_VOLUME_T_WIDEN;
  float hi = tf + RTCL_VOLUME_FABS(tf) * RTCL_VOLUME_T_WIDEN;
  *t_entry = RTCL_VOLUME_FMAX(lo, r->tmin);
  return lo <= hi;
}

/* The same for a sphere: the ray's closest approach to the centre is taken
 * as a point (o - c) - (b / a) d, which keeps the discriminant accurate for
 * a distant origin (no b^2 - a c cancellation); the roots' cancellation near
 * the origin is covered by an absolute widening of 4 ulp of |t_mid| + half_chord. */
RTCL_VOLUME_INLINE int intersect_sphere_volume(RTCL_VOLUME_ARG SphereVolume* s, const Ray* r, float* t_entry) {
  if (!rtcl_volume_ray_valid(r) || !(s->r >= 0.0f)) return 0;
  float e = rtcl_volume_margin(r, s->reach);
  /* Direction scaled to max |component| = 1 (no underflow of d.d for a tiny
   * valid direction); t' in those units, t = t' / scale. */
  float scale = RTCL_VOLUME_FMAX(RTCL_VOLUME_FABS(r->dx), RTCL_VOLUME_FMAX(RTCL_VOLUME_FABS(r->dy), RTCL_VOLUME_FABS(r->dz)));
  float dx = r->dx / scale, dy = r->dy / scale, dz = r->dz / scale;
  float fx = r->ox - s->cx, fy = r->oy - s->cy, fz = r->oz - s->cz;
  float a = dx * dx + dy * dy + dz * dz;
  float b = fx * dx + fy * dy + fz * dz;
  float t_mid = -b / a;
  float qx = fx + t_mid * dx, qy = fy + t_mid * dy, qz = fz + t_mid * dz;
  float l2 = qx * qx + qy * qy + qz * qz;
  float radius = s->r + e;
  float disc = radius * radius - l2;
  if (!(disc >= 0.0f)) return 0;
  float half_chord = RTCL_VOLUME_SQRT(disc / a);
  float w = 4.0f * FLT_EPSILON * (RTCL_VOLUME_FABS(t_mid) + half_chord);
  float t0 = (t_mid - half_chord - w) / scale, t1 = (t_mid + half_chord + w) / scale;
  float tn = RTCL_VOLUME_FMAX(t0, r->tmin), tf = RTCL_VOLUME_FMIN(t1, r->tmax);
  float lo = tn - RTCL_VOLUME_FABS(tn) * RTCL_VOLUME_T_WIDEN;
  float hi = tf + RTCL_VOLUME_FABS(tf) * RTCL_VOLUME_T_WIDEN;
  *t_entry = RTCL_VOLUME_FMAX(lo, r->tmin);
  return lo <= hi;
}

#ifndef __OPENCL_VERSION__
}  // namespace rtcl
#endif

#endif
