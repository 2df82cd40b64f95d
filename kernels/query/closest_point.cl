/* Closest point on the surface to each query point (Accel::closest_points),
 * over the plain 8-wide BVH (bvh, bvh-ploc, bvh-packet: Bvh8Node nodes,
 * TriangleBlock and SphereBlock leaves, shared/layouts.h). One point per
 * work-item.
 *
 * Traversal: the squared distances from the point to a node's eight child
 * boxes are computed in float8 lanes; the children within the best squared
 * distance so far (at first max_distance^2) are pushed sorted by that
 * distance, the nearest taken next (shared/bvh8_stack.h, the same push as
 * the ray traversal of kernels/accel/bvh.cl, so the structure's
 * RTCL_STACK_SIZE bounds this stack too), and an entry popped farther than
 * the best so far is skipped.
 *
 * Conservative pruning: each per-axis gap max(lo - p, p - hi, 0) is one
 * float subtraction (relative error <= 2^-24), then three squares and two
 * sums: the float box distance^2 is within 4 * 2^-24 of the true one,
 * relatively. It is shrunk by RTCL_CP_BOX_SHRINK (2^-18, 64x that bound)
 * before the comparison, so rounding never prunes a box holding a nearer
 * primitive. A box at distance 0 (the point inside or on it) is never
 * pruned, so every primitive at distance 0 is met: exact ties at a shared
 * vertex go to the smallest id.
 *
 * Point-triangle: Ericson, Real-Time Collision Detection (2005) 5.1.5, the
 * Voronoi regions of the vertices, edges and face, evaluated for the eight
 * lanes of a leaf at once and merged with selects (priority as in the
 * book's early returns). A vertex region yields the vertex itself, so a
 * point's distance to a shared vertex is bit-identical from every triangle
 * using it. Point-sphere: centre + r * unit(p - c), distance |(|p - c| - r)|;
 * a point at the centre takes centre + (r, 0, 0).
 *
 * Ties: a primitive replaces the best so far when its squared distance is
 * smaller, or equal with a smaller id. NaN lanes (unused lanes of a block)
 * never compare true, so they never win. */
#include "shared/bvh8_stack.h"
#include "shared/ray.h"

#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

#define RTCL_CP_BOX_SHRINK (1.0f - 0x1p-18f)
#define RTCL_CP_NO_PRIM 0x7fffffff

typedef struct ClosestState {
  float best_d2; /* squared distance of the best so far (or the radius^2, widened) */
  float x, y, z, u, v;
  int prim; /* RTCL_CP_NO_PRIM: none yet */
} ClosestState;

/* Takes lane candidates (d2, q, u, v, prim) into c where they beat it. */
inline void cp_take_lanes(float8 d2, float8 qx, float8 qy, float8 qz, float8 u, float8 v, int8 prim,
                          ClosestState* c) {
  int8 better = (d2 <= (float8)(c->best_d2));
  if (!rtcl_any8(better)) return;
  float a_d2[8], a_x[8], a_y[8], a_z[8], a_u[8], a_v[8];
  int a_p[8];
  vstore8(d2, 0, a_d2);
  vstore8(qx, 0, a_x);
  vstore8(qy, 0, a_y);
  vstore8(qz, 0, a_z);
  vstore8(u, 0, a_u);
  vstore8(v, 0, a_v);
  vstore8(prim, 0, a_p);
  for (int l = 0; l < 8; ++l) {
    float d = a_d2[l];
    if (d < c->best_d2 || (d == c->best_d2 && a_p[l] < c->prim && a_p[l] >= 0)) {
      c->best_d2 = d;
      c->x = a_x[l];
      c->y = a_y[l];
      c->z = a_z[l];
      c->u = a_u[l];
      c->v = a_v[l];
      c->prim = a_p[l];
    }
  }
}

/* Ericson 5.1.5 for the eight triangles of a block; u, v weight v1, v2 as
 * in Hit (point = (1-u-v) v0 + u v1 + v v2). */
