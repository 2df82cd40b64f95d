/* 8-wide BVH traversal, one ray per work-item (the shape of Embree's
 * single-ray BVH8 traversal, Wald et al. 2014, "Embree: a kernel framework
 * for efficient CPU ray tracing"): the eight child boxes of a node are tested
 * at once in float8 lanes (intersect_boxes8); leaves are blocks of eight
 * primitives, also tested in float8 lanes.
 *
 * Closest hit: the children a ray enters are pushed sorted by entry
 * distance, nearest on top, and the top is taken next; an entry popped with
 * an entry distance beyond the current hit is skipped. Any hit: pushed in
 * lane order, and the first hit ends the traversal.
 *
 * Stack: a node with k children pushes at most k entries and pops one, so
 * the stack never holds more than, over all nodes v, the sum of
 * (children - 1) over v's ancestors plus v's children. The host computes
 * that bound from the tree (flatten_bvh8) and compiles with
 * -DRTCL_STACK_SIZE >= it.
 *
 * Shape chosen by measurement on PoCL (CPU, AVX2), where each work-item runs
 * as scalar code around the explicit float8 operations: a per-lane branch
 * with a constant lane index (extracted from registers) beat bit-mask
 * iteration, a branch-free compaction and a float8 sorting network; the
 * traversal stays a separate function (its private arrays stay on the
 * native stack instead of becoming per-work-item arrays).
 *
 * Mixed volumes (RTCL_BVH_SPHERES, the "bvh-mixed" structure): nodes with
 * sphere_of[node] >= 0 also filter the children their boxes let through by
 * the bounding spheres of record sphere_of[node] (shared/sphere_filter8.h).
 * Without the define the kernel has no sphere code and no extra arguments. */
#include "shared/trace.h"
#ifdef RTCL_BVH_SPHERES
#include "shared/sphere_filter8.h"
#define BVH_SPHERE_PARAMS , global const int *sphere_of, global const Bvh8Spheres *sphere_filters
#define BVH_SPHERE_ARGS , sphere_of, sphere_filters
#else
#define BVH_SPHERE_PARAMS
#define BVH_SPHERE_ARGS
#endif

#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

__attribute__((noinline)) void bvh_traverse(const TraceRay* s, HitState* h, global const Bvh8Node* nodes,
                                            global const TriangleBlock* triangles,
                                            global const SphereBlock* spheres BVH_SPHERE_PARAMS) {
#ifdef RTCL_BVH_SPHERES
  SphereFilterRay filter;
  sphere_filter_setup(s, &filter);
#endif
  int stack_ref[RTCL_STACK_SIZE];
  float stack_t[RTCL_STACK_SIZE]; /* entry distance of stack_ref's box */
  int sp = 0;
  int ref = 0;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      float8 t_entry;
      int8 hit = intersect_boxes8(node, s, h->t_best, &t_entry);
#ifdef RTCL_BVH_SPHERES
      int filter_ref = sphere_of[ref];
      if (filter_ref >= 0 && rtcl_any8(hit)) hit &= sphere_filter8(sphere_filters + filter_ref, s, &filter);
#endif
      if (rtcl_any8(hit)) {
        int base = sp;
        /* insertion into [base, sp) kept sorted by decreasing distance */
#define BVH_PUSH_LANE(k)                                     \
  if (hit.s##k) {                                            \
    float t = t_entry.s##k;                                  \
    int j = sp++;                                            \
    while (!RTCL_ANY_HIT && j > base && stack_t[j - 1] < t) {     \
      stack_t[j] = stack_t[j - 1];                           \
      stack_ref[j] = stack_ref[j - 1];                       \
      --j;                                                   \
    }                                                        \
    stack_t[j] = t;                                          \
    stack_ref[j] = node->child[k];                           \
  }
        BVH_PUSH_LANE(0) BVH_PUSH_LANE(1) BVH_PUSH_LANE(2) BVH_PUSH_LANE(3)
        BVH_PUSH_LANE(4) BVH_PUSH_LANE(5) BVH_PUSH_LANE(6) BVH_PUSH_LANE(7)
#undef BVH_PUSH_LANE
      }
    } else {
      int leaf = ~ref;
#ifdef RTCL_HAS_SPHERES
      if (leaf & 1) {
        if (intersect_spheres8(spheres + (leaf >> 1), s, h) && RTCL_ANY_HIT) return;
      } else
#endif
      if (intersect_triangles8(triangles + (leaf >> 1), s, h) && RTCL_ANY_HIT) return;
    }
    do {
      if (sp == 0) return;
      --sp;
    } while (stack_t[sp] > h->t_best);
    ref = stack_ref[sp];
  }
}

#define BVH_PARAMS                                                                                    \
  global const Bvh8Node *nodes, global const TriangleBlock *triangles, global const SphereBlock *spheres \
      BVH_SPHERE_PARAMS
#define BVH_ARGS nodes, triangles, spheres BVH_SPHERE_ARGS
RTCL_TRACE_KERNELS(bvh, BVH_PARAMS, BVH_ARGS)
