/* BSP and kd-tree traversal, one ray per work-item: the lecture's
 * RayTreeIntersect(Ray, Node, min, max) (空间二分树, "Traversal in BSP
 * Tree") with an explicit stack in place of the recursion, several tree
 * levels per step. Both structures (src/rtcl/accel/bsp.cpp: midpoint
 * splits; kdtree.cpp: SAH splits) build the same nodes (KdNode,
 * kernels/shared/layouts.h), so this one file is the kernel of both:
 * trace_closest_kdtree / trace_any_kdtree.
 *
 * The recursion gives each node the ray's interval [min, max] inside the
 * node's cell: the root's is [tmin, tmax] clipped to the root box, and a
 * child's is its parent's cut at the plane's dist = (split - o) / d (near
 * over [min, dist], far over [dist, max]). That is the ray's interval
 * inside the child's box, whose faces are the planes of its path and the
 * root box. Here a step takes several levels at once: the host cuts the
 * tree into subtrees of up to eight cells each (kd nodes whose cells tile
 * the subtree root's cell), stored as a Bvh8Node (src/rtcl/accel/
 * kdtree_fused.cpp; a lane's box is its cell shrunk to what the cell
 * holds, which only narrows the interval to where a hit can lie), and the
 * eight cells' [min, max] are the slab test of their boxes in float8 lanes
 * against [tmin, t_best] (intersect_boxes8, shared/box.h). The cells entered are
 * pushed sorted by min, the nearest on top, so cells are visited front to
 * back as the recursion visits near before far.
 * Special cases, by the slab arithmetic of shared/box.h:
 *   - a zero direction component: the reciprocal is ±inf, the distances to
 *     a box's faces on that axis ±inf, so the origin decides (its side of
 *     every plane on that axis for the whole interval);
 *   - an origin on a plane, a ray lying in a plane (0 * inf = NaN, which
 *     the fmin/fmax chain drops): the closed boxes on both sides are
 *     entered; dist exactly at min or max: both cells;
 *   - the interval is widened by RTCL_SLAB_WIDEN (relative), which covers
 *     the rounding of the distances and of the hit's t. The fast level
 *     (-cl-fast-relaxed-math) tests the slabs of zero components by the
 *     origin alone (kd_enter_cells8).
 * Empty leaves (the SAH's cut-off empty space) are no cell at all.
 *
 * Leaves: the triangles are tested from the reference lanes (KdNode) in
 * contiguous runs of up to eight (intersect_triangle_run: float8 loads, no
 * gather; sphere positions are NaN and never hit), the spheres gathered by
 * reference in batches of eight (intersect_sphere_refs): the arithmetic of
 * brute force, so the same t bit for bit. The closest hit so far stays a
 * candidate even when it lies beyond the leaf's interval (a primitive
 * extending into later leaves is then not closer when met again). Early
 * exit: a cell is neither entered nor, when popped, visited once its min
 * lies beyond the closest hit; the walk ends when no cell is left (the
 * lecture's exit once the hit lies inside the current interval). Any hit
 * ends at the first hit.
 *
 * Stack bound (RTCL_KD_CELL_STACK, compile-time, kKdCellStack of
 * src/rtcl/accel/kdtree_fused.hpp): a step pushes at most eight cells and
 * the walk pops one to go on, so each fused ancestor of the node walked
 * keeps at most 7 entries; a fused node below the root spans at least two
 * kd levels, so a tree of depth D has at most max(1, D) fused levels, and
 * the host refuses trees deeper than kKdMaxDepth
 * (src/rtcl/accel/kdtree_nodes.cpp), so the stack holds at most
 * 7 kKdMaxDepth + 1 entries. */
#include "shared/bvh8_stack.h"
#include "shared/trace.h"

#ifndef RTCL_KD_CELL_STACK
#error "RTCL_KD_CELL_STACK (the stack bound of the deepest tree) must be defined"
#endif

/* Tests a leaf's references refs[first .. end) (triangles, then spheres as
 * ~r): the triangles' lanes in runs of eight, the spheres in batches of
 * eight. Returns 1 when a hit ends an any-hit query. */
inline int kd_test_leaf(global const int* refs, uint first, uint end, global const float* lanes, int lane_stride,
                        global const int* lane_prims, global const SphereBlock* spheres, const TraceRay* s,
                        HitState* h) {
  for (uint k = first; k < end; k += 8)
    if (intersect_triangle_run(lanes, lane_stride, lane_prims, k, (int)min(end - k, 8u), s, h) && RTCL_ANY_HIT)
      return 1;
#ifdef RTCL_HAS_SPHERES
  int batch[8];
  int count = 0;
  uint k = first;
  while (k < end && refs[k] >= 0) ++k;
  for (; k < end; ++k) {
    batch[count++] = ~refs[k];
    if (count == 8 || k + 1 == end) {
      if (intersect_sphere_refs(spheres, batch, count, s, h) && RTCL_ANY_HIT) return 1;
      count = 0;
    }
  }
#endif
  return 0;
}

