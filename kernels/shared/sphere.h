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

/* Lanes with radius NaN never hit. Records the nearest hit in
 * [tmin, h->t_best) (exact: by exact_better) in h and returns 1. */
inline int intersect_sphere_lanes(float8 cx, float8 cy, float8 cz, float8 r, int8 prim, const TraceRay* s,
                                  HitState* h) {
  float8 fx = s->ox - cx;
  float8 fy = s->oy - cy;
  float8 fz = s->oz - cz;
  float a = s->dx * s->dx + s->dy * s->dy + s->dz * s->dz;
  float8 b = -(fx * s->dx + fy * s->dy + fz * s->dz); /* = a * t_closest */
  float8 k = b / a;
  float8 lx = fx + k * s->dx, ly = fy + k * s->dy, lz = fz + k * s->dz;
  float8 l2 = lx * lx + ly * ly + lz * lz;
  float8 disc = a * (r * r - l2);
#ifdef RTCL_PRECISION_EXACT
  /* loose: the discriminant within rounding of zero, or real */
  int8 cand = disc >= -(RTCL_EXACT_EDGE_ULPS * FLT_EPSILON) * a * (r * r + l2 + fx * fx + fy * fy + fz * fz);
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
