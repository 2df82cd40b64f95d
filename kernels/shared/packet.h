/* Packets of 8 rays in float8 lanes, one lane per ray (Wald, Slusallek,
 * Benthin, Wagner 2001): the per-packet ray constants, the packet's hit
 * state and the per-lane primitive tests, shared by the packet kernels
 * (accel/bvh_packet.cl, accel/kdtree_packet.cl). Every lane runs the
 * single-ray tests' own lane-generic functions (rtcl_slabs8 of
 * shared/box.h, rtcl_watertight_edges8 / rtcl_watertight_hit8 /
 * rtcl_moller_trumbore8 of shared/triangle.h, rtcl_sphere_quadratic8 /
 * rtcl_sphere_roots8 of shared/sphere.h) with the packet's rays in the
 * lanes, and trace_ray_setup's setup, so closest-hit t is bit-identical to
 * them at every precision level. */
#ifndef RTCL_SHARED_PACKET_H
#define RTCL_SHARED_PACKET_H

#include "shared/trace.h"

/* Per-packet constants: the TraceRay of each lane, in float8/int8 lanes.
 * active: lanes with a traceable ray (trace_ray_setup's conditions). */
typedef struct TracePacket {
  float8 ox, oy, oz, tmin;
  float8 ix, iy, iz;
  int8 pos_x, pos_y, pos_z;  /* reciprocal direction >= 0: lower plane is the entry plane */
  int8 kx1, kx2, ky1, ky2, kz1, kz2; /* kx == 1, kx == 2, ... (axis permutation) */
  float8 sx, sy, sz;
  float8 okx, oky, okz;
  float8 dkx, dky, dkz; /* direction, permuted */
  float8 dx, dy, dz;
  float8 tmax;
  int8 active;
  /* every lane's permutation is (axis_x, axis_y, axis_z), or axis_x = -1
   * where they differ: the triangle tests then pick each vertex coordinate
   * once per packet */
  int axis_x, axis_y, axis_z;
} TracePacket;

/* Lane-wise a[k] for a per-lane axis index given as masks k == 1, k == 2. */
inline float8 rtcl_pick_axis(float8 x, float8 y, float8 z, int8 k1, int8 k2) {
  return select(select(x, y, k1), z, k2);
}

/* Eight Ray records as eight rows of eight floats, transposed into the
 * fields' lanes: out[f] lane l = field f of ray l. */
RTCL_LANES_INLINE void rtcl_transpose8(const float8 r[8], float8 out[8]) {
  const uint8 lo = (uint8)(0, 8, 1, 9, 4, 12, 5, 13), hi = (uint8)(2, 10, 3, 11, 6, 14, 7, 15);
  const uint8 lo2 = (uint8)(0, 1, 8, 9, 4, 5, 12, 13), hi2 = (uint8)(2, 3, 10, 11, 6, 7, 14, 15);
  const uint8 lo4 = (uint8)(0, 1, 2, 3, 8, 9, 10, 11), hi4 = (uint8)(4, 5, 6, 7, 12, 13, 14, 15);
  float8 a[8], b[8];
  for (int k = 0; k < 8; k += 2) {
    a[k] = shuffle2(r[k], r[k + 1], lo);
    a[k + 1] = shuffle2(r[k], r[k + 1], hi);
  }
  for (int k = 0; k < 8; k += 4) {
    b[k] = shuffle2(a[k], a[k + 2], lo2);      /* fields 0 | 4 of rays k .. k+3 */
    b[k + 1] = shuffle2(a[k], a[k + 2], hi2);  /* fields 1 | 5 */
    b[k + 2] = shuffle2(a[k + 1], a[k + 3], lo2); /* fields 2 | 6 */
    b[k + 3] = shuffle2(a[k + 1], a[k + 3], hi2); /* fields 3 | 7 */
  }
  for (int f = 0; f < 4; ++f) {
    out[f] = shuffle2(b[f], b[f + 4], lo4);
    out[f + 4] = shuffle2(b[f], b[f + 4], hi4);
  }
}

