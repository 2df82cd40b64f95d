/* Pointer octree traversal (octree-ptr, octree-r), one ray per work-item:
 * top-down, the children of each inner node visited in the order the ray
 * crosses them, after the parametric method of Revelles, Urena & Lastra
 * (2000, "An efficient parametric algorithm for octree traversal"), with
 * the split planes read from the node instead of taken at the centre (so
 * that Octree-R's planes work unchanged).
 *
 * At an inner node entered over the ray interval [ta, tb]: per axis the
 * distance ts to the split plane, (split - o) / d. The first child is the
 * one holding the ray at ta, side by side: upper on axis a when ts <= ta
 * for a positive direction component, ts > ta for a negative one (a point
 * on the plane goes to the side the ray moves into), o >= split for a zero
 * one. The ray then crosses the planes with ta < ts < tb in increasing ts,
 * each flipping that axis's bit of the child index: at most four children,
 * intervals [ta, ts1], [ts1, ts2], ..., [tsk, tb] that tile [ta, tb] with
 * shared float end points, so no child is skipped for rounding. Empty
 * children are not visited; the later children go on a stack (3 entries
 * per level, RTCL_OCTREE_STACK = 3 * depth + 1), the first is descended.
 *
 * A leaf holds its own blocks of eight primitives, ids ascending, tested
 * with the block tests brute force runs (the same t, bit for bit); the walk
 * ends once the closest hit lies inside the leaf: t_best <= its exit distance less a conservative margin, as the
 * grid's cells; the leaves left are all farther along the ray. Primitives
 * are listed in every leaf whose widened box they meet, so a hit within
 * rounding of a split plane is found on either side. */
#include "shared/octree.h"

#ifndef RTCL_OCTREE_STACK
#define RTCL_OCTREE_STACK 61
#endif

__attribute__((noinline)) void octree_ptr_traverse(const TraceRay* s, HitState* h,
                                                   global const OctreePtrHeader* header,
                                                   global const OctreeNode* nodes, global const uint* leaf_begin,
                                                   global const TriangleBlock* triangles,
                                                   global const SphereBlock* spheres) {
  const OctreePtrHeader g = *header;
  if (g.root == RTCL_CHILD_EMPTY) return;
  const float o[3] = {s->ox, s->oy, s->oz}, inv[3] = {s->ix, s->iy, s->iz};
  float ta = s->tmin, tb = s->tmax;
  int step[3];
  for (int a = 0; a < 3; ++a)
    if (!octree_clip_axis(o[a], a == 0 ? s->dx : (a == 1 ? s->dy : s->dz), inv[a], g.lower[a], g.upper[a], &ta,
                          &tb, &step[a]))
      return;
  if (!(ta <= tb)) return;
  int stack_ref[RTCL_OCTREE_STACK];
  float stack_ta[RTCL_OCTREE_STACK], stack_tb[RTCL_OCTREE_STACK];
  int sp = 0;
  int ref = g.root;
  for (;;) {
    if (ref >= 0) {
      const OctreeNode node = nodes[ref];
      int first = 0, crossings = 0;
      float ct[3];
      int ca[3];
      for (int a = 0; a < 3; ++a) {
        int upper;
        if (step[a] == 0) {
          upper = o[a] >= node.split[a];
        } else {
          float ts = (node.split[a] - o[a]) * inv[a];
          upper = step[a] > 0 ? ts <= ta : ts > ta;
          if (ta < ts && ts < tb) {
            /* insertion into the crossings, ascending ts, x before y before z on ties */
            int k = crossings++;
            while (k > 0 && ct[k - 1] > ts) {
              ct[k] = ct[k - 1];
              ca[k] = ca[k - 1];
              --k;
            }
            ct[k] = ts;
            ca[k] = a;
          }
        }
        first |= upper << a;
      }
      /* the later children, last first, onto the stack */
      int child = first;
      for (int k = 0; k < crossings; ++k) child ^= 1 << ca[k];
      for (int k = crossings - 1; k >= 0; --k) {
        int c = node.child[child];
        if (c != RTCL_CHILD_EMPTY) {
          stack_ref[sp] = c;
          stack_ta[sp] = ct[k];
          stack_tb[sp] = tb;
          ++sp;
        }
        tb = ct[k];
        child ^= 1 << ca[k];
      }
      ref = node.child[first];
      if (ref != RTCL_CHILD_EMPTY) continue;
    } else {
      if (octree_test_leaf((uint)~ref, leaf_begin, triangles, spheres, s, h)) return;
      if (h->t_best <= tb - fabs(tb) * RTCL_SLAB_WIDEN) return;
    }
    if (sp == 0) return;
    --sp;
    ref = stack_ref[sp];
    ta = stack_ta[sp];
    tb = stack_tb[sp];
  }
}

#define OCTREE_PTR_PARAMS                                                                          \
  global const OctreePtrHeader *header, global const OctreeNode *nodes, global const uint *leaf_begin, \
      global const TriangleBlock *triangles, global const SphereBlock *spheres
#define OCTREE_PTR_ARGS header, nodes, leaf_begin, triangles, spheres
RTCL_TRACE_KERNELS(octree_ptr, OCTREE_PTR_PARAMS, OCTREE_PTR_ARGS)
