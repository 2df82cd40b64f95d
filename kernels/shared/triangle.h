/* Ray/triangle tests of eight triangles in float8 lanes, one ray: the one
 * source of the arithmetic for every single-ray caller. Blocks
 * (TriangleBlock, the BVH's leaves and brute force) and indexed references
 * (cells and leaves that share primitives: grid, octree, kd-tree) load
 * their lanes differently and then run intersect_triangle_lanes, so every
 * structure reports the same closest t, bit for bit. OpenCL C only.
 *
 * Levels: robust and exact run the watertight test (Woop, Benthin, Wald
 * 2013, JCGT 2(1)); exact re-tests in double what float cannot decide
 * (shared/exact.h); fast runs Moller-Trumbore (1997), not watertight. */
#ifndef RTCL_SHARED_TRIANGLE_H
#define RTCL_SHARED_TRIANGLE_H

#include "shared/exact.h"

/* Edge function a*d - b*c in float. */
inline float8 rtcl_edge8(float8 a, float8 b, float8 c, float8 d) { return a * d - b * c; }

/* The lanes of edge function e = a*d - b*c that are exactly zero in float,
 * recomputed in double (Woop et al. 2013, section 4): a shared edge is then
 * decided identically by both triangles that own it. */
inline float8 rtcl_edge8_exact_zeros(float8 e, float8 a, float8 b, float8 c, float8 d) {
  /* two double4 halves: double8 is not a native vector type on AVX2 */
  double4 lo = convert_double4(a.lo) * convert_double4(d.lo) - convert_double4(b.lo) * convert_double4(c.lo);
  double4 hi = convert_double4(a.hi) * convert_double4(d.hi) - convert_double4(b.hi) * convert_double4(c.hi);
  float8 ed = (float8)(convert_float4(lo), convert_float4(hi));
  return select(e, ed, e == 0.0f);
}

/* Moller-Trumbore, every argument per lane (a single-ray caller broadcasts
 * its ray, a packet caller its triangle): the lanes hit in [tmin, t_best),
 * with their t and barycentrics. No epsilon: det == 0 (ray in the plane) is
 * the only rejection besides the barycentric and interval tests. */
inline int8 rtcl_moller_trumbore8(float8 ax, float8 ay, float8 az, float8 bx, float8 by, float8 bz, float8 cx,
                                  float8 cy, float8 cz, float8 ox, float8 oy, float8 oz, float8 dx, float8 dy,
                                  float8 dz, float8 tmin, float8 t_best, float8* t, float8* u, float8* v) {
  float8 e1x = bx - ax, e1y = by - ay, e1z = bz - az;
  float8 e2x = cx - ax, e2y = cy - ay, e2z = cz - az;
  float8 px = dy * e2z - dz * e2y, py = dz * e2x - dx * e2z, pz = dx * e2y - dy * e2x;
  float8 det = e1x * px + e1y * py + e1z * pz;
  float8 inv = 1.0f / det;
  float8 tx = ox - ax, ty = oy - ay, tz = oz - az;
  *u = (tx * px + ty * py + tz * pz) * inv;
  float8 qx = ty * e1z - tz * e1y, qy = tz * e1x - tx * e1z, qz = tx * e1y - ty * e1x;
  *v = (dx * qx + dy * qy + dz * qz) * inv;
  *t = (e2x * qx + e2y * qy + e2z * qz) * inv;
  return (det != 0.0f) & (*u >= 0.0f) & (*v >= 0.0f) & (*u + *v <= 1.0f) & (*t >= tmin) & (*t < t_best);
}

#ifndef RTCL_PRECISION_FAST
/* The watertight test's shear (Woop et al. 2013), every argument per lane
 * (a single-ray caller broadcasts its ray, a packet caller its triangle):
 * the vertices given on the ray's permuted axes (ax = a[kx], ...) relative
 * to the origin and sheared along the ray, (Ax, Ay, Az), ..., and the edge
 * functions U, V, W. The one source of this arithmetic. (A struct of
 * values, not arrays: PoCL keeps it in registers.) */
typedef struct Watertight8 {
  float8 Ax, Ay, Az, Bx, By, Bz, Cx, Cy, Cz, U, V, W;
} Watertight8;