/* The cells of a fused node the ray enters over [tmin, tmax] (lane = -1)
 * and their entry distances. At the robust and exact levels, the slab test
 * of box.h, whose fmin/fmax chain drops the NaN of (b - o) * inf for an
 * origin on a face of a zero direction component. The fast level is
 * compiled with -cl-fast-relaxed-math: the compiler may assume no NaN or
 * inf (and the reciprocal of ±0 may come out NaN), so there an axis the ray
 * does not move along only asks whether the origin lies in the slab; and
 * the interval is widened as at the other levels, since a cell's box may be
 * flat (a leaf of a flat scene) and a ray grazing it must still enter. */
inline int8 kd_enter_cells8(global const Bvh8Node* node, const TraceRay* s, float tmax, float8* t_entry) {
#ifdef RTCL_PRECISION_FAST
  global const float8* b = (global const float8*)node->bounds;
  float8 tn = (float8)(s->tmin), tf = (float8)(tmax);
  int8 inside = (int8)(-1);
#define KD_FAST_AXIS(A, O, D, I, NEAR, FAR)                                \
  if (D == 0.0f) {                                                         \
    inside &= b[A] <= (float8)(O) & (float8)(O) <= b[3 + (A)];             \
  } else {                                                                 \
    tn = rtcl_fmax8((b[NEAR] - (float8)(O)) * (float8)(I), tn);           \
    tf = rtcl_fmin8((b[FAR] - (float8)(O)) * (float8)(I), tf);            \
  }
  KD_FAST_AXIS(0, s->ox, s->dx, s->ix, s->near_x, s->far_x)
  KD_FAST_AXIS(1, s->oy, s->dy, s->iy, s->near_y, s->far_y)
  KD_FAST_AXIS(2, s->oz, s->dz, s->iz, s->near_z, s->far_z)
#undef KD_FAST_AXIS
  tn -= fabs(tn) * RTCL_SLAB_WIDEN;
  tf += fabs(tf) * RTCL_SLAB_WIDEN;
  *t_entry = tn;
  return inside & (tn <= tf);
#else
  return intersect_boxes8(node, s, tmax, t_entry);
#endif
}

/* Returns the leaf (its index in nodes) that ended an any-hit traversal,
 * else -1. */
__attribute__((noinline)) int kdtree_traverse(const TraceRay* s, HitState* h, global const KdHeader* header,
                                               global const KdNode* nodes, global const Bvh8Node* fused,
                                               global const int* refs, global const float* lanes,
                                               global const int* lane_prims, global const SphereBlock* spheres) {
  const int lane_stride = header->lane_stride;
  int stack_ref[RTCL_KD_CELL_STACK];
  float stack_t[RTCL_KD_CELL_STACK]; /* the cell's min */
  int sp = 0;
  int ref = 0;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = fused + ref;
      float8 t_entry;
      int8 hit = kd_enter_cells8(node, s, h->t_best, &t_entry);
      if (rtcl_any8(hit)) {
        RTCL_BVH8_PUSH_CHILDREN
      }
    } else {
      KdNode leaf = nodes[~ref];
      uint first = leaf.flags >> 2;
      if (kd_test_leaf(refs, first, first + leaf.data, lanes, lane_stride, lane_prims, spheres, s, h)) return ~ref;
    }
    do {
      if (sp == 0) return -1;
      --sp;
    } while (!RTCL_ANY_HIT && stack_t[sp] > h->t_best);
    ref = stack_ref[sp];
  }
}

#define KD_PARAMS                                                                                         \
  global const KdHeader *header, global const KdNode *nodes, global const Bvh8Node *fused, global const int *refs, \
      global const float *lanes, global const int *lane_prims, global const SphereBlock *spheres
#define KD_ARGS header, nodes, fused, refs, lanes, lane_prims, spheres
/* Leaf nodes[leaf] against the ray; whether it hit (any hit). */
inline int kdtree_leaf(int leaf, const TraceRay* s, HitState* h, KD_PARAMS) {
  KdNode node = nodes[leaf];
  uint first = node.flags >> 2;
  return kd_test_leaf(refs, first, first + node.data, lanes, header->lane_stride, lane_prims, spheres, s, h);
}
RTCL_TRACE_KERNELS_OCCLUDER_CACHE(kdtree, KD_PARAMS, KD_ARGS)