inline void cp_triangles8(global const TriangleBlock* block, float px, float py, float pz, ClosestState* c) {
  float8 ax = vload8(0, block->v[0][0]), ay = vload8(0, block->v[0][1]), az = vload8(0, block->v[0][2]);
  float8 bx = vload8(0, block->v[1][0]), by = vload8(0, block->v[1][1]), bz = vload8(0, block->v[1][2]);
  float8 cx = vload8(0, block->v[2][0]), cy = vload8(0, block->v[2][1]), cz = vload8(0, block->v[2][2]);
  float8 abx = bx - ax, aby = by - ay, abz = bz - az;
  float8 acx = cx - ax, acy = cy - ay, acz = cz - az;
  float8 apx = (float8)(px) - ax, apy = (float8)(py) - ay, apz = (float8)(pz) - az;
  float8 bpx = (float8)(px) - bx, bpy = (float8)(py) - by, bpz = (float8)(pz) - bz;
  float8 cpx = (float8)(px) - cx, cpy = (float8)(py) - cy, cpz = (float8)(pz) - cz;
  float8 d1 = abx * apx + aby * apy + abz * apz, d2 = acx * apx + acy * apy + acz * apz;
  float8 d3 = abx * bpx + aby * bpy + abz * bpz, d4 = acx * bpx + acy * bpy + acz * bpz;
  float8 d5 = abx * cpx + aby * cpy + abz * cpz, d6 = acx * cpx + acy * cpy + acz * cpz;
  float8 vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;

  /* Regions from the last of the book's cases to the first, each select
   * overriding the ones after it. Face: */
  float8 denom = 1.0f / (va + vb + vc);
  float8 u = vb * denom, v = vc * denom;
  /* edge bc: q = b + w (c - b) */
  float8 e43 = d4 - d3, e56 = d5 - d6;
  int8 on_bc = (va <= 0.0f) & (e43 >= 0.0f) & (e56 >= 0.0f);
  float8 w_bc = e43 / (e43 + e56);
  /* edge ac */
  int8 on_ac = (vb <= 0.0f) & (d2 >= 0.0f) & (d6 <= 0.0f);
  float8 w_ac = d2 / (d2 - d6);
  /* vertex c */
  int8 at_c = (d6 >= 0.0f) & (d5 <= d6);
  /* edge ab */
  int8 on_ab = (vc <= 0.0f) & (d1 >= 0.0f) & (d3 <= 0.0f);
  float8 v_ab = d1 / (d1 - d3);
  /* vertex b, vertex a */
  int8 at_b = (d3 >= 0.0f) & (d4 <= d3);
  int8 at_a = (d1 <= 0.0f) & (d2 <= 0.0f);

  u = select(u, 1.0f - w_bc, on_bc);
  v = select(v, w_bc, on_bc);
  u = select(u, (float8)(0.0f), on_ac);
  v = select(v, w_ac, on_ac);
  u = select(u, (float8)(0.0f), at_c);
  v = select(v, (float8)(1.0f), at_c);
  u = select(u, v_ab, on_ab);
  v = select(v, (float8)(0.0f), on_ab);
  u = select(u, (float8)(1.0f), at_b);
  v = select(v, (float8)(0.0f), at_b);
  u = select(u, (float8)(0.0f), at_a);
  v = select(v, (float8)(0.0f), at_a);

  /* q: from a (face, edges ab and ac), from b (edge bc), or the vertex
   * itself (exact). */
  int8 from_b = on_bc & ~(on_ac | at_c | on_ab | at_b | at_a);
  float8 qx = select(ax + abx * u + acx * v, bx + (cx - bx) * v, from_b);
  float8 qy = select(ay + aby * u + acy * v, by + (cy - by) * v, from_b);
  float8 qz = select(az + abz * u + acz * v, bz + (cz - bz) * v, from_b);
  int8 vc_only = at_c & ~(on_ab | at_b | at_a);
  qx = select(qx, cx, vc_only);
  qy = select(qy, cy, vc_only);
  qz = select(qz, cz, vc_only);
  int8 vb_only = at_b & ~at_a;
  qx = select(qx, bx, vb_only);
  qy = select(qy, by, vb_only);
  qz = select(qz, bz, vb_only);
  qx = select(qx, ax, at_a);
  qy = select(qy, ay, at_a);
  qz = select(qz, az, at_a);

  float8 dx = (float8)(px) - qx, dy = (float8)(py) - qy, dz = (float8)(pz) - qz;
  float8 dist2 = dx * dx + dy * dy + dz * dz;
  cp_take_lanes(dist2, qx, qy, qz, u, v, vload8(0, block->prim), c);
}