inline void packet_setup(global const Ray* rays, uint first, uint ray_count, TracePacket* p, float8* tmax) {
  float8 field[8]; /* ox, oy, oz, dx, dy, dz, tmin, tmax: the Ray layout */
  float8 row[8];
  for (int l = 0; l < 8; ++l) {
    uint i = first + (uint)l;
    if (i < ray_count) {
      row[l] = vload8(i, (global const float*)rays);
    } else { /* padding: an untraceable ray (zero direction) */
      row[l] = (float8)(0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, -1.0f);
    }
  }
  rtcl_transpose8(row, field);
  float8 ox = field[0], oy = field[1], oz = field[2];
  float8 dx = field[3], dy = field[4], dz = field[5];
  float8 tmin = field[6];
  *tmax = field[7];
  float8 ax = fabs(dx), ay = fabs(dy), az = fabs(dz);
  /* kz = dominant axis, ties as in trace_ray_setup */
  int8 kz = select(select((int8)(2), (int8)(1), ay > az), select((int8)(2), (int8)(0), ax > az), ax > ay);
  float8 adk = select(select(az, ay, kz == 1), ax, kz == 0);
  p->active = (adk > 0.0f) & rtcl_ray_valid8(ox, oy, oz, dx, dy, dz, tmin, *tmax);
  p->tmax = *tmax;
  int8 kx = select(kz + 1, (int8)(0), kz == 2);
  int8 ky = select(kx + 1, (int8)(0), kx == 2);
  float8 dkz = rtcl_pick_axis(dx, dy, dz, kz == 1, kz == 2);
  int8 flip = dkz < 0.0f;
  int8 tx = select(kx, ky, flip), ty = select(ky, kx, flip);
  p->kx1 = tx == 1; p->kx2 = tx == 2;
  p->ky1 = ty == 1; p->ky2 = ty == 2;
  p->kz1 = kz == 1; p->kz2 = kz == 2;
  int lx = tx.s0, ly = ty.s0, lz = kz.s0;
  int same = !rtcl_any8((tx != (int8)(lx)) | (ty != (int8)(ly)) | (kz != (int8)(lz)));
  p->axis_x = same ? lx : -1;
  p->axis_y = ly;
  p->axis_z = lz;
  p->ox = ox; p->oy = oy; p->oz = oz; p->tmin = tmin;
  p->dx = dx; p->dy = dy; p->dz = dz;
  p->ix = 1.0f / dx;
  p->iy = 1.0f / dy;
  p->iz = 1.0f / dz;
  p->pos_x = p->ix >= 0.0f;
  p->pos_y = p->iy >= 0.0f;
  p->pos_z = p->iz >= 0.0f;
  p->sz = 1.0f / dkz;
  p->sx = rtcl_pick_axis(dx, dy, dz, p->kx1, p->kx2) / dkz;
  p->sy = rtcl_pick_axis(dx, dy, dz, p->ky1, p->ky2) / dkz;
  p->okx = rtcl_pick_axis(ox, oy, oz, p->kx1, p->kx2);
  p->oky = rtcl_pick_axis(ox, oy, oz, p->ky1, p->ky2);
  p->okz = rtcl_pick_axis(ox, oy, oz, p->kz1, p->kz2);
  p->dkx = rtcl_pick_axis(dx, dy, dz, p->kx1, p->kx2);
  p->dky = rtcl_pick_axis(dx, dy, dz, p->ky1, p->ky2);
  p->dkz = dkz;
}

/* Closest-hit state of the packet, lane = ray: t_best (and at the exact
 * level t_exact) as in HitState; the winning edge functions are kept and
 * turned into (u, v) at the end, as intersect_triangle_lanes does for its
 * winner (fast and exact keep u, v themselves, with det = 1). */
typedef struct PacketHits {
  float8 t_best, det, V, W;
  int8 prim;
#ifdef RTCL_PRECISION_EXACT
  double t_exact[8];
#endif
} PacketHits;

/* No hit yet: t_best just above each ray's tmax, so that a hit at tmax counts. */
inline void packet_hits_init(PacketHits* h, float8 tmax) {
  h->t_best = rtcl_next_up8(tmax);
  h->det = (float8)(1.0f);
  h->V = h->W = (float8)(0.0f);
  h->prim = (int8)(-1);
#ifdef RTCL_PRECISION_EXACT
  for (int l = 0; l < 8; ++l) h->t_exact[l] = INFINITY;
#endif
}

/* Lane l as an int8 mask. */
inline int8 rtcl_lane_mask(int l) { return (int8)(0, 1, 2, 3, 4, 5, 6, 7) == (int8)(l); }

#ifdef RTCL_PRECISION_EXACT
/* Records a double-precision hit of lane l when it beats the lane's best
 * (exact_better). Returns 1 if it did. */