RTCL_LANES_INLINE Watertight8 rtcl_watertight_edges8(float8 ax, float8 ay, float8 az, float8 bx, float8 by,
                                                     float8 bz, float8 cx, float8 cy, float8 cz, float8 okx,
                                                     float8 oky, float8 okz, float8 sx, float8 sy) {
  Watertight8 w;
  w.Az = az - okz;
  w.Bz = bz - okz;
  w.Cz = cz - okz;
  w.Ax = ax - okx - sx * w.Az;
  w.Ay = ay - oky - sy * w.Az;
  w.Bx = bx - okx - sx * w.Bz;
  w.By = by - oky - sy * w.Bz;
  w.Cx = cx - okx - sx * w.Cz;
  w.Cy = cy - oky - sy * w.Cz;
  w.U = rtcl_edge8(w.Cx, w.Cy, w.Bx, w.By);
  w.V = rtcl_edge8(w.Ax, w.Ay, w.Cx, w.Cy);
  w.W = rtcl_edge8(w.Bx, w.By, w.Ax, w.Ay);
#if defined(RTCL_HAS_FP64) && defined(RTCL_PRECISION_ROBUST)
  /* one test for the three edges: rtcl_any8, not any() (PoCL turns any()
   * into a test and branch per lane) */
  if (rtcl_any8((w.U == 0.0f) | (w.V == 0.0f) | (w.W == 0.0f))) {
    w.U = rtcl_edge8_exact_zeros(w.U, w.Cx, w.Cy, w.Bx, w.By);
    w.V = rtcl_edge8_exact_zeros(w.V, w.Ax, w.Ay, w.Cx, w.Cy);
    w.W = rtcl_edge8_exact_zeros(w.W, w.Bx, w.By, w.Ax, w.Ay);
  }
#endif
  return w;
}

/* The lanes inside all three edges of rtcl_watertight_edges8, either
 * winding (a lane with a NaN edge may pass; its det and t are NaN and fail
 * rtcl_watertight_hit8's t test). */
RTCL_LANES_INLINE int8 rtcl_watertight_inside8(const Watertight8* w) {
  return (rtcl_fmin8(w->U, rtcl_fmin8(w->V, w->W)) >= 0.0f) | (rtcl_fmax8(w->U, rtcl_fmax8(w->V, w->W)) <= 0.0f);
}

#if defined(RTCL_HAS_FP64) && defined(RTCL_PRECISION_ROBUST)
/* One double4 half of rtcl_watertight_refine8: U, V, W, det and t
 * recomputed in double from the sheared float vertices (each product of two
 * floats is exact in double) where `redo` is set. */
inline void rtcl_watertight_refine4(double4 Ax, double4 Ay, double4 Az, double4 Bx, double4 By, double4 Bz,
                                    double4 Cx, double4 Cy, double4 Cz, double4 sz, long4 redo, float4* U,
                                    float4* V, float4* W, float4* det, float4* t) {
  double4 u = Cx * By - Cy * Bx, v = Ax * Cy - Ay * Cx, w = Bx * Ay - By * Ax;
  double4 d = u + v + w;
  double4 T = sz * (u * Az + v * Bz + w * Cz);
  int4 r = convert_int4(redo);
  *U = select(*U, convert_float4(u), r);
  *V = select(*V, convert_float4(v), r);
  *W = select(*W, convert_float4(w), r);
  *det = select(*det, convert_float4(d), r);
  *t = select(*t, convert_float4(T / d), r);
}

/* The lanes inside their edges whose float determinant is ill-conditioned
 * (|det| below 2^-5 of the sum of the edge functions' absolute products,
 * whose float rounding reaches 2^-23 of that sum: a thin sliver, or a
 * triangle seen almost edge-on) get U, V, W, det and t from double:
 * otherwise t = T / det can be wrong by far more than the float rounding
 * of the hit point (a sliver 1e5 long and 0.03 wide, hit head-on, put the
 * point 7e3 off the triangle). The inside decision stays the float one, so
 * shared edges stay watertight; only lanes that are inside pay. */