#ifdef RTCL_HAS_SPHERES
inline void cp_spheres8(global const SphereBlock* block, float px, float py, float pz, ClosestState* c) {
  float8 cx = vload8(0, block->cx), cy = vload8(0, block->cy), cz = vload8(0, block->cz);
  float8 r = vload8(0, block->r);
  float8 fx = (float8)(px) - cx, fy = (float8)(py) - cy, fz = (float8)(pz) - cz;
  float8 len = sqrt(fx * fx + fy * fy + fz * fz);
  int8 centre = (len == 0.0f);
  float8 s = r / len;
  float8 qx = select(cx + fx * s, cx + r, centre);
  float8 qy = select(cy + fy * s, cy, centre);
  float8 qz = select(cz + fz * s, cz, centre);
  float8 d = fabs(len - r);
  cp_take_lanes(d * d, qx, qy, qz, (float8)(0.0f), (float8)(0.0f), vload8(0, block->prim), c);
}
#endif

__attribute__((noinline)) void cp_traverse(float px, float py, float pz, ClosestState* c,
                                           global const Bvh8Node* nodes, global const TriangleBlock* triangles,
                                           global const SphereBlock* spheres) {
  int stack_ref[RTCL_STACK_SIZE];
  float stack_t[RTCL_STACK_SIZE]; /* shrunk box distance^2 of stack_ref's box */
  int sp = 0;
  int ref = 0;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      global const float8* rows = (global const float8*)node->bounds;
      float8 lx = rows[0], ly = rows[1], lz = rows[2], hx = rows[3], hy = rows[4], hz = rows[5];
      float8 gx = fmax(fmax(lx - (float8)(px), (float8)(px) - hx), (float8)(0.0f));
      float8 gy = fmax(fmax(ly - (float8)(py), (float8)(py) - hy), (float8)(0.0f));
      float8 gz = fmax(fmax(lz - (float8)(pz), (float8)(pz) - hz), (float8)(0.0f));
      float8 t_entry = (gx * gx + gy * gy + gz * gz) * RTCL_CP_BOX_SHRINK;
      /* lx <= hx: not an empty slot (lower +inf, upper -inf) */
      int8 hit = (t_entry <= (float8)(c->best_d2)) & (lx <= hx);
      if (rtcl_any8(hit)) {
        RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST
        ref = near_entry;
        continue;
      }
    } else {
      int leaf = ~ref;
#ifdef RTCL_HAS_SPHERES
      if (leaf & 1)
        cp_spheres8(spheres + (leaf >> 1), px, py, pz, c);
      else
#endif
        cp_triangles8(triangles + (leaf >> 1), px, py, pz, c);
    }
    do {
      if (sp == 0) return;
      --sp;
    } while (stack_t[sp] > c->best_d2);
    ref = stack_ref[sp];
  }
}

/* points: 3 floats per point. A point with a NaN or infinite coordinate
 * gets the miss record (the host-array path rejects such points before). */
kernel void closest_point_bvh(global const float* points, global PointHit* out, uint count, float max_distance,
                              global const Bvh8Node* nodes, global const TriangleBlock* triangles,
                              global const SphereBlock* spheres) {
  uint i = get_global_id(0);
  if (i >= count) return;
  float px = points[3 * (size_t)i], py = points[3 * (size_t)i + 1], pz = points[3 * (size_t)i + 2];
  ClosestState c;
  /* The radius^2 widened by 2^-20: a primitive at exactly max_distance is
   * not lost to the rounding of the square; the final test is on the
   * distance itself. */
  c.best_d2 = max_distance * max_distance * (1.0f + 0x1p-20f);
  c.prim = RTCL_CP_NO_PRIM;
  c.x = c.y = c.z = c.u = c.v = 0.0f;
  if (isfinite(px) && isfinite(py) && isfinite(pz)) cp_traverse(px, py, pz, &c, nodes, triangles, spheres);
  PointHit h;
  float d = sqrt(c.best_d2);
  if (c.prim == RTCL_CP_NO_PRIM || !(d <= max_distance)) {
    h.x = h.y = h.z = NAN;
    h.distance = INFINITY;
    h.u = h.v = 0.0f;
    h.prim = -1;
  } else {
    h.x = c.x;
    h.y = c.y;
    h.z = c.z;
    h.distance = d;
    h.u = c.u;
    h.v = c.v;
    h.prim = c.prim;
  }
  h.reserved = 0u;
  out[i] = h;
}
