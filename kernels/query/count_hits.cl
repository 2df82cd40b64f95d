/* Every crossing of a ray with the surface, on the plain 8-wide BVH
 * (Bvh8Node / TriangleBlock / SphereBlock: bvh, bvh-ploc, bvh-packet;
 * src/rtcl/query/count_hits.cpp): count_hits_bvh counts them,
 * list_hits_bvh lists the nearest ones of each ray, sorted.
 *
 * Precision: always the robust level's watertight triangle test (Woop,
 * Benthin, Wald 2013; zero edge values re-tested in double where the device
 * has fp64) with the crossing fill rule of shared/triangle.h
 * (rtcl_crossing_hit8), whatever the structure's level: the host builds
 * this file at the robust level (detail::AccelAccess::kernel's `level`).
 * The fast level's Moller-Trumbore test is not watertight and its
 * -cl-fast-relaxed-math may contract or reassociate the edge functions, so
 * shared edges could count 0 or 2; the exact level's double re-test
 * decides each triangle alone, without a rule for ties. t is the robust
 * level's float t.
 *
 * A crossing: a triangle hit by that rule, or a sphere root, with t in
 * [tmin, tmax]; a ray tangent to a sphere crosses it twice at one t.
 * Invalid rays (shared/ray.h) have none. Traversal visits every child box
 * the ray meets within [tmin, tmax] (the robust level's widened slabs), in
 * lane order: the stack's bound is the BVH's RTCL_STACK_SIZE (each node
 * pushes at most its children and pops one). */
#define RTCL_CROSSINGS
#include "shared/box.h"
#include "shared/sphere.h"
#include "shared/triangle.h"

#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

/* Whether hit a comes before hit b: nearer, or as near with the smaller
 * primitive id. */
inline int hit_before(Hit a, Hit b) { return a.t < b.t || (a.t == b.t && a.prim < b.prim); }

/* Inserts h into the sorted list seg[0 .. *n) of capacity cap >= 1; when
 * full, the last (farthest) entry drops out, or h itself if it is not
 * before it. */
inline void list_insert(global Hit* seg, uint cap, uint* n, Hit h) {
  uint j = *n;
  if (j == cap) {
    if (!hit_before(h, seg[cap - 1])) return;
    j = cap - 1;
  } else {
    ++*n;
  }
  while (j > 0 && hit_before(h, seg[j - 1])) {
    seg[j] = seg[j - 1];
    --j;
  }
  seg[j] = h;
}

/* Triangle block `block` against the ray: the crossing lanes as bits. */
inline int crossing_bits_triangles8(global const TriangleBlock* block, const TraceRay* s, float8* t, float8* det,
                                    Watertight8* w) {
  global const float* v = &block->v[0][0][0];
  *w = rtcl_watertight_edges8(vload8(s->kx, v), vload8(s->ky, v), vload8(s->kz, v), vload8(3 + s->kx, v),
                              vload8(3 + s->ky, v), vload8(3 + s->kz, v), vload8(6 + s->kx, v),
                              vload8(6 + s->ky, v), vload8(6 + s->kz, v), (float8)(s->okx), (float8)(s->oky),
                              (float8)(s->okz), (float8)(s->sx), (float8)(s->sy));
  return rtcl_lane_bits8(rtcl_crossing_hit8(w, (float8)(s->sz), (float8)(s->tmin), (float8)(s->tmax), t, det));
}

/* Counts the crossings of the ray; with seg != 0 also keeps the nearest
 * cap of them in seg (sorted, hit_before). Returns the count. */