RTCL_LANES_INLINE void rtcl_watertight_refine8(Watertight8* w, float8 sz, int8 inside, float8* det, float8* t) {
  if (!rtcl_any8(inside)) return;
  float8 products = fabs(w->Cx * w->By) + fabs(w->Cy * w->Bx) + fabs(w->Ax * w->Cy) + fabs(w->Ay * w->Cx) +
                    fabs(w->Bx * w->Ay) + fabs(w->By * w->Ax);
  int8 redo = inside & (fabs(*det) < products * 0x1p-5f);
  if (!rtcl_any8(redo)) return;
  float4 U = w->U.lo, V = w->V.lo, W = w->W.lo, d = det->lo, tt = t->lo;
  rtcl_watertight_refine4(convert_double4(w->Ax.lo), convert_double4(w->Ay.lo), convert_double4(w->Az.lo),
                          convert_double4(w->Bx.lo), convert_double4(w->By.lo), convert_double4(w->Bz.lo),
                          convert_double4(w->Cx.lo), convert_double4(w->Cy.lo), convert_double4(w->Cz.lo),
                          convert_double4(sz.lo), convert_long4(redo.lo), &U, &V, &W, &d, &tt);
  w->U.lo = U; w->V.lo = V; w->W.lo = W; det->lo = d; t->lo = tt;
  U = w->U.hi; V = w->V.hi; W = w->W.hi; d = det->hi; tt = t->hi;
  rtcl_watertight_refine4(convert_double4(w->Ax.hi), convert_double4(w->Ay.hi), convert_double4(w->Az.hi),
                          convert_double4(w->Bx.hi), convert_double4(w->By.hi), convert_double4(w->Bz.hi),
                          convert_double4(w->Cx.hi), convert_double4(w->Cy.hi), convert_double4(w->Cz.hi),
                          convert_double4(sz.hi), convert_long4(redo.hi), &U, &V, &W, &d, &tt);
  w->U.hi = U; w->V.hi = V; w->W.hi = W; det->hi = d; t->hi = tt;
}
#endif

/* The robust level's decision from rtcl_watertight_edges8: the lanes hit
 * in [tmin, t_best) (inside all three edges, either winding; not in the
 * triangle's plane), with the hit distance *t and the determinant *det
 * (barycentrics V / det, W / det; at the robust level with fp64, lanes with
 * an ill-conditioned det have U, V, W, det and t from double,
 * rtcl_watertight_refine8). */
RTCL_LANES_INLINE int8 rtcl_watertight_hit8(Watertight8* w, float8 sz, float8 tmin, float8 t_best, float8* t,
                                            float8* det) {
  int8 inside = rtcl_watertight_inside8(w);
  *det = w->U + w->V + w->W;
  float8 T = sz * (w->U * w->Az + w->V * w->Bz + w->W * w->Cz);
  *t = T / *det;
#if defined(RTCL_HAS_FP64) && defined(RTCL_PRECISION_ROBUST)
  rtcl_watertight_refine8(w, sz, inside & (*det != 0.0f), det, t);
#endif
  return inside & (*det != 0.0f) & (*t >= tmin) & (*t < t_best);
}

#ifdef RTCL_CROSSINGS
/* Crossings (the count and all-hits queries, kernels/query/count_hits.cl;
 * only kernels built with RTCL_CROSSINGS compile this): the watertight test
 * with a tie-breaking fill rule, so that a ray through a shared edge or
 * vertex of a closed mesh crosses it exactly once.
 *
 * Edge values exactly 0 (the ray's line meets the edge's line; at the
 * robust level zeros are re-tested in double, so 0 is exact for the sheared
 * float vertices) are decided as if the ray were moved by an infinitesimal
 * eps * (1, -delta), delta << 1, in the sheared plane: an edge whose
 * direction, taken with the triangle's interior on its right, is d counts
 * as inside iff d.y > 0, or d.y == 0 and d.x > 0. Both triangles of an
 * edge compute bitwise the same sheared vertices and exactly opposite edge
 * values, so where they lie on opposite sides of the edge (the ray crosses
 * it) they see opposite directions and exactly one owns the edge; where
 * they lie on the same side (a silhouette) both or neither do (0 or 2).
 * At a shared vertex the rule is the test of the moved ray, which lies on
 * no edge: exactly one triangle of a fan around the vertex. A triangle
 * whose projection has zero area (det == 0: a ray in its plane) is never
 * hit. The lanes hit in [tmin, tmax], with *t and *det as
 * rtcl_watertight_hit8's. */
