/* What the two octree kernels (kernels/accel/octree.cl, octree_ptr.cl)
 * share: the clip of a ray to the root box and the leaf tests.
 * OpenCL C only. */
#ifndef RTCL_SHARED_OCTREE_H
#define RTCL_SHARED_OCTREE_H

/* The leaf tests' triangle arithmetic inlined into the traversal
 * (shared/triangle.h). */
#define RTCL_INLINE_TRIANGLE_LANES
#include "shared/trace.h"

/* The ray's step along one axis: the direction's sign, 0 when it does not
 * move along the axis (zero component, or a reciprocal that overflows). */
inline int octree_axis_step(float d, float inv) {
  return (d == 0.0f || !rtcl_is_finite(inv)) ? 0 : (d > 0.0f ? 1 : -1);
}

/* Clips one axis of the ray to the slab [lower, upper] (conservatively
 * widened, as the grid's: entering a cell too early costs a test, too late
 * a miss) and sets its step (octree_axis_step); an axis the ray does not
 * move along limits nothing when the origin lies within the slab.
 * Returns 0 when the ray misses the slab. */
inline int octree_clip_axis(float o, float d, float inv, float lower, float upper, float* t0, float* t1,
                            int* step) {
  *step = octree_axis_step(d, inv);
  if (*step == 0) return o >= lower && o <= upper;
  float tn = ((*step > 0 ? lower : upper) - o) * inv;
  float tf = ((*step > 0 ? upper : lower) - o) * inv;
  *t0 = fmax(*t0, tn - fabs(tn) * RTCL_SLAB_WIDEN);
  *t1 = fmin(*t1, tf + fabs(tf) * RTCL_SLAB_WIDEN);
  return 1;
}

/* Tests the blocks of leaf `leaf` (OctreeHeader / OctreeNode pair layout:
 * triangle blocks [leaf_begin[2l], leaf_begin[2l + 2]), sphere blocks
 * [leaf_begin[2l + 1], leaf_begin[2l + 3])) with the block tests brute force
 * runs (the same t, bit for bit); a triangle block whose BlockBox the ray
 * misses before the best hit is skipped (its hits inside the widened cell
 * lie in the box; a hit outside the cell is in another leaf of the block's
 * triangle, which the walk reaches unless a nearer hit ends it). Returns 1
 * when an any-hit query is done. */
inline int octree_test_leaf(uint leaf, global const uint* leaf_begin, global const TriangleBlock* triangles,
                            global const SphereBlock* spheres, global const BlockBox* boxes, const TraceRay* s,
                            HitState* h) {
  uint end = leaf_begin[2 * leaf + 2];
  for (uint b = leaf_begin[2 * leaf]; b < end; ++b)
    if (intersect_box1(boxes[b].bounds, s, h->t_best) && intersect_triangles8(triangles + b, s, h) &&
        RTCL_ANY_HIT)
      return 1;
#ifdef RTCL_HAS_SPHERES
  end = leaf_begin[2 * leaf + 3];
  for (uint b = leaf_begin[2 * leaf + 1]; b < end; ++b)
    if (intersect_spheres8(spheres + b, s, h) && RTCL_ANY_HIT) return 1;
#endif
  return 0;
}

#endif
