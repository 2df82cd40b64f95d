/* The single-ray traversal of the 8-wide BVH (bvh_traverse), shared by the
 * BVH's kernel (kernels/accel/bvh.cl) and the bottom levels of two-level
 * scenes (kernels/accel/instances.cl); the shape of Embree's
 * single-ray BVH8 traversal, Wald et al. 2014, "Embree: a kernel framework
 * for efficient CPU ray tracing"): the eight child boxes of a node are tested
 * at once in float8 lanes (intersect_boxes8); leaves are blocks of eight
 * primitives, also tested in float8 lanes.
 *
 * Closest hit: the children a ray enters are pushed sorted by entry
 * distance, nearest on top, and the top is taken next (kept in registers,
 * never stored: shared/bvh8_stack.h); an entry popped with an entry
 * distance beyond the current hit is skipped. Any hit: pushed in
 * lane order, and the first hit ends the traversal.
 *
 * Stack: a node with k children pushes at most k - 1 entries and takes the
 * nearest directly (as pushing k and popping one), so the stack never
 * holds more than, over all nodes v, the sum of
 * (children - 1) over v's ancestors plus v's children. The host computes
 * that bound from the tree (flatten_bvh8) and compiles with
 * -DRTCL_STACK_SIZE >= it. bvh_traverse walks on a stack of its own;
 * bvh_walk, the same walk, on its caller's, above the entries there (the
 * two-level walk of an identity instance, kernels/accel/instances.cl).
 *
 * Shape for PoCL (CPU), where each work-item runs as scalar code around the
 * explicit float8 operations: the children are pushed by a per-lane branch
 * with a constant lane index (extracted from registers), the fastest form
 * there (docs/benchmarks.md); the traversal stays a separate function (its
 * private arrays stay on the native stack instead of becoming per-work-item
 * arrays).
 *
 * Mixed volumes (the "bvh-mixed" structure): a node with filter_of[node]
 * >= 0 (RTCL_FILTER_REF of shared/layouts.h) also filters the children its
 * boxes let through by the record of one kind: bounding spheres
 * (RTCL_BVH_SPHERES, shared/sphere_filter8.h), body-diagonal k-DOP slabs
 * (RTCL_BVH_KDOP, shared/kdop_filter8.h) or oriented boxes (RTCL_BVH_OBB,
 * shared/obb_filter8.h). Each define is passed only when some node uses
 * that kind; each kind's record array is an argument only then, and
 * without any of them the kernel has no filter code and no extra
 * arguments.
 *
 * A kernel that includes this file may define RTCL_INLINE_TRIANGLE_LANES,
 * RTCL_INLINE_TRIANGLE_BLOCK and RTCL_INLINE_RAY_SETUP first (shared/
 * triangle.h, shared/ray.h). OpenCL C only. */
#ifndef RTCL_SHARED_BVH8_TRAVERSE_H
#define RTCL_SHARED_BVH8_TRAVERSE_H

#include "shared/bvh8_stack.h"
#include "shared/trace.h"
#if defined(RTCL_BVH_SPHERES) || defined(RTCL_BVH_KDOP) || defined(RTCL_BVH_OBB)
#define RTCL_BVH_FILTERS
#define BVH_FILTER_OF_PARAM , global const int *filter_of
#define BVH_FILTER_OF_ARG , filter_of
#else
#define BVH_FILTER_OF_PARAM
#define BVH_FILTER_OF_ARG
#endif
#ifdef RTCL_BVH_SPHERES
#include "shared/sphere_filter8.h"
#define BVH_SPHERE_PARAM , global const Bvh8Spheres *sphere_filters
#define BVH_SPHERE_ARG , sphere_filters
#else
#define BVH_SPHERE_PARAM
#define BVH_SPHERE_ARG
#endif
#ifdef RTCL_BVH_KDOP
#include "shared/kdop_filter8.h"
#define BVH_KDOP_PARAM , global const Bvh8Kdop *kdop_filters
#define BVH_KDOP_ARG , kdop_filters
#else
#define BVH_KDOP_PARAM
#define BVH_KDOP_ARG
#endif
#ifdef RTCL_BVH_OBB
#include "shared/obb_filter8.h"
#define BVH_OBB_PARAM , global const Bvh8Obb *obb_filters
#define BVH_OBB_ARG , obb_filters
#else
#define BVH_OBB_PARAM
#define BVH_OBB_ARG
#endif
#define BVH_FILTER_PARAMS BVH_FILTER_OF_PARAM BVH_SPHERE_PARAM BVH_KDOP_PARAM BVH_OBB_PARAM
#define BVH_FILTER_ARGS BVH_FILTER_OF_ARG BVH_SPHERE_ARG BVH_KDOP_ARG BVH_OBB_ARG

