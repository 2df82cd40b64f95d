/* Ray/sphere tests of eight spheres in float8 lanes, one ray (Haines et al.,
 * "Precision improvements for ray/sphere intersection", Ray Tracing Gems
 * ch. 7: the discriminant is formed from the distance of the centre to the
 * line, not from b^2 - 4ac). Blocks and indexed references load their lanes
 * and run intersect_sphere_lanes, as for triangles (shared/triangle.h). The
 * exact level re-tests in double every lane float cannot rule out.
 * OpenCL C only. */
#ifndef RTCL_SHARED_SPHERE_H
#define RTCL_SHARED_SPHERE_H

#include "shared/exact.h"

/* The ray/sphere quadratic, every argument per lane (a single-ray caller
 * broadcasts its ray, a packet caller its sphere), on the direction scaled
 * by a power of two, d' = d * scale with scale = 2^-e for the exponent e of
 * the largest |d| component (clamped to [-126, 126]): exact, and it keeps
 * a = d'.d' and the discriminant clear of float underflow and overflow for
 * very short or very long directions (a direction 1e-18 long put a root's
 * point 14 tolerances off the sphere); the roots of d' are those of d over
 * scale (t = t' * scale, rtcl_sphere_roots8). f = o - c, a = d'.d',
 * b = -f.d' (= a * t' of the closest approach), the squared distance l2 of
 * the line from the centre, and the discriminant a (r^2 - l2), which does
 * not cancel for distant spheres (Haines et al., Ray Tracing Gems ch. 7).
 * *cand (exact level): the lanes whose discriminant is real or within
 * rounding of zero, which double precision then decides. The one source
 * of this arithmetic. */
typedef struct SphereQuadratic8 {
  float8 fx, fy, fz, a, b, l2, disc, scale;
} SphereQuadratic8;

RTCL_LANES_INLINE SphereQuadratic8 rtcl_sphere_quadratic8(float8 cx, float8 cy, float8 cz, float8 r, float8 ox,
                                                          float8 oy, float8 oz, float8 dx, float8 dy, float8 dz) {
  SphereQuadratic8 q;
  /* e from the exponent bits of max |d| (a subnormal's are 0: e = -127,
   * clamped) */
  float8 largest = fmax(fabs(dx), fmax(fabs(dy), fabs(dz)));
  int8 e = clamp(((as_int8(largest) >> 23) & 0xff) - 127, (int8)(-126), (int8)(126));
  q.scale = as_float8((127 - e) << 23);
  dx *= q.scale;
  dy *= q.scale;
  dz *= q.scale;
  q.fx = ox - cx;
  q.fy = oy - cy;
  q.fz = oz - cz;
  q.a = dx * dx + dy * dy + dz * dz;
  q.b = -(q.fx * dx + q.fy * dy + q.fz * dz);
  float8 k = q.b / q.a;
  float8 lx = q.fx + k * dx, ly = q.fy + k * dy, lz = q.fz + k * dz;
  q.l2 = lx * lx + ly * ly + lz * lz;
  q.disc = q.a * (r * r - q.l2);
  return q;
}

#ifdef RTCL_PRECISION_EXACT
RTCL_LANES_INLINE int8 rtcl_sphere_candidates8(const SphereQuadratic8* q, float8 r) {
  return q->disc >= -(RTCL_EXACT_EDGE_ULPS * FLT_EPSILON) * q->a *
                        (r * r + q->l2 + q->fx * q->fx + q->fy * q->fy + q->fz * q->fz);
}
#else
/* The two roots for d (*tn <= *tf, from the numerically stable pair c / q,
 * q / a, times scale) and which of them lie in [tmin, t_best). */
RTCL_LANES_INLINE void rtcl_sphere_roots8(const SphereQuadratic8* q, float8 r, float8 tmin, float8 t_best,
                                          float8* tn, float8* tf, int8* ok_n, int8* ok_f) {
  int8 real = q->disc >= 0.0f;
  float8 c = q->fx * q->fx + q->fy * q->fy + q->fz * q->fz - r * r;
  float8 qq = q->b + copysign(sqrt(fmax(q->disc, 0.0f)), q->b);
  float8 t0 = c / qq * q->scale, t1 = qq / q->a * q->scale;
  *tn = fmin(t0, t1);
  *tf = fmax(t0, t1);
  *ok_n = real & (*tn >= tmin) & (*tn < t_best);
  *ok_f = real & (*tf >= tmin) & (*tf < t_best);
}
#endif