RTCL_LANES_INLINE int8 rtcl_edge_owned8(float8 dx, float8 dy) {
  return (dy > 0.0f) | ((dy == 0.0f) & (dx > 0.0f));
}

RTCL_LANES_INLINE int8 rtcl_crossing_hit8(Watertight8* w, float8 sz, float8 tmin, float8 tmax, float8* t,
                                          float8* det) {
  /* U, V, W = minus the orientation of the origin against B->C, C->A,
   * A->B: where all are >= 0 the interior lies right of these directions,
   * where all are <= 0 right of the reversed ones */
  float8 bcx = w->Cx - w->Bx, bcy = w->Cy - w->By;
  float8 cax = w->Ax - w->Cx, cay = w->Ay - w->Cy;
  float8 abx = w->Bx - w->Ax, aby = w->By - w->Ay;
  int8 pos = ((w->U > 0.0f) | ((w->U == 0.0f) & rtcl_edge_owned8(bcx, bcy))) &
             ((w->V > 0.0f) | ((w->V == 0.0f) & rtcl_edge_owned8(cax, cay))) &
             ((w->W > 0.0f) | ((w->W == 0.0f) & rtcl_edge_owned8(abx, aby)));
  int8 neg = ((w->U < 0.0f) | ((w->U == 0.0f) & rtcl_edge_owned8(-bcx, -bcy))) &
             ((w->V < 0.0f) | ((w->V == 0.0f) & rtcl_edge_owned8(-cax, -cay))) &
             ((w->W < 0.0f) | ((w->W == 0.0f) & rtcl_edge_owned8(-abx, -aby)));
  *det = w->U + w->V + w->W;
  float8 T = sz * (w->U * w->Az + w->V * w->Bz + w->W * w->Cz);
  *t = T / *det;
#if defined(RTCL_HAS_FP64) && defined(RTCL_PRECISION_ROBUST)
  rtcl_watertight_refine8(w, sz, (pos | neg) & (*det != 0.0f), det, t);
#endif
  return (pos | neg) & (*det != 0.0f) & (*t >= tmin) & (*t <= tmax);
}
#endif
#endif

/* How intersect_triangle_lanes is compiled: a plain inline function, which
 * PoCL keeps as a call (its float8 arguments passed through memory), or
 * always inlined where the kernel defines RTCL_INLINE_TRIANGLE_LANES (the
 * octrees, kernels/shared/octree.h, which trace faster inlined). */
#ifdef RTCL_INLINE_TRIANGLE_LANES
#define RTCL_TRIANGLE_LANES_INLINE RTCL_LANES_INLINE
#else
#define RTCL_TRIANGLE_LANES_INLINE inline
#endif

/* Eight triangles against the ray: lane l is the triangle with vertices
 * (a, b, c) given on the ray's permuted axes (kx, ky, kz): ax = a[kx], ...
 * Lanes with NaN vertices never hit. If one is hit in [tmin, h->t_best)
 * (at the exact level: beats h by exact_better), records the nearest in h
 * and returns 1. */