#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

/* Leaf `leaf` (~ a child reference: its block index times two, plus one for
 * spheres) against the ray; whether it hit. Always inlined: called, it cost
 * the closest-hit traversal 3-20% (sponza's primary rays most). */
inline __attribute__((always_inline)) int bvh_test_leaf(int leaf, const TraceRay* s, HitState* h,
                                                        global const TriangleBlock* triangles,
                                                        global const SphereBlock* spheres) {
#ifdef RTCL_HAS_SPHERES
  if (leaf & 1) return intersect_spheres8(spheres + (leaf >> 1), s, h);
#endif
  return intersect_triangles8(triangles + (leaf >> 1), s, h);
}

/* The walk from the root of (nodes, triangles, spheres) on the caller's
 * stack (stack_ref, stack_t), above its first stack_base entries, which it
 * leaves as they are. Returns the leaf that ended an any-hit walk, else
 * -1. */
inline __attribute__((always_inline)) int bvh_walk(const TraceRay* s, HitState* h, global const Bvh8Node* nodes,
                                                   global const TriangleBlock* triangles,
                                                   global const SphereBlock* spheres BVH_FILTER_PARAMS,
                                                   int* stack_ref, float* stack_t, int stack_base) {
#ifdef RTCL_BVH_SPHERES
  SphereFilterRay sphere_ray;
  sphere_filter_setup(s, &sphere_ray);
#endif
#ifdef RTCL_BVH_KDOP
  KdopFilterRay kdop_ray;
  kdop_filter_setup(s, &kdop_ray);
#endif
#ifdef RTCL_BVH_OBB
  float obb_widen = obb_filter_setup(s);
#endif
  int sp = stack_base;
  int ref = 0;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      float8 t_entry;
#ifdef RTCL_BVH_FILTERS
      float8 t_exit;
      int8 hit = intersect_box_rows8((global const float8*)node->bounds, s, h->t_best, &t_entry, &t_exit);
      int filter = filter_of[ref];
      if (filter >= 0 && rtcl_any8(hit)) {
        int kind = RTCL_FILTER_KIND(filter), index = RTCL_FILTER_INDEX(filter);
#ifdef RTCL_BVH_SPHERES
        if (kind == RTCL_FILTER_SPHERE) hit &= sphere_filter8(sphere_filters + index, s, &sphere_ray);
#endif
#ifdef RTCL_BVH_KDOP
        if (kind == RTCL_FILTER_KDOP) hit &= kdop_filter8(kdop_filters + index, &kdop_ray, t_entry, t_exit);
#endif
#ifdef RTCL_BVH_OBB
        if (kind == RTCL_FILTER_OBB) hit &= obb_filter8(obb_filters + index, s, obb_widen, t_entry, t_exit);
#endif
      }
#else
      int8 hit = intersect_boxes8(node, s, h->t_best, &t_entry);
#endif
      if (rtcl_any8(hit)) {
        RTCL_BVH8_PUSH_CHILDREN_BUT_NEAREST
        ref = near_entry;
        continue;
      }
    } else {
      int leaf = ~ref;
      if (bvh_test_leaf(leaf, s, h, triangles, spheres) && RTCL_ANY_HIT) return leaf;
    }
    do {
      if (sp == stack_base) return -1;
      --sp;
    } while (!RTCL_ANY_HIT && stack_t[sp] > h->t_best);
    ref = stack_ref[sp];
  }
}

/* bvh_walk on a stack of its own: returns the leaf that ended an any-hit
 * traversal, else -1. */
__attribute__((noinline)) int bvh_traverse(const TraceRay* s, HitState* h, global const Bvh8Node* nodes,
                                            global const TriangleBlock* triangles,
                                            global const SphereBlock* spheres BVH_FILTER_PARAMS) {
  int stack_ref[RTCL_STACK_SIZE];
  float stack_t[RTCL_STACK_SIZE]; /* entry distance of stack_ref's box */
  return bvh_walk(s, h, nodes, triangles, spheres BVH_FILTER_ARGS, stack_ref, stack_t, 0);
}

#endif