inline int packet_exact_record(PacketHits* h, int l, double t, int prim, float tmin, float tmax, float u, float v) {
  if (!exact_better(t, prim, h->t_exact[l], rtcl_lane_i(h->prim, l), tmin, tmax)) return 0;
  int8 m = rtcl_lane_mask(l);
  h->t_exact[l] = t;
  h->t_best = select(h->t_best, (float8)(convert_float_rtp(t)), m);
  h->det = select(h->det, (float8)(1.0f), m);
  h->V = select(h->V, (float8)(u), m);
  h->W = select(h->W, (float8)(v), m);
  h->prim = select(h->prim, (int8)(prim), m);
  return 1;
}
#endif

/* One triangle, broadcast to the packet's rays in `mask`: its coordinate
 * (vertex j, axis a) is at[(3 j + a) * stride] (a TriangleBlock's lane:
 * stride RTCL_BLOCK_WIDTH; a kd-tree reference lane: the lane stride), prim
 * its id. intersect_triangle_lanes's arithmetic per lane, so the same t
 * bit for bit. Returns the lanes it hits in [tmin, t_best) (exact: by
 * exact_better) and records those hits. */
inline int8 packet_triangle_at(global const float* at, int stride, int prim, const TracePacket* p, PacketHits* h,
                               int8 mask) {
  /* vertex j's coordinates on each ray's permuted axes */
  float8 v[3][3];
  if (p->axis_x >= 0) {
    for (int j = 0; j < 3; ++j) {
      v[j][0] = (float8)(at[(3 * j + p->axis_x) * stride]);
      v[j][1] = (float8)(at[(3 * j + p->axis_y) * stride]);
      v[j][2] = (float8)(at[(3 * j + p->axis_z) * stride]);
    }
  } else for (int j = 0; j < 3; ++j) {
    float8 x = (float8)(at[(3 * j) * stride]), y = (float8)(at[(3 * j + 1) * stride]), z = (float8)(at[(3 * j + 2) * stride]);
    v[j][0] = rtcl_pick_axis(x, y, z, p->kx1, p->kx2);
    v[j][1] = rtcl_pick_axis(x, y, z, p->ky1, p->ky2);
    v[j][2] = rtcl_pick_axis(x, y, z, p->kz1, p->kz2);
  }
#ifdef RTCL_PRECISION_FAST
  float8 t, u, w;
  int8 ok = mask & rtcl_moller_trumbore8(v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2], v[2][0], v[2][1],
                                         v[2][2], p->okx, p->oky, p->okz, p->dkx, p->dky, p->dkz, p->tmin,
                                         h->t_best, &t, &u, &w);
  if (!rtcl_any8(ok)) return ok;
  h->t_best = select(h->t_best, t, ok);
  h->det = select(h->det, (float8)(1.0f), ok);
  h->V = select(h->V, u, ok);
  h->W = select(h->W, w, ok);
  h->prim = select(h->prim, (int8)(prim), ok);
  return ok;
#else
  Watertight8 wt = rtcl_watertight_edges8(v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2], v[2][0], v[2][1],
                                          v[2][2], p->okx, p->oky, p->okz, p->sx, p->sy);
#ifdef RTCL_PRECISION_EXACT
  int8 cand = mask & rtcl_exact_triangle_candidates(wt.Ax, wt.Ay, wt.Az, wt.Bx, wt.By, wt.Bz, wt.Cx, wt.Cy, wt.Cz,
                                                    wt.U, wt.V, wt.W, p->sz, p->tmin, h->t_best);
  if (!rtcl_any8(cand)) return cand;
  int hit[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (int l = 0; l < 8; ++l) {
    if (!rtcl_lane_i(cand, l)) continue;
    float u = 0.0f, w = 0.0f;
    double t = exact_triangle(rtcl_lane(v[0][0], l), rtcl_lane(v[0][1], l), rtcl_lane(v[0][2], l),
                              rtcl_lane(v[1][0], l), rtcl_lane(v[1][1], l), rtcl_lane(v[1][2], l),
                              rtcl_lane(v[2][0], l), rtcl_lane(v[2][1], l), rtcl_lane(v[2][2], l),
                              rtcl_lane(p->okx, l), rtcl_lane(p->oky, l), rtcl_lane(p->okz, l),
                              exact_shear(rtcl_lane(p->dkx, l), rtcl_lane(p->dky, l), rtcl_lane(p->dkz, l)), &u, &w);
    hit[l] = -packet_exact_record(h, l, t, prim, rtcl_lane(p->tmin, l), rtcl_lane(p->tmax, l), u, w);
  }
  return vload8(0, hit);
#else
  /* most of a packet's triangle tests find no ray inside the edges: no division then */
  if (!rtcl_any8(mask & rtcl_watertight_inside8(&wt))) return (int8)(0);
  float8 t, det;
  int8 ok = mask & rtcl_watertight_hit8(&wt, p->sz, p->tmin, h->t_best, &t, &det);
  if (!rtcl_any8(ok)) return ok;
  h->t_best = select(h->t_best, t, ok);
  h->det = select(h->det, det, ok);
  h->V = select(h->V, wt.V, ok);
  h->W = select(h->W, wt.W, ok);
  h->prim = select(h->prim, (int8)(prim), ok);
  return ok;
#endif
#endif
}