RTCL_TRIANGLE_LANES_INLINE int intersect_triangle_lanes(float8 ax, float8 ay, float8 az, float8 bx, float8 by, float8 bz, float8 cx,
                                    float8 cy, float8 cz, int8 prim, const TraceRay* s, HitState* h) {
#ifdef RTCL_PRECISION_FAST
  float8 t, u, v;
  int8 ok = rtcl_moller_trumbore8(ax, ay, az, bx, by, bz, cx, cy, cz, (float8)(s->okx), (float8)(s->oky),
                                  (float8)(s->okz), (float8)(s->dkx), (float8)(s->dky), (float8)(s->dkz),
                                  (float8)(s->tmin), (float8)(h->t_best), &t, &u, &v);
  if (!rtcl_any8(ok)) return 0;
  float8 t_ok = select((float8)(INFINITY), t, ok);
  float m = rtcl_min8(t_ok);
  int lane = rtcl_lane_of(t_ok, m);
  h->t_best = m;
  h->u = rtcl_lane(u, lane);
  h->v = rtcl_lane(v, lane);
  h->prim = rtcl_lane_i(prim, lane);
  return 1;
#else
  Watertight8 w = rtcl_watertight_edges8(ax, ay, az, bx, by, bz, cx, cy, cz, (float8)(s->okx), (float8)(s->oky),
                                         (float8)(s->okz), (float8)(s->sx), (float8)(s->sy));
#ifdef RTCL_PRECISION_EXACT
  int8 cand = rtcl_exact_triangle_candidates(w.Ax, w.Ay, w.Az, w.Bx, w.By, w.Bz, w.Cx, w.Cy, w.Cz, w.U, w.V, w.W,
                                             (float8)(s->sz), (float8)(s->tmin), (float8)(h->t_best));
  if (!rtcl_any8(cand)) return 0;
  float va[9][8];
  int c[8], p[8];
  vstore8(ax, 0, va[0]); vstore8(ay, 0, va[1]); vstore8(az, 0, va[2]);
  vstore8(bx, 0, va[3]); vstore8(by, 0, va[4]); vstore8(bz, 0, va[5]);
  vstore8(cx, 0, va[6]); vstore8(cy, 0, va[7]); vstore8(cz, 0, va[8]);
  vstore8(cand, 0, c);
  vstore8(prim, 0, p);
  int found = 0;
  for (int l = 0; l < 8; ++l) {
    if (!c[l]) continue;
    float u = 0.0f, v = 0.0f;
    double t = exact_triangle(va[0][l], va[1][l], va[2][l], va[3][l], va[4][l], va[5][l], va[6][l], va[7][l],
                              va[8][l], s->okx, s->oky, s->okz, s->shear_exact, &u, &v);
    if (!exact_better(t, p[l], h->t_exact, h->prim, s->tmin, s->tmax)) continue;
    h->t_exact = t;
    h->t_best = convert_float_rtp(t);
    h->u = u;
    h->v = v;
    h->prim = p[l];
    found = 1;
  }
  return found;
#else
  /* any hit: no division when no lane is inside its edges (closest hit
   * is faster without the branch) */
  if (RTCL_ANY_HIT && !rtcl_any8(rtcl_watertight_inside8(&w))) return 0;
  float8 t, det;
  int8 ok = rtcl_watertight_hit8(&w, (float8)(s->sz), (float8)(s->tmin), (float8)(h->t_best), &t, &det);
  if (!rtcl_any8(ok)) return 0;
  float8 t_ok = select((float8)(INFINITY), t, ok);
  float m = rtcl_min8_ordered(t_ok);
  int lane = rtcl_lane_of(t_ok, m);
  float inv_det = 1.0f / rtcl_lane(det, lane);
  h->t_best = m;
  h->u = rtcl_lane(w.V, lane) * inv_det;
  h->v = rtcl_lane(w.W, lane) * inv_det;
  h->prim = rtcl_lane_i(prim, lane);
  return 1;
#endif
#endif
}

/* A block of eight triangles (v[vertex][axis][lane] rows: row 3*vertex+axis).
 * Always inlined where the kernel defines RTCL_INLINE_TRIANGLE_BLOCK (the
 * BVH, kernels/accel/bvh.cl; not the octrees, which trace slower with
 * it). */
#ifdef RTCL_INLINE_TRIANGLE_BLOCK
RTCL_LANES_INLINE
#else
inline
#endif
int intersect_triangles8(global const TriangleBlock* block, const TraceRay* s, HitState* h) {
  global const float* v = &block->v[0][0][0];
  return intersect_triangle_lanes(vload8(s->kx, v), vload8(s->ky, v), vload8(s->kz, v), vload8(3 + s->kx, v),
                                  vload8(3 + s->ky, v), vload8(3 + s->kz, v), vload8(6 + s->kx, v),
                                  vload8(6 + s->ky, v), vload8(6 + s->kz, v), vload8(0, block->prim), s, h);
}

