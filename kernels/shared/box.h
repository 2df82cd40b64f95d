/* Ray/box slab test of eight boxes in float8 lanes. OpenCL C only.
 *
 * ±0 direction components: the reciprocal of ±0 is ±inf, so a ray parallel
 * to an axis gets slab distances (b - o) * inf = ±inf, exact for an origin
 * strictly inside or outside the slab. An origin exactly on one of the
 * slab's planes gives 0 * inf = NaN, and the fmin/fmax chain drops a NaN
 * operand (OpenCL C 1.2, 6.12.2): that plane then does not limit the
 * interval, which is exact too, since the ray stays on the closed slab for
 * every t. Clamping |d| to a tiny finite value instead would reject a box
 * whose face the ray lies on (tf = 0 * 1/eps = 0) for one sign of zero but
 * not the other. */
#ifndef RTCL_SHARED_BOX_H
#define RTCL_SHARED_BOX_H

#include "shared/ray.h"

/* Relative widening of each slab interval at the robust and exact levels:
 * covers the rounding of (b - o), of the reciprocal (<= 2.5 ulp in OpenCL C)
 * and of the product, with margin (Ize 2013, "Robust BVH ray traversal").
 * The fast level does not widen. */
#define RTCL_SLAB_WIDEN (8.0f * FLT_EPSILON)

/* One fused multiply-add per side, no slower than a multiply and a
 * subtraction: the widened value is the exact tn - |tn| * RTCL_SLAB_WIDEN
 * rounded once, within half an ulp of it, as the two-step form's is. */
inline void rtcl_widen_slab(float8* tn, float8* tf) {
#ifndef RTCL_PRECISION_FAST
  *tn = fma(-fabs(*tn), (float8)(RTCL_SLAB_WIDEN), *tn);
  *tf = fma(fabs(*tf), (float8)(RTCL_SLAB_WIDEN), *tf);
#endif
}

/* Slab test of the ray against eight boxes over [tmin, tmax], given as six
 * float8 rows (lower x, y, z, upper x, y, z; the Bvh8Node bounds layout).
 * Returns the hit mask (lane = -1 where hit) and the entry and exit
 * distances. Empty slots (lower = +inf, upper = -inf) never hit. Each axis's
 * distance enters a chain that starts from tmin or tmax, which are never
 * NaN, so tn and tf are not either. */
/* The slab arithmetic, every argument per lane (a single-ray caller
 * broadcasts its ray over eight boxes, a packet caller one box over its
 * rays): the entry planes (nx, ny, nz) and exit planes (fx, fy, fz) chosen
 * by the direction's signs, the widened entry and exit distances over
 * [tmin, tmax] into *tn, *tf. The one source of every slab test's
 * arithmetic, so single rays and packets get the same distances. */
RTCL_LANES_INLINE void rtcl_slabs8(float8 nx, float8 ny, float8 nz, float8 fx, float8 fy, float8 fz, float8 ox,
                                   float8 oy, float8 oz, float8 ix, float8 iy, float8 iz, float8 tmin, float8 tmax,
                                   float8* tn, float8* tf) {
  float8 tnx = (nx - ox) * ix;
  float8 tny = (ny - oy) * iy;
  float8 tnz = (nz - oz) * iz;
  float8 tfx = (fx - ox) * ix;
  float8 tfy = (fy - oy) * iy;
  float8 tfz = (fz - oz) * iz;
  *tn = rtcl_fmax8(tnx, rtcl_fmax8(tny, rtcl_fmax8(tnz, tmin)));
  *tf = rtcl_fmin8(tfx, rtcl_fmin8(tfy, rtcl_fmin8(tfz, tmax)));
  rtcl_widen_slab(tn, tf);
}