__attribute__((noinline)) uint crossings_traverse(const TraceRay* s, global Hit* seg, uint cap,
                                                  global const Bvh8Node* nodes,
                                                  global const TriangleBlock* triangles,
                                                  global const SphereBlock* spheres) {
  int stack[RTCL_STACK_SIZE];
  int sp = 0;
  uint count = 0, listed = 0;
  int ref = 0;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      float8 t_entry;
      int8 hit = intersect_boxes8(node, s, s->tmax, &t_entry);
#define COUNT_HITS_PUSH(k) \
  if (hit.s##k) stack[sp++] = node->child[k];
      COUNT_HITS_PUSH(0) COUNT_HITS_PUSH(1) COUNT_HITS_PUSH(2) COUNT_HITS_PUSH(3)
      COUNT_HITS_PUSH(4) COUNT_HITS_PUSH(5) COUNT_HITS_PUSH(6) COUNT_HITS_PUSH(7)
#undef COUNT_HITS_PUSH
    } else {
      int leaf = ~ref;
#ifdef RTCL_HAS_SPHERES
      if (leaf & 1) {
        global const SphereBlock* block = spheres + (leaf >> 1);
        float8 r = vload8(0, block->r);
        SphereQuadratic8 q = rtcl_sphere_quadratic8(vload8(0, block->cx), vload8(0, block->cy),
                                                    vload8(0, block->cz), r, (float8)(s->ox), (float8)(s->oy),
                                                    (float8)(s->oz), (float8)(s->dx), (float8)(s->dy),
                                                    (float8)(s->dz));
        float8 tn, tf;
        int8 ok_n, ok_f;
        rtcl_sphere_roots8(&q, r, (float8)(s->tmin), (float8)(rtcl_next_up(s->tmax)), &tn, &tf, &ok_n, &ok_f);
        int bits_n = rtcl_lane_bits8(ok_n), bits_f = rtcl_lane_bits8(ok_f);
        count += popcount(bits_n) + popcount(bits_f);
        if (seg && (bits_n | bits_f)) {
          float tn_l[8], tf_l[8];
          vstore8(tn, 0, tn_l);
          vstore8(tf, 0, tf_l);
          for (int l = 0; l < 8; ++l) {
            Hit h = {0.0f, 0.0f, 0.0f, block->prim[l]};
            if (bits_n & (1 << l)) {
              h.t = tn_l[l];
              list_insert(seg, cap, &listed, h);
            }
            if (bits_f & (1 << l)) {
              h.t = tf_l[l];
              list_insert(seg, cap, &listed, h);
            }
          }
        }
      } else
#endif
      {
        global const TriangleBlock* block = triangles + (leaf >> 1);
        float8 t, det;
        Watertight8 w;
        int bits = crossing_bits_triangles8(block, s, &t, &det, &w);
        count += popcount(bits);
        if (seg && bits) {
          float t_l[8], u_l[8], v_l[8];
          vstore8(t, 0, t_l);
          vstore8(w.V / det, 0, u_l);
          vstore8(w.W / det, 0, v_l);
          for (int l = 0; l < 8; ++l) {
            if (!(bits & (1 << l))) continue;
            Hit h = {t_l[l], u_l[l], v_l[l], block->prim[l]};
            list_insert(seg, cap, &listed, h);
          }
        }
      }
    }
    if (sp == 0) return count;
    ref = stack[--sp];
  }
}

#define COUNT_HITS_BVH_PARAMS \
  global const Bvh8Node *nodes, global const TriangleBlock *triangles, global const SphereBlock *spheres

/* counts[i] = the crossings of rays[i], i < ray_count. */
kernel void count_hits_bvh(global const Ray* rays, global uint* counts, uint ray_count, COUNT_HITS_BVH_PARAMS) {
  uint i = get_global_id(0);
  if (i >= ray_count) return;
  TraceRay s;
  uint n = 0;
  if (trace_ray_setup(rays[i], &s)) n = crossings_traverse(&s, 0, 0, nodes, triangles, spheres);
  counts[i] = n;
}

/* The nearest offsets[i + 1] - offsets[i] crossings of rays[i], sorted
 * (hit_before), into hits[offsets[i] ..), i < ray_count. A segment longer
 * than the ray's count (never, after count_hits_bvh's count) keeps its
 * tail unwritten. */
kernel void list_hits_bvh(global const Ray* rays, global const uint* offsets, global Hit* hits, uint ray_count,
                          COUNT_HITS_BVH_PARAMS) {
  uint i = get_global_id(0);
  if (i >= ray_count) return;
  uint first = offsets[i], cap = offsets[i + 1] - first;
  TraceRay s;
  if (cap > 0 && trace_ray_setup(rays[i], &s)) crossings_traverse(&s, hits + first, cap, nodes, triangles, spheres);
}