/* Lanes with radius NaN never hit. Records the nearest hit in
 * [tmin, h->t_best) (exact: by exact_better) in h and returns 1. */
inline int intersect_sphere_lanes(float8 cx, float8 cy, float8 cz, float8 r, int8 prim, const TraceRay* s,
                                  HitState* h) {
  SphereQuadratic8 q = rtcl_sphere_quadratic8(cx, cy, cz, r, (float8)(s->ox), (float8)(s->oy), (float8)(s->oz),
                                              (float8)(s->dx), (float8)(s->dy), (float8)(s->dz));
#ifdef RTCL_PRECISION_EXACT
  int8 cand = rtcl_sphere_candidates8(&q, r);
  if (!rtcl_any8(cand)) return 0;
  float vc[4][8];
  int c[8], p[8];
  vstore8(cx, 0, vc[0]); vstore8(cy, 0, vc[1]); vstore8(cz, 0, vc[2]); vstore8(r, 0, vc[3]);
  vstore8(cand, 0, c);
  vstore8(prim, 0, p);
  int found = 0;
  for (int l = 0; l < 8; ++l) {
    if (!c[l]) continue;
    double t = exact_sphere(vc[0][l], vc[1][l], vc[2][l], vc[3][l], s->ox, s->oy, s->oz, s->dx, s->dy, s->dz,
                            s->tmin, s->tmax);
    if (!exact_better(t, p[l], h->t_exact, h->prim, s->tmin, s->tmax)) continue;
    h->t_exact = t;
    h->t_best = convert_float_rtp(t);
    h->u = 0.0f;
    h->v = 0.0f;
    h->prim = p[l];
    found = 1;
  }
  return found;
#else
  float8 tn, tf;
  int8 ok_n, ok_f;
  rtcl_sphere_roots8(&q, r, (float8)(s->tmin), (float8)(h->t_best), &tn, &tf, &ok_n, &ok_f);
  float8 t = select(select((float8)(INFINITY), tf, ok_f), tn, ok_n);
  int8 ok = ok_n | ok_f;
  if (!rtcl_any8(ok)) return 0;
  float m = rtcl_min8(t);
  int lane = rtcl_lane_of(t, m);
  h->t_best = m;
  h->u = 0.0f;
  h->v = 0.0f;
  h->prim = rtcl_lane_i(prim, lane);
  return 1;
#endif
}

inline int intersect_spheres8(global const SphereBlock* block, const TraceRay* s, HitState* h) {
  return intersect_sphere_lanes(vload8(0, block->cx), vload8(0, block->cy), vload8(0, block->cz),
                                vload8(0, block->r), vload8(0, block->prim), s, h);
}

/* Up to eight referenced spheres of an id-ordered sphere block array
 * (reference r is lane r & 7 of block r >> 3); count <= 8. */
inline int intersect_sphere_refs(global const SphereBlock* blocks, const int* refs, int count, const TraceRay* s,
                                 HitState* h) {
  float lanes[4][8];
  int prim[8];
  for (int l = 0; l < 8; ++l) {
    if (l < count) {
      global const SphereBlock* b = blocks + (refs[l] >> 3);
      int lane = refs[l] & 7;
      lanes[0][l] = b->cx[lane];
      lanes[1][l] = b->cy[lane];
      lanes[2][l] = b->cz[lane];
      lanes[3][l] = b->r[lane];
      prim[l] = b->prim[lane];
    } else {
      lanes[0][l] = lanes[1][l] = lanes[2][l] = 0.0f;
      lanes[3][l] = NAN;
      prim[l] = -1;
    }
  }
  return intersect_sphere_lanes(vload8(0, lanes[0]), vload8(0, lanes[1]), vload8(0, lanes[2]),
                                vload8(0, lanes[3]), vload8(0, prim), s, h);
}

#endif