/* A run of up to eight triangles stored as lanes: row 3 * vertex + axis of
 * `lanes` (rows `stride` floats apart) and `prims` hold, from position
 * `first` on, count <= 8 triangles' coordinates and ids (GridHeader
 * contract); lanes past count are replaced by NaN and never hit. Contiguous
 * float8 loads, the arithmetic of a block: the same closest t, bit for
 * bit. */
inline int intersect_triangle_run(global const float* lanes, int stride, global const int* prims, uint first,
                                  int count, const TraceRay* s, HitState* h) {
  const int8 used = (int8)(0, 1, 2, 3, 4, 5, 6, 7) < (int8)(count);
  global const float* p = lanes + first;
#define RTCL_RUN_ROW(VERTEX, AXIS) select((float8)(NAN), vload8(0, p + (3 * (VERTEX) + (AXIS)) * stride), used)
  const int found = intersect_triangle_lanes(RTCL_RUN_ROW(0, s->kx), RTCL_RUN_ROW(0, s->ky), RTCL_RUN_ROW(0, s->kz),
                                             RTCL_RUN_ROW(1, s->kx), RTCL_RUN_ROW(1, s->ky), RTCL_RUN_ROW(1, s->kz),
                                             RTCL_RUN_ROW(2, s->kx), RTCL_RUN_ROW(2, s->ky), RTCL_RUN_ROW(2, s->kz),
                                             select((int8)(-1), vload8(0, prims + first), used), s, h);
#undef RTCL_RUN_ROW
  return found;
}

/* Up to eight referenced triangles: refs[0 .. count) index the triangles of
 * an id-ordered block array (reference r is lane r & 7 of block r >> 3, as
 * make_primitive_blocks_in_order lays them out); count <= 8. Lanes past
 * count are NaN and never hit. The same arithmetic as a block: the same
 * closest t, bit for bit. */
inline int intersect_triangle_refs(global const TriangleBlock* blocks, const int* refs, int count,
                                   const TraceRay* s, HitState* h) {
  /* Lanes are gathered straight into float8 values (no private staging
   * array: PoCL then keeps them in registers); lanes past count re-read
   * reference 0 and are replaced by NaN. */
  const int8 used = (int8)(0, 1, 2, 3, 4, 5, 6, 7) < (int8)(count);
  const int8 r = (int8)(refs[0], count > 1 ? refs[1] : refs[0], count > 2 ? refs[2] : refs[0],
                        count > 3 ? refs[3] : refs[0], count > 4 ? refs[4] : refs[0], count > 5 ? refs[5] : refs[0],
                        count > 6 ? refs[6] : refs[0], count > 7 ? refs[7] : refs[0]);
  const int8 at = (r >> 3) * (int)(sizeof(TriangleBlock) / sizeof(float)) + (r & 7);
  global const float* base = (global const float*)blocks;
#define RTCL_GATHER8(P) (P)[at.s0], (P)[at.s1], (P)[at.s2], (P)[at.s3], (P)[at.s4], (P)[at.s5], (P)[at.s6], (P)[at.s7]
#define RTCL_VERTEX_AXIS(J, K) \
  select((float8)(NAN), (float8)(RTCL_GATHER8(base + (3 * (J) + (K)) * RTCL_BLOCK_WIDTH)), used)
  const int8 prim = select((int8)(-1), (int8)(RTCL_GATHER8((global const int*)base + 9 * RTCL_BLOCK_WIDTH)), used);
  const int found = intersect_triangle_lanes(RTCL_VERTEX_AXIS(0, s->kx), RTCL_VERTEX_AXIS(0, s->ky),
                                             RTCL_VERTEX_AXIS(0, s->kz), RTCL_VERTEX_AXIS(1, s->kx),
                                             RTCL_VERTEX_AXIS(1, s->ky), RTCL_VERTEX_AXIS(1, s->kz),
                                             RTCL_VERTEX_AXIS(2, s->kx), RTCL_VERTEX_AXIS(2, s->ky),
                                             RTCL_VERTEX_AXIS(2, s->kz), prim, s, h);
#undef RTCL_VERTEX_AXIS
#undef RTCL_GATHER8
  return found;
}

#endif
