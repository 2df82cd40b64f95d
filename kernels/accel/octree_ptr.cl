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
 * one. The ray then crosses the planes with ta < ts < tb in increasing ts
 * (a three-element sorting network, stable: x before y before z on ties),
 * each flipping that axis's bit of the child index: at most four children,
 * intervals [ta, ts1], [ts1, ts2], ..., [tsk, tb] that tile [ta, tb] with
 * shared float end points, so no child is skipped for rounding. Empty
 * children are not visited; the later children go on a stack (3 entries
 * per level, RTCL_OCTREE_STACK = 3 * depth + 1), the first is descended.
 *
 * Occupied space: before the walk the ray meets the eight boxes of the
 * root's children's contents (OctreePtrHeader.occupied_bounds) in one
 * float8 slab test; a ray that meets none is done, the others walk only
 * [ta, tb] narrowed to the boxes they meet, and the root's children whose
 * box they miss are not visited. Exact: every hit lies in its octant's box.
 *
 * A leaf holds its own blocks of eight primitives, ids ascending, tested
 * with the block tests brute force runs (the same t, bit for bit), a
 * triangle block only when the ray meets its BlockBox (shared/octree.h);
 * the walk ends once the closest hit lies inside the leaf: t_best <= its
 * exit distance less a conservative margin, as the grid's cells; the
 * leaves left are all farther along the ray. Primitives are listed in
 * every leaf whose widened box they meet, so a hit within rounding of a
 * split plane is found on either side. */
#include "shared/octree.h"

#ifndef RTCL_OCTREE_STACK
#define RTCL_OCTREE_STACK 61
#endif

/* Whether the ray at ta is on the upper side of split plane ts along an axis
 * it moves along with sign step (0: it does not move along it; the origin
 * decides). */
inline int octree_ptr_upper(int step, float o, float split, float ts, float ta) {
  return step == 0 ? o >= split : (step > 0 ? ts <= ta : ts > ta);
}

/* Orders two (distance, axis) pairs by distance, the first kept first on a
 * tie: three of these are a stable sort of three (bubble sort). */
inline void octree_ptr_order(float* t0, int* a0, float* t1, int* a1) {
  if (*t1 < *t0) {
    float t = *t0;
    *t0 = *t1;
    *t1 = t;
    int a = *a0;
    *a0 = *a1;
    *a1 = a;
  }
}

/* The occupied space below the root: its children whose boxes (six float8
 * rows, OctreePtrHeader) the ray meets, as bits (bit q for child q), with
 * [*ta, *tb] narrowed to them; 0 when the ray meets none inside [*ta, *tb];
 * all of them, nothing narrowed, where rtcl_slabs_defined does not hold. */
inline int octree_ptr_occupied(global const float* rows, const TraceRay* s, float* ta, float* tb) {
  if (!rtcl_slabs_defined(s)) return 0xff;
  float8 entry, exit;
  const int8 meets = intersect_box_rows8((global const float8*)rows, s, *tb, &entry, &exit);
  if (!rtcl_any8(meets)) return 0;
  *ta = fmax(*ta, rtcl_min8(select((float8)(INFINITY), entry, meets)));
  *tb = fmin(*tb, rtcl_max8(select((float8)(-INFINITY), exit, meets)));
  if (!(*ta <= *tb)) return 0;
  const int8 bit = meets & (int8)(1, 2, 4, 8, 16, 32, 64, 128);
  return bit.s0 | bit.s1 | bit.s2 | bit.s3 | bit.s4 | bit.s5 | bit.s6 | bit.s7;
}

/* Returns the leaf (its index into leaf_begin's pairs) that ended an
 * any-hit traversal, else -1. */
