/* 8-wide BVH traversal, one ray per work-item: the eight child boxes of a node
 * are tested at once in float8 lanes; leaves are blocks of eight primitives.
 * Closest hit visits hit children nearest first and skips any whose entry
 * distance is beyond the current hit; any hit stops at the first hit. */
#include "shared/trace.h"

/* Entries the traversal stack needs; the host computes it from the tree. */
#ifndef RTCL_STACK_SIZE
#define RTCL_STACK_SIZE 64
#endif

inline void bvh_traverse(const TraceRay* s, HitState* h, global const Bvh8Node* nodes,
                         global const TriangleBlock* triangles, global const SphereBlock* spheres,
                         const int any_hit) {
  int stack_ref[RTCL_STACK_SIZE];
  float stack_t[RTCL_STACK_SIZE];
  int sp = 0;
  int ref = 0;
  for (;;) {
    if (ref >= 0) {
      global const Bvh8Node* node = nodes + ref;
      float8 t_entry;
      int8 hit = intersect_boxes8(node, s, h->t_best, &t_entry);
      if (any(hit)) {
        int hit_lanes[8];
        float t_lanes[8];
        vstore8(hit, 0, hit_lanes);
        vstore8(t_entry, 0, t_lanes);
        int base = sp;
        for (int i = 0; i < 8; ++i) {
          if (!hit_lanes[i]) continue;
          float t = t_lanes[i];
          int j = sp++;
          /* keep [base, sp) sorted by decreasing entry distance: nearest on top */
          while (!any_hit && j > base && stack_t[j - 1] < t) {
            stack_t[j] = stack_t[j - 1];
            stack_ref[j] = stack_ref[j - 1];
            --j;
          }
          stack_t[j] = t;
          stack_ref[j] = node->child[i];
        }
      }
    } else {
      int leaf = ~ref;
#ifdef RTCL_HAS_SPHERES
      if (leaf & 1) {
        if (intersect_spheres8(spheres + (leaf >> 1), s, h) && any_hit) return;
      } else
#endif
      if (intersect_triangles8(triangles + (leaf >> 1), s, h) && any_hit) return;
    }
    do {
      if (sp == 0) return;
      --sp;
    } while (stack_t[sp] > h->t_best);
    ref = stack_ref[sp];
  }
}

#define BVH_PARAMS \
  global const Bvh8Node *nodes, global const TriangleBlock *triangles, global const SphereBlock *spheres
#define BVH_ARGS nodes, triangles, spheres
RTCL_TRACE_KERNELS(bvh, BVH_PARAMS, BVH_ARGS)