/* The slab arithmetic of a whole packet at once (the packet kernel's
 * frustum traversal, kernels/accel/bvh_packet.cl): the rays' origins lie
 * in a box, their reciprocal directions in a range of one sign per axis,
 * and their tmin >= 0. Per axis the entry distance is bounded below by
 * A * rn, A = entry plane - the origin bound that makes it smallest (the
 * largest origin coordinate where the direction is positive, the smallest
 * where it is negative: on = that bound), rn = the reciprocal of least
 * magnitude: that is min(A * lo, A * hi) where A >= 0 (the plane ahead),
 * and a negative bound where A < 0, which the max with tmin >= 0 then
 * drops, as it drops every ray's own. The exit distance is bounded above
 * by B * rf, B = exit plane - of (the other bound), rf = the reciprocal of
 * greatest magnitude: max(B * lo, B * hi) where B >= 0; where B < 0 it is
 * negative, so below the entry, and the box is rejected, as every ray's
 * own exit is negative there too. Float rounding is monotone, so these
 * bounds hold for every ray's own rtcl_slabs8 distances (widened alike,
 * monotone again): a box this test rejects, every ray of the packet
 * rejects. One multiplication per plane where min(A * lo, A * hi) takes
 * two and a min. Needs finite
 * reciprocals (no NaN arises then). */
RTCL_LANES_INLINE void rtcl_frustum_slabs8(float8 nx, float8 ny, float8 nz, float8 fx, float8 fy, float8 fz,
                                           float onx, float ony, float onz, float ofx, float ofy, float ofz,
                                           float rnx, float rny, float rnz, float rfx, float rfy, float rfz,
                                           float tmin, float tmax, float8* tn, float8* tf) {
  float8 tnx = (nx - onx) * rnx, tny = (ny - ony) * rny, tnz = (nz - onz) * rnz;
  float8 tfx = (fx - ofx) * rfx, tfy = (fy - ofy) * rfy, tfz = (fz - ofz) * rfz;
  *tn = rtcl_fmax8(tnx, rtcl_fmax8(tny, rtcl_fmax8(tnz, (float8)(tmin))));
  *tf = rtcl_fmin8(tfx, rtcl_fmin8(tfy, rtcl_fmin8(tfz, (float8)(tmax))));
  rtcl_widen_slab(tn, tf);
}

inline int8 intersect_box_rows8(global const float8* b, const TraceRay* s, float tmax, float8* t_entry,
                                float8* t_exit) {
  rtcl_slabs8(b[s->near_x], b[s->near_y], b[s->near_z], b[s->far_x], b[s->far_y], b[s->far_z], (float8)(s->ox),
              (float8)(s->oy), (float8)(s->oz), (float8)(s->ix), (float8)(s->iy), (float8)(s->iz),
              (float8)(s->tmin), (float8)(tmax), t_entry, t_exit);
  return *t_entry <= *t_exit;
}

/* Whether a slab test may rely on infinite slab distances for this ray:
 * always at the robust and exact levels; at the fast level, compiled with
 * -cl-fast-relaxed-math (which lets the compiler assume finite operands),
 * only when the ray moves along every axis (finite reciprocals). A box
 * test that may not answers "meets", which is conservative. */
inline int rtcl_slabs_defined(const TraceRay* s) {
#ifdef RTCL_PRECISION_FAST
  return rtcl_is_finite(s->ix) && rtcl_is_finite(s->iy) && rtcl_is_finite(s->iz);
#else
  return 1;
#endif
}

/* The ray over [tmin, tmax] against one box, six floats in the Bvh8Node
 * bounds order (lower x, y, z, upper x, y, z): lane by lane the arithmetic
 * of intersect_box_rows8. Returns whether the ray meets it (always, where
 * rtcl_slabs_defined does not hold). */
inline int intersect_box1(global const float* b, const TraceRay* s, float tmax) {
  if (!rtcl_slabs_defined(s)) return 1;
  float tn = fmax((b[s->near_x] - s->ox) * s->ix,
                  fmax((b[s->near_y] - s->oy) * s->iy, fmax((b[s->near_z] - s->oz) * s->iz, s->tmin)));
  float tf = fmin((b[s->far_x] - s->ox) * s->ix,
                  fmin((b[s->far_y] - s->oy) * s->iy, fmin((b[s->far_z] - s->oz) * s->iz, tmax)));
#ifndef RTCL_PRECISION_FAST
  tn = fma(-fabs(tn), RTCL_SLAB_WIDEN, tn);
  tf = fma(fabs(tf), RTCL_SLAB_WIDEN, tf);
#endif
  return tn <= tf;
}

/* The same for the eight child boxes of a BVH node. */
inline int8 intersect_boxes8(global const Bvh8Node* node, const TraceRay* s, float tmax, float8* t_entry) {
  float8 t_exit;
  return intersect_box_rows8((global const float8*)node->bounds, s, tmax, t_entry, &t_exit);
}

#endif