__attribute__((noinline)) int octree_ptr_traverse(const TraceRay* s, HitState* h,
                                                  global const OctreePtrHeader* header,
                                                  global const OctreeNode* nodes, global const uint* leaf_begin,
                                                  global const TriangleBlock* triangles,
                                                  global const SphereBlock* spheres,
                                                  global const BlockBox* boxes) {
  const int root = header->root;
  if (root == RTCL_CHILD_EMPTY) return -1;
  float ta = s->tmin, tb = s->tmax;
  int step_x = octree_axis_step(s->dx, s->ix), step_y = octree_axis_step(s->dy, s->iy),
      step_z = octree_axis_step(s->dz, s->iz);
  /* the occupied boxes lie in the root box (widened as every cell is): where
   * they narrow [ta, tb], the clip to the root box adds nothing */
  if (!rtcl_slabs_defined(s) &&
      (!octree_clip_axis(s->ox, s->dx, s->ix, header->lower[0], header->upper[0], &ta, &tb, &step_x) ||
       !octree_clip_axis(s->oy, s->dy, s->iy, header->lower[1], header->upper[1], &ta, &tb, &step_y) ||
       !octree_clip_axis(s->oz, s->dz, s->iz, header->lower[2], header->upper[2], &ta, &tb, &step_z) ||
       !(ta <= tb)))
    return -1;
  const int root_live = octree_ptr_occupied(&header->occupied_bounds[0][0], s, &ta, &tb);
  if (root_live == 0) return -1;
  const float4 o = (float4)(s->ox, s->oy, s->oz, 0.0f), inv = (float4)(s->ix, s->iy, s->iz, 0.0f);
  int stack_ref[RTCL_OCTREE_STACK];
  float stack_ta[RTCL_OCTREE_STACK], stack_tb[RTCL_OCTREE_STACK];
  int sp = 0;
  int ref = root;
  for (;;) {
    if (ref >= 0) {
      global const OctreeNode* node = nodes + ref;
      const int live = ref == root ? root_live : 0xff; /* the children that may hold a hit */
      const float4 split = vload4(0, node->split);
      const float4 ts = (split - o) * inv;
      const int first = octree_ptr_upper(step_x, o.x, split.x, ts.x, ta) |
                        octree_ptr_upper(step_y, o.y, split.y, ts.y, ta) << 1 |
                        octree_ptr_upper(step_z, o.z, split.z, ts.z, ta) << 2;
      /* the planes crossed inside (ta, tb), in increasing distance; the others at +inf */
      const int cross_x = step_x != 0 && ta < ts.x && ts.x < tb;
      const int cross_y = step_y != 0 && ta < ts.y && ts.y < tb;
      const int cross_z = step_z != 0 && ta < ts.z && ts.z < tb;
      const int crossings = cross_x + cross_y + cross_z;
      float t0 = cross_x ? ts.x : INFINITY, t1 = cross_y ? ts.y : INFINITY, t2 = cross_z ? ts.z : INFINITY;
      int a0 = 0, a1 = 1, a2 = 2;
      octree_ptr_order(&t0, &a0, &t1, &a1);
      octree_ptr_order(&t1, &a1, &t2, &a2);
      octree_ptr_order(&t0, &a0, &t1, &a1);
      /* child k follows the k-th crossing: the later ones, last first, onto the stack */
      const int c1 = first ^ (1 << a0), c2 = c1 ^ (1 << a1), c3 = c2 ^ (1 << a2);
      if (crossings == 3 && (live >> c3 & 1) && node->child[c3] != RTCL_CHILD_EMPTY) {
        stack_ref[sp] = node->child[c3];
        stack_ta[sp] = t2;
        stack_tb[sp] = tb;
        ++sp;
      }
      if (crossings >= 2 && (live >> c2 & 1) && node->child[c2] != RTCL_CHILD_EMPTY) {
        stack_ref[sp] = node->child[c2];
        stack_ta[sp] = t1;
        stack_tb[sp] = crossings == 3 ? t2 : tb;
        ++sp;
      }
      if (crossings >= 1 && (live >> c1 & 1) && node->child[c1] != RTCL_CHILD_EMPTY) {
        stack_ref[sp] = node->child[c1];
        stack_ta[sp] = t0;
        stack_tb[sp] = crossings >= 2 ? t1 : tb;
        ++sp;
      }
      if (crossings >= 1) tb = t0;
      ref = (live >> first & 1) ? node->child[first] : RTCL_CHILD_EMPTY;
      if (ref != RTCL_CHILD_EMPTY) continue;
    } else {
      if (octree_test_leaf((uint)~ref, leaf_begin, triangles, spheres, boxes, s, h)) return ~ref;
      if (h->t_best <= tb - fabs(tb) * RTCL_SLAB_WIDEN) return -1;
    }
    if (sp == 0) return -1;
    --sp;
    ref = stack_ref[sp];
    ta = stack_ta[sp];
    tb = stack_tb[sp];
  }
}

#define OCTREE_PTR_PARAMS                                                                          \
  global const OctreePtrHeader *header, global const OctreeNode *nodes, global const uint *leaf_begin, \
      global const TriangleBlock *triangles, global const SphereBlock *spheres, global const BlockBox *boxes
#define OCTREE_PTR_ARGS header, nodes, leaf_begin, triangles, spheres, boxes
/* Leaf `leaf` against the ray; whether it hit (any hit). */
inline int octree_ptr_leaf(int leaf, const TraceRay* s, HitState* h, OCTREE_PTR_PARAMS) {
  return octree_test_leaf((uint)leaf, leaf_begin, triangles, spheres, boxes, s, h);
}
RTCL_TRACE_KERNELS_OCCLUDER_CACHE(octree_ptr, OCTREE_PTR_PARAMS, OCTREE_PTR_ARGS)