#ifdef RTCL_HAS_SPHERES
/* Sphere k of a block against the packet: rtcl_sphere_quadratic8 and its
 * roots, intersect_sphere_lanes's arithmetic, per lane. */
inline int8 packet_sphere(global const SphereBlock* block, int k, const TracePacket* p, PacketHits* h, int8 mask) {
  float r = block->r[k];
  SphereQuadratic8 q = rtcl_sphere_quadratic8((float8)(block->cx[k]), (float8)(block->cy[k]), (float8)(block->cz[k]),
                                              (float8)(r), p->ox, p->oy, p->oz, p->dx, p->dy, p->dz);
#ifdef RTCL_PRECISION_EXACT
  int8 cand = mask & rtcl_sphere_candidates8(&q, (float8)(r));
  if (!rtcl_any8(cand)) return cand;
  int prim = block->prim[k];
  int hit[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (int l = 0; l < 8; ++l) {
    if (!rtcl_lane_i(cand, l)) continue;
    float tmin = rtcl_lane(p->tmin, l), tmax = rtcl_lane(p->tmax, l);
    double t = exact_sphere(block->cx[k], block->cy[k], block->cz[k], r, rtcl_lane(p->ox, l), rtcl_lane(p->oy, l),
                            rtcl_lane(p->oz, l), rtcl_lane(p->dx, l), rtcl_lane(p->dy, l), rtcl_lane(p->dz, l), tmin,
                            tmax);
    hit[l] = -packet_exact_record(h, l, t, prim, tmin, tmax, 0.0f, 0.0f);
  }
  return vload8(0, hit);
#else
  float8 tn, tf;
  int8 ok_n, ok_f;
  rtcl_sphere_roots8(&q, (float8)(r), p->tmin, h->t_best, &tn, &tf, &ok_n, &ok_f);
  float8 t = select(tf, tn, ok_n);
  int8 ok = mask & (ok_n | ok_f);
  if (!rtcl_any8(ok)) return ok;
  h->t_best = select(h->t_best, t, ok);
  h->det = select(h->det, (float8)(1.0f), ok);
  h->V = select(h->V, (float8)(0.0f), ok);
  h->W = select(h->W, (float8)(0.0f), ok);
  h->prim = select(h->prim, (int8)(block->prim[k]), ok);
  return ok;
#endif
}
#endif

/* Writes the packet's hits for its rays first .. first+7 below ray_count:
 * (u, v) from the winning edge functions, t = INFINITY on a miss; a full
 * packet as four float8 stores of the transposed records. */
inline void packet_store(const PacketHits* h, global Hit* hits, uint first, uint ray_count) {
  float8 id = 1.0f / h->det;
  float8 u = h->V * id, v = h->W * id;
#ifdef RTCL_PRECISION_EXACT
  float exact[8];
  for (int l = 0; l < 8; ++l) exact[l] = convert_float_rte(h->t_exact[l]);
  float8 t = vload8(0, exact);
#else
  float8 t = h->t_best;
#endif
  t = select(t, (float8)(INFINITY), h->prim < 0);
  float8 prim = as_float8(h->prim);
  /* Hit records (t, u, v, prim) of rays 0-1, 2-3, 4-5, 6-7 as float8 rows */
  const uint8 lo = (uint8)(0, 8, 1, 9, 2, 10, 3, 11), hi = (uint8)(4, 12, 5, 13, 6, 14, 7, 15);
  const uint8 lo2 = (uint8)(0, 1, 8, 9, 2, 3, 10, 11), hi2 = (uint8)(4, 5, 12, 13, 6, 7, 14, 15);
  float8 tu_lo = shuffle2(t, u, lo), vp_lo = shuffle2(v, prim, lo);
  float8 tu_hi = shuffle2(t, u, hi), vp_hi = shuffle2(v, prim, hi);
  float8 rows[4] = {shuffle2(tu_lo, vp_lo, lo2), shuffle2(tu_lo, vp_lo, hi2), shuffle2(tu_hi, vp_hi, lo2),
                    shuffle2(tu_hi, vp_hi, hi2)};
  global float* out = (global float*)(hits + first);
  if (first + 8u <= ray_count) {
    for (int k = 0; k < 4; ++k) vstore8(rows[k], k, out);
    return;
  }
  for (uint l = 0; l < 8u && first + l < ray_count; ++l) vstore4(l & 1 ? rows[l / 2].hi : rows[l / 2].lo, l, out);
}

/* The packet trace kernel of structure NAME: rays 8p .. 8p + 7 (those below
 * ray_count) form the packet of work-item p; NAME##_traverse(&packet, &hits,
 * ARGS) answers its active lanes (as RTCL_TRACE_KERNELS in shared/trace.h,
 * for packets). */
#define RTCL_PACKET_KERNELS(NAME, PARAMS, ARGS)                                                     \
  kernel void RTCL_TRACE_KERNEL_NAME(NAME)(global const Ray* rays, global Hit* hits, uint ray_count, \
                                           PARAMS) {                                                 \
    uint first = get_global_id(0) * 8u;                                                             \
    if (first >= ray_count) return;                                                                 \
    TracePacket p;                                                                                  \
    float8 tmax;                                                                                    \
    packet_setup(rays, first, ray_count, &p, &tmax);                                                \
    PacketHits h;                                                                                   \
    packet_hits_init(&h, tmax);                                                                     \
    if (rtcl_any8(p.active)) NAME##_traverse(&p, &h, ARGS);                                         \
    packet_store(&h, hits, first, ray_count);                                                       \
  }

/* RTCL_PACKET_KERNELS with occluder runs (as RTCL_TRACE_KERNELS_OCCLUDER_CACHE
 * in shared/trace.h, for packets): NAME##_traverse returns the last leaf
 * that blocked rays of the packet (-1: none, and always at closest hit) and
 * NAME##_leaf(code, &packet, &hits, ARGS) tests one leaf against the
 * packet's active rays, returning those it blocked. The any-hit kernel
 * traces a run of ceil(packets / global size) consecutive packets per
 * work-item, each first against the leaf that blocked rays of the previous
 * packet of the run; the rays it blocks leave the packet before the
 * traversal, which is skipped when none is left. Its closest-hit kernel is
 * RTCL_PACKET_KERNELS's. */
#ifdef RTCL_QUERY_ANY
#define RTCL_PACKET_KERNELS_OCCLUDER_CACHE(NAME, PARAMS, ARGS)                                        \
  kernel void trace_any_##NAME(global const Ray* rays, global Hit* hits, uint ray_count, PARAMS) {     \
    ulong packets = ((ulong)ray_count + 7) / 8;                                                        \
    ulong run = (packets + get_global_size(0) - 1) / get_global_size(0);                              \
    ulong first_packet = get_global_id(0) * run;                                                       \
    ulong end = min(first_packet + run, packets);                                                      \
    int occluder = -1;                                                                                 \
    for (ulong k = first_packet; k < end; ++k) {                                                       \
      uint first = (uint)(k * 8);                                                                      \
      TracePacket p;                                                                                   \
      float8 tmax;                                                                                     \
      packet_setup(rays, first, ray_count, &p, &tmax);                                                 \
      PacketHits h;                                                                                    \
      packet_hits_init(&h, tmax);                                                                      \
      int8 cached = (int8)(0);                                                                         \
      if (occluder >= 0 && rtcl_any8(p.active)) {                                                      \
        cached = NAME##_leaf(occluder, &p, &h, ARGS);                                                  \
        p.active &= ~cached;                                                                           \
      }                                                                                                \
      if (rtcl_any8(p.active)) {                                                                       \
        int blocked = NAME##_traverse(&p, &h, ARGS);                                                   \
        if (blocked >= 0 || !rtcl_any8(cached)) occluder = blocked;                                    \
      }                                                                                                \
      packet_store(&h, hits, first, ray_count);                                                        \
    }                                                                                                  \
  }
#else
#define RTCL_PACKET_KERNELS_OCCLUDER_CACHE RTCL_PACKET_KERNELS
#endif

#endif
